"""A long call releases the GIL (another Python thread progresses meanwhile), and SIGINT during
oobleck.run stops it within one second with a valid checkpoint."""
import json
import os
import signal
import subprocess
import sys
import threading
import time

import oobleck


def test_long_call_releases_the_gil():
    counter = [0]
    done = threading.Event()

    def spin():
        while not done.is_set():
            counter[0] += 1

    t = threading.Thread(target=spin)
    t.start()
    time.sleep(0.05)
    before = counter[0]
    t0 = time.perf_counter()
    oobleck.point_shear("hermes2016", 0.44, shear_rate=10, duration=2.0, samples=10)  # ~0.5 s of C++
    elapsed = time.perf_counter() - t0
    during = counter[0] - before
    done.set()
    t.join()
    assert elapsed > 0.1
    # the spinning thread ran throughout (millions of increments per second when it holds the GIL)
    assert during > 10000 * elapsed, (during, elapsed)


SCRIPT = r"""
import faulthandler, signal, sys
faulthandler.register(signal.SIGUSR1)  # the test's diagnosis if the run does not stop
# Ctrl-C as at a terminal: a shell that starts the tests in the background (`nohup ... &`) hands
# them SIGINT ignored, and Python then installs no KeyboardInterrupt handler.
signal.signal(signal.SIGINT, signal.default_int_handler)
sys.path.insert(0, sys.argv[1])
import oobleck
try:
    oobleck.run(sys.argv[2], sys.argv[3], threads=1, set={"time.duration": 20.0}, progress=False)
except KeyboardInterrupt:
    print("interrupted", flush=True)
    sys.exit(130)
"""


def test_sigint_stops_run_with_checkpoint(root, tmp_path):
    out = tmp_path / "run"
    scene = root / "scenes" / "verification" / "settling.toml"
    env = dict(os.environ)
    p = subprocess.Popen([sys.executable, "-c", SCRIPT, str(root / "python"), str(scene), str(out)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    deadline = time.monotonic() + 30
    while not (out / "series.csv").exists() and time.monotonic() < deadline:  # the run is stepping
        time.sleep(0.05)
    time.sleep(0.5)
    t0 = time.monotonic()
    p.send_signal(signal.SIGINT)
    try:
        stdout, stderr = p.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        p.send_signal(signal.SIGUSR1)  # every thread's Python stack to stderr
        time.sleep(0.5)
        p.kill()
        stdout, stderr = p.communicate()
        raise AssertionError(f"the run did not stop within 10 s of SIGINT; its stderr:\n{stderr}") from None
    elapsed = time.monotonic() - t0
    assert p.returncode == 130 and "interrupted" in stdout, stderr
    assert elapsed < 1.0, elapsed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"] is False and 0 < summary["steps"]
    assert (out / "checkpoint.h5").exists()
    # the checkpoint is valid: the run continues from it, bit for bit in step count
    s = oobleck.run(out=out, restart=True, stop_after=summary["steps"] + 10, progress=False)
    assert s["steps"] == summary["steps"] + 10 and s["steps_this_run"] == 10
