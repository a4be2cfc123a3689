#!/usr/bin/env bash
# Cross-code comparison on the S3 intruder (docs/cross_code.md): the authors' code
# (aaronbaumgarten/mpm_3d, built from source, run as is) against oobleck in the authors'
# configuration, and oobleck with one choice at a time switched back to the scene's default.
#
#   bash bench/cross_code/run.sh [all|build|mpm3d|oobleck|table]     (default: all)
#
# Environment: OUT (default out/cross_code), MPM3D_DIR (default $OUT/mpm_3d: clone + build),
# OOBLECK (default build/release/oobleck), PY (default /usr/bin/python3).
# One simulation at a time, single-threaded; the mpm_3d build runs at -j1 (about 15 min on one
# free core), its runs take about 9 + 3 min (the cases) and 3 min (the plain-linear and first-
# millisecond runs), the oobleck runs 4-28 s each.
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
OUT=${OUT:-$ROOT/out/cross_code}
MPM3D_DIR=${MPM3D_DIR:-$OUT/mpm_3d}
OOBLECK=${OOBLECK:-$ROOT/build/release/oobleck}
PY=${PY:-/usr/bin/python3}
COMMIT=a3d0701fcea15fe67e40b7ec5fee87d84a2717ed   # mpm_3d HEAD used in docs/cross_code.md
what=${1:-all}
mkdir -p "$OUT"

# case name, phi, v0, duration [s]
CASES=("phi047_v02 0.47 0.2 0.012" "phi049_v05 0.49 0.5 0.004")
FRAME=0.00025   # [s] frame interval of both codes

build_mpm3d() {
  if [ ! -d "$MPM3D_DIR/.git" ]; then
    git clone https://github.com/aaronbaumgarten/mpm_3d "$MPM3D_DIR"
  fi
  git -C "$MPM3D_DIR" checkout -q "$COMMIT"
  echo "mpm_3d at $(git -C "$MPM3D_DIR" rev-parse HEAD)"
  mkdir -p "$MPM3D_DIR/build"
  (cd "$MPM3D_DIR/build" && cmake .. > cmake.log && nice cmake --build . -j1 > build.log 2>&1)
  ls -l "$MPM3D_DIR/build/mpm_v3"
}

mpm3d_case() {   # dir phi v0 duration frame_interval cpdi
  "$PY" bench/cross_code/mpm3d_case.py --phi "$2" --v0 "$3" --duration "$4" --frame-interval "$5" --cpdi "$6" --out "$1"
  (cd "$1" && /usr/bin/time -v "$MPM3D_DIR/build/mpm_v3" -c intrusion.cfg > log.txt 2> time.txt)
  grep -E "Elapsed \(wall" "$1/time.txt"
}

# Their solver's default shape functions (cpdi_spec 1: linear, averaged over each point's domain
# where it straddles a grid line) are the reference; their plain linear functions (cpdi_spec 0)
# fail by 2.5 ms (phi 0.47) and 1.5 ms (phi 0.49), and are compared up to then.
run_mpm3d() {
  for c in "${CASES[@]}"; do
    set -- $c
    mpm3d_case "$OUT/mpm3d/$1" "$2" "$3" "$4" $FRAME 1
    mpm3d_case "$OUT/mpm3d/${1}_linear" "$2" "$3" "$4" $FRAME 0
  done
  mpm3d_case "$OUT/mpm3d/early_phi047_v02" 0.47 0.2 0.001 0.00005 1   # the first millisecond, 0.05 ms frames
}

# oobleck in the authors' configuration (linear, pure FLIP, frictionless, dt 1e-6; the scene's
# hydrostatic initial state equals their input's, see docs/cross_code.md), then one choice at a
# time back to the scene's default, the mass floor off, and the noise floor (dt / 2).
# key=value pairs of the matched configuration; a variant replaces or drops one of them
MATCHED="grid.shape_function=linear transfer.scheme=flip transfer.flip_fraction=1.0 body.0.friction=0 time.dt=1e-6"
variant_args() {   # variant name -> --set arguments
  local v=$1 kv
  local -A m=()
  for kv in $MATCHED; do m[${kv%%=*}]=${kv#*=}; done
  case $v in
    matched) ;;
    quadratic) m[grid.shape_function]=quadratic ;;                       # the scene's default kernel
    apic) unset 'm[transfer.scheme]' 'm[transfer.flip_fraction]' ;;        # the scene's default transfer (APIC)
    friction) m[body.0.friction]=0.3 ;;                                   # the scene's intruder friction
    dt_cfl) unset 'm[time.dt]' ;;                                         # the default step, cfl 0.4
    no_mass_floor) m[grid.linear_mass_floor]=0 ;;                         # oobleck's linear mass floor off
    dt_half) m[time.dt]=5e-7 ;;                                           # noise floor: the matched run at dt / 2
    ugimp) m[grid.shape_function]=ugimp ;;                                # uGIMP (half-width h/4), nearest to their cpdi_spec 1
    *) echo "unknown variant $v" >&2; exit 2 ;;
  esac
  for kv in "${!m[@]}"; do printf -- '--set\n%s=%s\n' "$kv" "${m[$kv]}"; done
}
VARIANTS=(matched quadratic apic friction dt_cfl no_mass_floor dt_half ugimp)

run_oobleck() {
  for c in "${CASES[@]}"; do
    set -- $c
    for v in "${VARIANTS[@]}"; do
      mapfile -t args < <(variant_args "$v")
      "$OOBLECK" run scenes/paper/intrusion.toml --set phi="$2" --set v0="$3" --set duration="$4" \
        --set output.frame_interval=$FRAME "${args[@]}" --out "$OUT/oobleck/$1/$v" --threads 1 --quiet \
        || echo "$1/$v: oobleck exited with $?"
    done
  done
  mapfile -t args < <(variant_args matched)
  "$OOBLECK" run scenes/paper/intrusion.toml --set phi=0.47 --set v0=0.2 --set duration=0.001 \
    --set output.frame_interval=0.00005 "${args[@]}" --out "$OUT/oobleck/early_phi047_v02/matched" --threads 1 --quiet
}

table() {
  mkdir -p "$OUT/tables"
  for c in "${CASES[@]}"; do
    set -- $c
    runs=()
    for v in "${VARIANTS[@]}"; do runs+=(--run "$v=$OUT/oobleck/$1/$v"); done
    # (a) and (b): every oobleck run against the authors' code; (c) against the matched oobleck run
    "$PY" tools/cross_code.py --ref "mpm_3d=$OUT/mpm3d/$1" "${runs[@]}" --run "mpm_3d_linear=$OUT/mpm3d/${1}_linear" \
      --v0 "$3" --times 0.002 0.004 0.008 --window 0.001 --csv-dir "$OUT/tables/$1" \
      --plot "$OUT/tables/$1.png" | tee "$OUT/tables/$1.txt"
    "$PY" tools/cross_code.py --ref "mpm_3d=$OUT/mpm3d/$1" --run "matched=$OUT/oobleck/$1/matched" \
      --run "quadratic=$OUT/oobleck/$1/quadratic" --v0 "$3" --plot-fronts "$OUT/tables/${1}_fronts.png" > /dev/null
    "$PY" tools/cross_code.py --ref "matched=$OUT/oobleck/$1/matched" "${runs[@]:2}" --v0 "$3" \
      --times 0.002 0.004 0.008 --window 0.001 | tee "$OUT/tables/${1}_vs_matched.txt"
  done
  "$PY" tools/cross_code.py --ref "mpm_3d=$OUT/mpm3d/early_phi047_v02" \
    --run "matched=$OUT/oobleck/early_phi047_v02/matched" --v0 0.2 \
    --times 0.00005 0.0001 0.0002 0.0005 | tee "$OUT/tables/early_phi047_v02.txt"
}

case $what in
  all) build_mpm3d; run_mpm3d; run_oobleck; table ;;
  build) build_mpm3d ;;
  mpm3d) run_mpm3d ;;
  oobleck) run_oobleck ;;
  table) table ;;
  *) echo "usage: $0 [all|build|mpm3d|oobleck|table]" >&2; exit 1 ;;
esac
