#!/bin/bash
# Scaling of decomposed runs (docs/mpi.md "Scaling"). Strong: bench/scenes/mpi_3d.toml (1.03e6
# points of a moving bed and a rigid cylinder pushed into it, 50 steps) on 1 and 2 ranks of 1
# thread, interleaved round by round, and the gain of each round as the ratio of the step rates
# (points x steps / the step's wall time, summary.json timings_seconds; the first and last frames,
# gathered on rank 0, are not part of the step). Weak: the bed widened along x with the ranks
# (points per rank fixed; the cylinder at mid-length) on 1, 2 and 4 ranks (4 oversubscribes a
# 2-core machine: that row measures the overhead, not a speed-up).
#   bash bench/mpi_scaling.sh [BUILD=build/release] [ROUNDS=3]
set -euo pipefail
exe() { if [ -d "$1" ]; then echo "$1/oobleck"; else echo "$1"; fi; }
X=$(realpath -- "$(exe "${1:-build/release}")")
ROUNDS=${2:-3}
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
MPIRUN=(mpirun --allow-run-as-root --oversubscribe --bind-to none)
run() {  # run NAME RANKS [--set ...]
  local name=$1 ranks=$2; shift 2
  rm -rf "$out/run"
  OMP_WAIT_POLICY=PASSIVE "${MPIRUN[@]}" -np "$ranks" "$X" run bench/scenes/mpi_3d.toml --threads 1 --out "$out/run" \
    --quiet "$@" >/dev/null
  cp "$out/run/summary.json" "$out/$name.json"
}
for r in $(seq 1 "$ROUNDS"); do
  run "strong.1.$r" 1
  run "strong.2.$r" 2 --ranks-grid 2x1x1  # (split across the motion: points migrate)
  echo "mpi_scaling: strong round $r of $ROUNDS done" >&2
done
for n in 1 2 4; do
  L=$(/usr/bin/python3 -c "print(0.024 * $n)")
  M=$(/usr/bin/python3 -c "print(0.012 * $n)")  # the cylinder at mid-length (on a cut for 2 and 4 ranks)
  run "weak.$n" "$n" --set "grid.size=[$L, 0.048, 0.032]" --set "region.0.max=[$L, 0.048, 0.028]" \
    --set "body.0.centre=[$M, 0.024, 0.028]" --ranks-grid "${n}x1x1"
  echo "mpi_scaling: weak $n rank(s) done" >&2
done
/usr/bin/python3 - "$out" "$ROUNDS" <<'PY'
import json, statistics, sys
out, rounds = sys.argv[1], int(sys.argv[2])
def load(name):
    with open(f"{out}/{name}.json") as f:
        return json.load(f)
def step_rate(s):
    t = s["timings_seconds"]
    step = t["p2g"] + t["grid"] + t["g2p"] + t["stress"]
    return s["points"] * s["steps_this_run"] / step, step, t.get("communication", 0.0)
gains, r1, r2, shares = [], [], [], []
for r in range(1, rounds + 1):
    a, b = step_rate(load(f"strong.1.{r}")), step_rate(load(f"strong.2.{r}"))
    r1.append(a[0]); r2.append(b[0]); gains.append(b[0] / a[0]); shares.append(b[2] / b[1])
s2 = load(f"strong.2.{rounds}")
print(f"strong scaling, {s2['points']} points x {s2['steps_this_run']} steps, 1 thread per rank:")
print(f"  1 rank : {statistics.median(r1):.3g} point updates/s (median of {rounds})")
print(f"  2 ranks: {statistics.median(r2):.3g} point updates/s, ranks grid {s2['ranks_grid']}, "
      f"points per rank {s2['points_per_rank']}")
print(f"  gain 2/1: median {statistics.median(gains):.3f} (rounds: {', '.join(f'{g:.3f}' for g in gains)})")
print(f"  communication share of the step on 2 ranks: median {100 * statistics.median(shares):.1f} %; "
      f"halo {s2['halo_bytes_sent_per_rank_per_step'] / 1e6:.2f} MB sent per rank per step; "
      f"{s2['points_migrated']} points migrated in {s2['steps_this_run']} steps")
print("weak scaling (points per rank fixed), 1 thread per rank:")
base = None
for n in (1, 2, 4):
    s = load(f"weak.{n}")
    rate, step, comm = step_rate(s)
    per_rank = rate / n
    base = base or per_rank
    print(f"  {n} rank(s): {s['points']} points, {rate:.3g} updates/s, {per_rank:.3g} per rank "
          f"(efficiency {per_rank / base:.3f}), communication {100 * comm / step:.1f} % of the step, "
          f"halo {s.get('halo_bytes_sent_per_rank_per_step', 0) / 1e6:.2f} MB/rank/step")
PY
