#!/bin/bash
# Point-update throughput vs number of points (issue 4: "the scaling with points"): the two
# authors' set-ups (bench/scenes) at several resolutions, 1 and 2 threads, a fixed number of
# steps each. Prints one line per run: scene, cells, points, threads, steps, wall s, updates/s.
#   bash bench/scaling_with_points.sh [build/release/oobleck] > scaling.txt
# Run it on an otherwise idle machine: wall times are the measurement.
set -euo pipefail
B=${1:-build/release/oobleck}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# OpenMP threads spin between parallel regions by default (fast on an idle machine; on a busy one
# set OMP_WAIT_POLICY=PASSIVE, as the tests do).
printf "%-24s %-10s %8s %3s %6s %8s %10s\n" scene cells points thr steps wall_s updates/s
run() {  # scene cells_setting label steps dt threads
  local scene=$1 set=$2 label=$3 steps=$4 dt=$5 thr=$6
  "$B" run "bench/scenes/$scene.toml" --out "$out/r" --threads "$thr" --quiet $set \
       --set time.dt="$dt" --set time.duration="$(awk "BEGIN{print $steps*$dt}")" >/dev/null
  /usr/bin/python3 - "$out/r/summary.json" "$scene" "$label" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"{sys.argv[2]:<24} {sys.argv[3]:<10} {s['points']:8d} {s['threads']:3d} {s['steps']:6d} {s['wall_seconds']:8.2f} {s['point_updates_per_second']:10.3e}")
PY
  rm -rf "$out/r"
}
for thr in 1 2; do
  # (a) axisymmetric intruder set-up: 2.5 mm / 1 mm / 0.5 mm cells of the 50 x 35 mm grid
  run intruder_authors_setup "--set grid.cell_size=0.0025" "20x14" 1000 2e-6 $thr
  run intruder_authors_setup "" "50x35" 1000 1e-6 $thr
  run intruder_authors_setup "--set grid.cell_size=0.0005" "100x70" 400 5e-7 $thr
  # (b) plane-strain wheel set-up
  run wheel_authors_setup "--set grid.cells=[60,30]" "60x30" 1000 2e-5 $thr
  run wheel_authors_setup "" "150x75" 1000 2e-5 $thr
  run wheel_authors_setup "--set grid.cells=[300,150]" "300x150" 300 1e-5 $thr
done
