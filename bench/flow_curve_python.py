#!/usr/bin/env python3
"""Benchmark (not a test): oobleck.flow_curve calls per second from Python against the C++
Google Benchmark of the same sweep (bench_flow_curve, BM_FlowCurve/hermes2016_dst/200).

  /usr/bin/python3 bench/flow_curve_python.py [BUILD_DIR]     (default build/release)

Prints both rates and the Python overhead: (C++ rate / Python rate - 1), for the raw module call
(_oobleck.flow_curve, arrays) and for oobleck.flow_curve (a pandas DataFrame).
"""
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BUILD = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "build" / "release"
sys.path.insert(0, str(ROOT / "python"))
import oobleck  # noqa: E402

POINTS, PHI = 200, 0.47


def rate(f, seconds=2.0):
    f()
    n, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        f()
        n += 1
    return n / (time.perf_counter() - t0)


p = oobleck.load_params("hermes2016")
raw = rate(lambda: oobleck._core.flow_curve(p, [PHI], POINTS))
df = rate(lambda: oobleck.flow_curve(p, PHI, POINTS))
out = subprocess.run([str(BUILD / "bench" / "bench_flow_curve"), "--benchmark_filter=hermes2016_dst/200$",
                      "--benchmark_format=json", "--benchmark_min_time=2"], capture_output=True, text=True, check=True)
b = json.loads(out.stdout)["benchmarks"][0]
cpp = 1e9 / b["real_time"] if b["time_unit"] == "ns" else b["iterations"] / (b["real_time"] * 1e-6)
print(f"flow_curve, hermes2016, phi = {PHI}, {POINTS} points")
print(f"  C++ (Google Benchmark)      {cpp:10.0f} calls/s")
print(f"  Python, _oobleck (arrays)   {raw:10.0f} calls/s   overhead {cpp / raw - 1:+.1%}")
print(f"  Python, oobleck (DataFrame) {df:10.0f} calls/s   overhead {cpp / df - 1:+.1%}")
