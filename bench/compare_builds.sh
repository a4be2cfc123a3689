#!/bin/bash
# A/B comparison of two builds on the authors' set-ups (issue 4), for noisy hosts: the runs of the
# two builds are interleaved round by round (A and B see the same minute of the host), and the
# report gives the median and the best of each build, scene and thread count, with the medians of
# the step's phases (summary.json "timings_seconds", s per run).
#   bash bench/compare_builds.sh BUILD_A BUILD_B [ROUNDS=5] [THREADS="1 2"] [SCENES="intruder wheel"]
# BUILD_A/B: build folders (each with its ./oobleck) or oobleck executables. A single build may be
# given twice to see the host's own spread. Run it on an otherwise idle machine.
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n 2,8p "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
exe() { if [ -d "$1" ]; then echo "$1/oobleck"; else echo "$1"; fi; }
A=$(exe "$1"); B=$(exe "$2")
ROUNDS=${3:-5}; THREADS=${4:-"1 2"}; SCENES=${5:-"intruder wheel"}
for x in "$A" "$B"; do
  [ -x "$x" ] || { echo "compare_builds: '$x' is not an executable oobleck" >&2; exit 2; }
done
A=$(realpath -- "$A"); B=$(realpath -- "$B")  # before the cd below
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for r in $(seq 1 "$ROUNDS"); do
  for s in $SCENES; do
    for t in $THREADS; do
      for label in A B; do
        x=$A; [ $label = B ] && x=$B
        d="$out/run"
        rm -rf "$d"
        OMP_NUM_THREADS=$t "$x" run "bench/scenes/${s}_authors_setup.toml" --threads "$t" --out "$d" --quiet >/dev/null ||
          { echo "compare_builds: build $label ($x) failed on $s, $t threads, round $r" >&2; exit 1; }
        cp "$d/summary.json" "$out/$label.$t.$r.$s.json"
      done
    done
  done
  echo "compare_builds: round $r of $ROUNDS done" >&2
done
/usr/bin/python3 - "$out" "$A" "$B" <<'PY'
import glob, json, os, statistics, sys
out, exe_a, exe_b = sys.argv[1:4]
runs = {}
for f in sorted(glob.glob(os.path.join(out, "*.json"))):
    label, threads, _, scene = os.path.basename(f)[: -len(".json")].split(".", 3)
    runs.setdefault((scene, int(threads), label), []).append(json.load(open(f)))
print(f"A = {exe_a}\nB = {exe_b}")
print(f"{'scene':<9} {'thr':>3} {'build':<5} {'median/s':>10} {'best/s':>10} {'B/A':>6}  phase medians [s]")
for (scene, threads) in sorted({(k[0], k[1]) for k in runs}):
    med = {}
    for label in ("A", "B"):
        rs = runs[(scene, threads, label)]
        ups = [r["point_updates_per_second"] for r in rs]
        med[label] = statistics.median(ups)
        phases = " ".join(f"{k}={statistics.median(r['timings_seconds'][k] for r in rs):.3f}"
                          for k in rs[0]["timings_seconds"])
        ratio = f"{med['B'] / med['A']:6.3f}" if label == "B" else " " * 6
        print(f"{scene:<9} {threads:>3} {label:<5} {med[label]:10.3e} {max(ups):10.3e} {ratio}  {phases}")
PY
