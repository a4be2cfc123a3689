#!/usr/bin/env bash
# Bit-for-bit check of the solver against reference outputs: short, coarse runs of the intrusion,
# rod, wheel and annular set-ups on 1 and 2 threads and on 2 MPI ranks, each stopped after a few
# steps (--stop-after: a checkpoint is written there); their checkpoint, frames, series.csv and
# summary.json compared with bench/bitwise_compare.py (every dataset and attribute by its bytes,
# the summary but its wall-time keys).
#
#   bench/bitwise_check.sh record [BIN] [DIR]    runs into DIR (default /work/runs/bitwise-baseline)
#   bench/bitwise_check.sh compare [BIN] [DIR]   runs into a fresh folder, compares with DIR
#
# BIN defaults to build/release/oobleck (a wrapper script that sets LD_LIBRARY_PATH will do).
# TOL (default 1e-12): the largest relative difference allowed on 2 ranks, where a moved
# reduction may change the order of a sum; threads must be identical.
set -euo pipefail
cd "$(dirname "$0")/.."
MODE=${1:?record or compare}
BIN=${2:-build/release/oobleck}
REF=${3:-/work/runs/bitwise-baseline}
TOL=${TOL:-1e-12}
export OMP_WAIT_POLICY=PASSIVE
case $MODE in
  record) OUT=$REF ;;
  compare) OUT=$(mktemp -d /work/runs/bitwise-new.XXXX) ;;
  *) echo "mode: record or compare" >&2; exit 2 ;;
esac
mkdir -p "$OUT"

# name | scene | steps | overrides
CASES=(
  "intrusion|scenes/paper/intrusion.toml|400|--set duration=0.002 --set output.frame_interval=0.0001 --set output.series_interval=0.00001"
  "rod|scenes/paper/rod_impact.toml|600|--set cell_size=0.004 --set duration=0.01 --set output.frame_interval=0.0006 --set output.series_interval=0.00005"
  "wheel|scenes/paper/wheel.toml|600|--set cells=[60,30] --set duration=0.05 --set output.frame_interval=0.003 --set output.series_interval=0.0002 --set analysis.sample_interval=0.0004"
  "annular|scenes/paper/annular_shear.toml|300|--set duration=0.01 --set output.frame_interval=0.001 --set output.series_interval=0.0001"
)

for c in "${CASES[@]}"; do
  IFS='|' read -r name scene steps sets <<<"$c"
  for run in t1 t2 np2; do
    d=$OUT/${name}_$run
    rm -rf "$d"
    # shellcheck disable=SC2086
    case $run in
      t1) nice "$BIN" run "$scene" --out "$d" --threads 1 --stop-after "$steps" --quiet $sets ;;
      t2) nice "$BIN" run "$scene" --out "$d" --threads 2 --stop-after "$steps" --quiet $sets ;;
      np2) nice mpirun --allow-run-as-root --oversubscribe -np 2 -x OMP_WAIT_POLICY \
             "$BIN" run "$scene" --out "$d" --threads 1 --stop-after "$steps" --quiet $sets ;;
    esac >"$OUT/${name}_$run.log" 2>&1 || { echo "${name}_$run: exit status $? (see $OUT/${name}_$run.log)"; exit 1; }
    rm -f "$d"/*.lock "$d"/.lock 2>/dev/null || true
  done
done

if [[ $MODE == compare ]]; then
  /usr/bin/python3 bench/bitwise_compare.py "$REF" "$OUT" "$TOL"
  echo "outputs: $OUT"
fi
