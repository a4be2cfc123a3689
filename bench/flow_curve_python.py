#!/usr/bin/env python3
"""Benchmark (not a test): oobleck.flow_curve calls per second from Python against the C++ Google
Benchmark of the same sweep (bench_flow_curve, BM_FlowCurve/hermes2016_dst/200: hermes2016,
phi = 0.47, 200 points).

  /usr/bin/python3 bench/flow_curve_python.py [BUILD_DIR] [--rounds N] [--seconds S]

BUILD_DIR defaults to build/release (its bench/bench_flow_curve and python/oobleck/_oobleck*.so).
The rates move by +-20 % on a shared machine, so the measurements are interleaved A/B: every
round runs, in a rotating order, the C++ benchmark (a subprocess, --benchmark_min_time=S) and the
three Python calls (S seconds each, in this process); each overhead is C++ rate / Python rate - 1
within a round, and the table shows the median over the rounds (and the range). Rates are per
second of CPU time of the measuring process (Google Benchmark's cpu_time; time.process_time in
Python), which other processes' load disturbs less than wall time; --clock wall for wall time.

  C++ BM_FlowCurve         rheology::flow_curve (the reference of the 20 % budget)
  C++ BM_FlowCurveColumns  the same plus what the module adds in C++ (DST rate, 9 columns)
  raw                      oobleck._core.flow_curve(p, 0.47, 200): the compiled call, a (9, 200) array
  fast path                oobleck.flow_curve(p, 0.47, 200, as_frame=False): dict of numpy arrays
  DataFrame                oobleck.flow_curve(p, 0.47, 200): the pandas DataFrame (the default)
"""
import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("build", nargs="?", default=str(ROOT / "build" / "release"))
ap.add_argument("--rounds", type=int, default=15)
ap.add_argument("--seconds", type=float, default=0.3, help="per measurement")
ap.add_argument("--clock", choices=["cpu", "wall"], default="cpu")
a = ap.parse_args()
BUILD = Path(a.build)
import os  # noqa: E402

os.environ["OOBLECK_BUILD_DIR"] = str(BUILD)
sys.path.insert(0, str(ROOT / "python"))
import numpy as np  # noqa: E402
import oobleck  # noqa: E402

POINTS, PHI = 200, 0.47
p = oobleck.load_params("hermes2016")
core_flow_curve, flow_curve = oobleck._core.flow_curve, oobleck.flow_curve


clock = time.process_time if a.clock == "cpu" else time.perf_counter


def python_rate(call, seconds):
    for _ in range(200):
        call()
    n, t0 = 0, clock()
    while True:
        for _ in range(100):
            call()
        n += 100
        dt = clock() - t0
        if dt >= seconds:
            return n / dt


def cpp_rates(seconds):
    out = subprocess.run([str(BUILD / "bench" / "bench_flow_curve"),
                          "--benchmark_filter=^BM_FlowCurve(Columns)?/hermes2016_dst/200$",
                          "--benchmark_format=json", f"--benchmark_min_time={seconds}"],
                         capture_output=True, text=True, check=True)
    r = {}
    for b in json.loads(out.stdout)["benchmarks"]:
        scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
        r[b["name"].split("/")[0]] = 1.0 / (b["cpu_time" if a.clock == "cpu" else "real_time"] * scale)
    return r["BM_FlowCurve"], r["BM_FlowCurveColumns"]


# Same numbers on every path (the DataFrame and the dict view the same kind of block).
fc, fd = flow_curve(p, PHI, POINTS), flow_curve(p, PHI, POINTS, as_frame=False)
assert list(fc.columns) == list(fd) == list(oobleck.FLOW_CURVE_COLUMNS)
assert all(np.array_equal(fc[k].to_numpy(), fd[k], equal_nan=True) for k in fd)

runs = {
    "raw": lambda: core_flow_curve(p, PHI, POINTS),
    "fast": lambda: flow_curve(p, PHI, POINTS, as_frame=False),
    "frame": lambda: flow_curve(p, PHI, POINTS),
}
steps = ["cpp", "raw", "fast", "frame"]
rates = {k: [] for k in ("cpp", "cols", "raw", "fast", "frame")}
for r in range(a.rounds):
    for step in steps[r % 4:] + steps[:r % 4]:
        if step == "cpp":
            cpp, cols = cpp_rates(a.seconds)
            rates["cpp"].append(cpp)
            rates["cols"].append(cols)
        else:
            rates[step].append(python_rate(runs[step], a.seconds))


def line(label, key):
    med = statistics.median(rates[key])
    s = f"  {label:<44}{med:10.0f} calls/s {1e6 / med:7.2f} us/call"
    if key != "cpp":
        over = [c / x - 1 for c, x in zip(rates["cpp"], rates[key])]
        s += f"   overhead {statistics.median(over):+6.1%} (rounds {min(over):+.1%} .. {max(over):+.1%})"
    print(s)


print(f"flow_curve, hermes2016, phi = {PHI}, {POINTS} points; {a.rounds} interleaved rounds of {a.seconds:g} s "
      f"({a.clock} time); medians")
line("C++ BM_FlowCurve (reference)", "cpp")
line("C++ BM_FlowCurveColumns (+ DST, 9 columns)", "cols")
line("Python _core.flow_curve (raw, (9, N) array)", "raw")
line("Python flow_curve(as_frame=False) (dict)", "fast")
line("Python flow_curve() (DataFrame)", "frame")
