#!/bin/bash
# The experiments of docs/results.md "Diagnosis": for one claim, runs of its scene with one change
# at a time from the scene's defaults, each one `oobleck run` (its command is the first line of
# OUT/<variant>_<point>/log.txt), JOBS at a time; a run whose summary.json exists is skipped.
# Then tools/hypotheses_table.py tables the claim's own quantities into OUT/table.md.
#   bash bench/hypotheses.sh CLAIM [BUILD=build/release] [OUT=out/hypotheses_CLAIM] [JOBS=2]
# CLAIM: s3 (intruder fronts; tools/hypotheses_table.py s3_recession OUT tables how far each front ran and fell back at phi 0.47 / v0 0.2 and phi 0.49 / v0 0.5, 1 mm, 20 ms; ~1-2 min
# per run on one thread, the deep bed ~3 min, the 0.5 mm grid ~5 min; 40 runs), s1 (fast bob, 1 mm, 0.1 s; ~1 min per run),
# s2 (rod launched at 0.5, 1, 2 m/s into the large container, 60 ms, 5 / 2.5 mm and 1.5 mm at 1 m/s; the changes at 2.5 mm),
# s4 (fast and slow wheel, 13.3 mm, 1.5 s; 10-20 min per run).
set -euo pipefail
exe() { if [ -d "$1" ]; then echo "$1/oobleck"; else echo "$1"; fi; }
CLAIM=${1:?usage: bench/hypotheses.sh s1|s2|s3|s4 [BUILD] [OUT] [JOBS]}
X=$(realpath -- "$(exe "${2:-build/release}")")
OUT=${3:-out/hypotheses_$CLAIM}
JOBS=${4:-2}
cd "$(dirname "$0")/.."
flip="transfer.scheme=flip transfer.flip_fraction=1.0"
# variant | scene | --set options (space-separated) [| the one point it runs at]; points: a name
# and its --set options
case "$CLAIM" in
  s3)
    s=scenes/paper/intrusion.toml
    variants=("defaults|$s|" "flip|$s|$flip" "linear|$s|grid.shape_function=linear"
      "linear_flip|$s|grid.shape_function=linear $flip" "frictionless|$s|body.0.friction=0"
      "K0_1|$s|K_0=1" "kappa_1e7|$s|kappa=1e7" "ramp_2ms|$s|ramp_time=0.002" "cfl_0.2|$s|time.cfl=0.2"
      "flip_cfl_0.2|$s|$flip time.cfl=0.2" "deep_bed|scenes/paper/intrusion_deep.toml|"
      "drained_d_x10|$s|material.granular.d=5.85e-5" "stiff_G_K_x10|$s|material.granular.G=3.8e8 material.granular.K=8.3e8")
    # grid convergence (a 36 mm tall grid, so that 2 mm cells fit; the bed and intruder as the scene's)
    # (a 0.5 mm run takes 4-5 min on one thread)
    for h in 0.002 0.001 0.0005; do
      variants+=("h${h}|$s|grid.cell_size=$h grid.size=[0.05,0.036]" "flip_h${h}|$s|grid.cell_size=$h grid.size=[0.05,0.036] $flip")
    done
    points=("0.47_0.2|phi=0.47 v0=0.2" "0.49_0.5|phi=0.49 v0=0.5") ;;
  s1)
    s=scenes/paper/annular_shear.toml
    variants=("defaults|$s|" "flip|$s|$flip" "linear|$s|grid.shape_function=linear" "cfl_0.2|$s|time.cfl=0.2"
      "cells_2mm|$s|grid.cell_size=0.002")
    points=("fast|") ;;
  s2)
    # Fig. 8 on 5, 2.5 and 1.5 mm cells (cells divide the 0.15 x 0.225 m grid; the paper's 1 mm takes
    # 95 min per run, 1.5 mm ~22 min, 2.5 mm 2-5 min, 5 mm < 2 min); the set-up and model changes on
    # 2.5 mm cells at v0 = 1 m/s
    s=scenes/paper/rod_impact_large.toml
    variants=("h5mm|$s|cell_size=0.005" "h2.5mm|$s|cell_size=0.0025" "h1.5mm|$s|cell_size=0.0015|v1"
      "h2.5mm_rod_mass_0.1|$s|cell_size=0.0025 rod_mass=0.1|v1" "h2.5mm_rod_mass_1|$s|cell_size=0.0025 rod_mass=1.0|v1"
      "h2.5mm_eta_0_x10|$s|cell_size=0.0025 eta_0=1e-2|v1" "h2.5mm_frictionless|$s|cell_size=0.0025 body.0.friction=0|v1"
      "h2.5mm_flip|$s|cell_size=0.0025 $flip|v1")
    points=("v0.5|v0=0.5" "v1|v0=1" "v2|v0=2") ;;
  s4)
    s=scenes/paper/wheel.toml
    variants=("defaults|$s|" "linear|$s|grid.shape_function=linear" "dt_1e-5|$s|time.dt=1e-5")
    points=("omega10|omega=10" "omega1|omega=1") ;;
  *) echo "hypotheses: unknown claim '$CLAIM' (s1, s2, s3 or s4)" >&2; exit 2 ;;
esac
mkdir -p "$OUT"
jobs_file="$OUT/jobs.txt"
: >"$jobs_file"
for v in "${variants[@]}"; do
  IFS='|' read -r name file sets only <<<"$v"
  for p in "${points[@]}"; do
    IFS='|' read -r pname psets <<<"$p"
    [ -n "$only" ] && [ "$pname" != "$only" ] && continue
    d="$OUT/${name}_${pname}"
    [ -f "$d/summary.json" ] && continue
    args="run $file --out $d --threads 1 --quiet"
    for o in $psets $sets; do args+=" --set $o"; done
    echo "$args" >>"$jobs_file"
  done
done
# the longest runs first (the finest grid, the deep bed), so that the short ones fill in beside them
{ grep -E "cell_size=0\.0005|intrusion_deep" "$jobs_file" || true; grep -vE "cell_size=0\.0005|intrusion_deep" "$jobs_file" || true; } >"$jobs_file.sorted"
mv "$jobs_file.sorted" "$jobs_file"
run_one() {
  local d
  d=$(sed -E 's/.* --out ([^ ]+) .*/\1/' <<<"$2")
  mkdir -p "$d"
  echo "\$ oobleck $2" >"$d/log.txt"
  # shellcheck disable=SC2086
  "$1" $2 >>"$d/log.txt" 2>&1 || echo "hypotheses: failed: oobleck $2 (see $d/log.txt)" >&2
}
export -f run_one
xargs -P "$JOBS" -I{} bash -c 'run_one "$0" "$1"' "$X" {} <"$jobs_file"
/usr/bin/python3 tools/hypotheses_table.py "$CLAIM" "$OUT" | tee "$OUT/table.md"
