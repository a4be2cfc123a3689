#!/usr/bin/env bash
# What a second thread gains on this host (bench/host_ceiling.cpp): runs the kernels on 1 and 2
# threads and prints, per kernel, the aggregate rate on 2 threads over the rate on 1. No program
# gains more from a second thread than the `compute` ratio in its compute-bound parts; the stream
# ratios are reference points for memory-bound loops. The ratios drift on shared hosts.
#   usage: bash bench/host_ceiling.sh [BUILD_DIR=build/release]
set -euo pipefail
build=$(realpath "${1:-build/release}")
exe="$build/bench/bench_host_ceiling"
if [[ ! -x "$exe" ]]; then
  echo "host_ceiling.sh: $exe not found (build the bench targets: cmake --build $build)" >&2
  exit 1
fi
json=$(mktemp)
trap 'rm -f "$json"' EXIT
"$exe" --benchmark_format=json --benchmark_out="$json" --benchmark_out_format=json >/dev/null
/usr/bin/python3 - "$json" <<'PY'
import json, re, sys
runs = json.load(open(sys.argv[1]))["benchmarks"]
rate = {}
for r in runs:
    m = re.match(r"([a-z_0-9]+)/.*threads:(\d+)", r["name"])
    rate[(m.group(1), int(m.group(2)))] = r["items_per_second"]
print(f"{'kernel':<12} {'1 thread':>12} {'2 threads':>12} {'2 / 1':>7}")
for k in ["compute", "stream_l2", "stream_l3", "stream_mem"]:
    unit = "madd/s" if k == "compute" else "B/s"
    a, b = rate[(k, 1)], rate[(k, 2)]
    print(f"{k:<12} {a:12.3e} {b:12.3e} {b / a:7.2f}   ({unit}, summed over threads)")
PY
