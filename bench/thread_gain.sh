#!/bin/bash
# What the second thread gains on the authors' set-ups (issue 4's "≥ 1.7× more on two threads"),
# measured so that a noisy host does not decide it: each round runs one build on 1 thread and then
# on 2 threads, back to back (the same minute of the host), and the gain of the round is the ratio
# of the two rates. The report gives, per set-up, the median and the range of the per-round gains,
# and the median rates. Run it on an otherwise idle machine.
#   bash bench/thread_gain.sh [BUILD=build/release] [ROUNDS=7] [SCENES="intruder wheel"]
# BUILD: a build folder (with its ./oobleck) or an oobleck executable.
set -euo pipefail
exe() { if [ -d "$1" ]; then echo "$1/oobleck"; else echo "$1"; fi; }
X=$(exe "${1:-build/release}")
ROUNDS=${2:-7}; SCENES=${3:-"intruder wheel"}
[ -x "$X" ] || { echo "thread_gain: '$X' is not an executable oobleck" >&2; exit 2; }
X=$(realpath -- "$X")
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for r in $(seq 1 "$ROUNDS"); do
  for s in $SCENES; do
    for t in 1 2; do
      d="$out/run"
      rm -rf "$d"
      OMP_NUM_THREADS=$t "$X" run "bench/scenes/${s}_authors_setup.toml" --threads "$t" --out "$d" --quiet >/dev/null ||
        { echo "thread_gain: $s failed on $t threads, round $r" >&2; exit 1; }
      cp "$d/summary.json" "$out/$s.$t.$r.json"
    done
  done
  echo "thread_gain: round $r of $ROUNDS done" >&2
done
/usr/bin/python3 - "$out" "$X" "$ROUNDS" "$SCENES" <<'PY'
import json, os, statistics, sys
out, exe, rounds, scenes = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4].split()
authors = {"intruder": 2.2e5, "wheel": 2.8e5}  # the authors' code, one core (issue 4)
print(f"build: {exe}")
print(f"{'scene':<9} {'1 thread: median (best)':>24} {'2 threads: median (best)':>25} {'gain per round: median (min-max)':>34}")
for s in scenes:
    ups = {t: [json.load(open(os.path.join(out, f"{s}.{t}.{r}.json")))["point_updates_per_second"]
               for r in range(1, rounds + 1)] for t in (1, 2)}
    gains = [b / a for a, b in zip(ups[1], ups[2])]
    m1 = statistics.median(ups[1])
    ref = f" = {m1 / authors[s]:.1f}x authors" if s in authors else ""
    print(f"{s:<9} {m1:11.3e} ({max(ups[1]):.3e}) {statistics.median(ups[2]):12.3e} ({max(ups[2]):.3e})"
          f"      {statistics.median(gains):.2f} ({min(gains):.2f}-{max(gains):.2f}){ref}")
PY
