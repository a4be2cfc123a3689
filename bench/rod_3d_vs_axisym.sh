#!/bin/bash
# S2 in 3D against the axisymmetric S2 (issue 28; docs/results.md "S2 in 3D"): the same rod, bed
# and material at the same cell size, 40 ms after impact. Runs scenes/paper/rod_impact.toml
# (axisymmetric) and scenes/paper/rod_impact_3d.toml (square container), then the 3D rod tilted
# by 30 deg (the oblique launch), and prints final_depth and final_velocity of each with the 3D
# runs' relative differences from the axisymmetric one. Extra arguments go to every run
# (e.g. --set v0=2). Wall time at 5 mm on 2 threads: see docs/results.md.
#   bash bench/rod_3d_vs_axisym.sh [BUILD=build/release] [CELL=0.005] [THREADS=2] [OUT=out/rod_3d_vs_axisym]
set -euo pipefail
exe() { if [ -d "$1" ]; then echo "$1/oobleck"; else echo "$1"; fi; }
X=$(realpath -- "$(exe "${1:-build/release}")")
CELL=${2:-0.005}
THREADS=${3:-2}
OUT=${4:-out/rod_3d_vs_axisym}
shift $(($# < 4 ? $# : 4))
cd "$(dirname "$0")/.."
mkdir -p "$OUT"
common=(--set "cell_size=$CELL" --set duration=0.04 --threads "$THREADS" --quiet "$@")
run() {  # run NAME SCENE [--set ...]
  local name=$1 scene=$2; shift 2
  rm -rf "${OUT:?}/$name"
  local t0=$SECONDS
  "$X" run "scenes/paper/$scene" --out "$OUT/$name" "${common[@]}" "$@" >/dev/null
  echo "rod_3d_vs_axisym: $name done in $((SECONDS - t0)) s" >&2
}
run axisym rod_impact.toml --set "analysis.snapshot_times=[]"
run 3d rod_impact_3d.toml
run 3d_tilt30 rod_impact_3d.toml --set tilt_deg=30
/usr/bin/python3 - "$OUT" <<'PY'
import json, sys
out = sys.argv[1]
def load(name):
    with open(f"{out}/{name}/summary.json") as f:
        return json.load(f)
ref = load("axisym")
print(f"{'run':<12} {'points':>9} {'steps':>6} {'step s':>8} {'final_depth m':>14} {'rel.':>8} "
      f"{'final_velocity m/s':>19} {'rel.':>8} {'peak decel. (force) m/s^2':>26}")
for name in ("axisym", "3d", "3d_tilt30"):
    s = load(name)
    d, v = s["final_depth"], s["final_velocity"]
    rd = "" if name == "axisym" else f"{(d - ref['final_depth']) / ref['final_depth']:+.3f}"
    rv = "" if name == "axisym" else f"{(v - ref['final_velocity']) / ref['final_velocity']:+.3f}"
    pk = s["peak_deceleration_from_force"]["peak_deceleration"]
    print(f"{name:<12} {s['points']:>9} {s['steps']:>6} {sum(s['timings_seconds'].values()):>8.1f} {d:>14.5f} {rd:>8} "
          f"{v:>19.5f} {rv:>8} {pk:>26.1f}")
PY
