#!/bin/bash
# S4 in 3D against the plane-strain S4 (issue 28; docs/results.md "S2 and S4 in 3D"), at the same
# cell size and time step. Two modes:
#   periodic: scenes/paper/wheel_3d.toml --set width_periodic=true (a slab of bed and wheel
#             periodic across the width) against scenes/paper/wheel.toml, at omega = 10 rad/s;
#   finite:   the 0.3 m wide wheel on the 0.6 m walled bed (wheel_3d.toml as it is) against
#             wheel.toml, at omega = 10 and 1 rad/s.
# Prints each run's hub height (final, minimum), height loss, distance travelled and the 3D runs'
# relative differences from plane strain. NX cells along the 2 m track (a multiple of 15, so that
# the slab's 0.133 m and the bed's 0.6 m are whole cells: 60 = 33.3 mm, 90 = 22.2 mm, 150 = the
# scenes' 13.3 mm). Extra arguments go to every run (e.g. --set time.dt=4e-5).
#   bash bench/wheel_3d_vs_plane.sh MODE [BUILD=build/release] [NX=90] [DURATION=0.5] [THREADS=2] [OUT=out/wheel_3d_MODE]
set -euo pipefail
MODE=${1:?usage: wheel_3d_vs_plane.sh periodic|finite [BUILD] [NX] [DURATION] [THREADS] [OUT] [--set ...]}
exe() { if [ -d "$1" ]; then echo "$1/oobleck"; else echo "$1"; fi; }
X=$(realpath -- "$(exe "${2:-build/release}")")
NX=${3:-90}
DURATION=${4:-0.5}
THREADS=${5:-2}
OUT=${6:-out/wheel_3d_$MODE}
shift $(($# < 6 ? $# : 6))
if [ $((NX % 15)) -ne 0 ]; then
  echo "wheel_3d_vs_plane: NX = $NX is not a multiple of 15" >&2
  exit 2
fi
case $MODE in
  periodic) NY=$((NX / 15)); OMEGAS="10"; VARIANT=(--set width_periodic=true) ;;
  finite) NY=$((NX * 3 / 10)); OMEGAS="10 1"; VARIANT=() ;;
  *) echo "wheel_3d_vs_plane: MODE is periodic or finite, not '$MODE'" >&2; exit 2 ;;
esac
NZ=$((NX / 2))
cd "$(dirname "$0")/.."
mkdir -p "$OUT"
common=(--set "duration=$DURATION" --set output.frame_interval=0.1 --threads "$THREADS" --quiet "$@")
run() {  # run NAME SCENE [--set ...]
  local name=$1 scene=$2; shift 2
  rm -rf "${OUT:?}/$name"
  local t0=$SECONDS
  "$X" run "scenes/paper/$scene" --out "$OUT/$name" "${common[@]}" "$@" >/dev/null
  echo "wheel_3d_vs_plane: $name done in $((SECONDS - t0)) s" >&2
}
for w in $OMEGAS; do
  run "plane_omega$w" wheel.toml --set "cells=[$NX, $NZ]" --set "omega=$w" --set "analysis.snapshot_times=[]"
  run "3d_omega$w" wheel_3d.toml "${VARIANT[@]}" --set "cells=[$NX, $NY, $NZ]" --set "omega=$w"
done
/usr/bin/python3 - "$OUT" "$OMEGAS" <<'PY'
import json, sys
out, omegas = sys.argv[1], sys.argv[2].split()
def load(name):
    with open(f"{out}/{name}/summary.json") as f:
        return json.load(f)
print(f"{'run':<14} {'points':>8} {'steps':>6} {'step s':>8} {'hub final m':>12} {'rel.':>7} {'hub min m':>10} "
      f"{'loss m':>8} {'distance m':>11} {'rel.':>7} {'on surface':>10}")
for w in omegas:
    ref = load(f"plane_omega{w}")
    for name in (f"plane_omega{w}", f"3d_omega{w}"):
        s = load(name)
        a = s
        h, d = a["hub_height_final"], a["distance"]
        rh = "" if name.startswith("plane") else f"{(h - ref['hub_height_final']) / ref['hub_height_final']:+.3f}"
        rd = "" if name.startswith("plane") else f"{(d - ref['distance']) / abs(ref['distance']):+.3f}"
        print(f"{name:<14} {s['points']:>8} {s['steps']:>6} {sum(s['timings_seconds'].values()):>8.1f} {h:>12.4f} {rh:>7} "
              f"{a['hub_height_min']:>10.4f} {a['height_loss']:>8.4f} {d:>11.4f} {rd:>7} {str(a['runs_on_surface']):>10}")
PY
