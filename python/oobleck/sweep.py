"""``oobleck.sweep``: a grid of scene runs through the ``oobleck sweep`` command line, its table
(sweep.csv) as a pandas DataFrame."""
from __future__ import annotations

import numbers
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

_ROOT = Path(__file__).resolve().parent.parent.parent  # the checkout (a development tree)


def _find_executable(executable=None) -> str:
    """The ``oobleck`` executable: ``executable`` if given, else $OOBLECK_BUILD_DIR/oobleck, the
    one on PATH, or build/release/oobleck of this checkout."""
    if executable is not None:
        return os.fspath(executable)
    candidates = []
    if os.environ.get("OOBLECK_BUILD_DIR"):
        candidates.append(Path(os.environ["OOBLECK_BUILD_DIR"]) / "oobleck")
    on_path = shutil.which("oobleck")
    if on_path:
        candidates.append(Path(on_path))
    candidates.append(_ROOT / "build" / "release" / "oobleck")
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return str(c)
    from . import InputError
    raise InputError("sweep: the oobleck executable was not found (looked in $OOBLECK_BUILD_DIR, PATH and "
                     f"{_ROOT / 'build' / 'release'}): pass executable=PATH")


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(float(v))  # (numpy's float64 is a float whose repr is not the number alone)
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        return repr(float(v))
    return str(v)


def _spec(key, values) -> str:
    """A --vary SPEC: a string is passed as written (``"0.46:0.50:0.01"`` or ``"0.2,0.5"``), a
    sequence becomes a comma list."""
    from . import InputError
    if isinstance(values, str):
        return values
    if isinstance(values, (numbers.Number, bool)):
        return _value(values)
    try:
        items = list(values)
    except TypeError:
        raise InputError(f"vary[{key!r}] = {values!r}: must be a list of values or a SPEC string") from None
    if not items:
        raise InputError(f"vary[{key!r}]: no values")
    for v in items:
        if isinstance(v, str) and ("," in v or ":" in v):
            raise InputError(f"vary[{key!r}]: value {v!r} holds ',' or ':', which a --vary SPEC cannot")
    return ",".join(_value(v) for v in items)


def sweep(scene, vary: dict, jobs: int = 1, out=None, sets=None, threads=None, *, plot=None, executable=None,
          check: bool = False, progress: bool = True):
    """Run ``scene`` over the grid of ``vary`` as ``oobleck sweep`` and return sweep.csv as a DataFrame.

    scene: the scene file (TOML); vary: {key: values}, key a scene key or an [aliases] name
    (as ``--set``), values a list (``[0.2, 0.5]``) or a SPEC string (``"0.46:0.50:0.01"``, stop
    included); the runs are the Cartesian product, the last key varying fastest. jobs: runs at a
    time; out: the sweep folder (default out/sweep_<scene stem>; each run in out/<run>/, complete
    runs are skipped and stopped ones continued when called again); sets: {key: value} set in every
    run; threads: OpenMP threads per run; plot: a column to plot (out/<plot>.png); executable: the
    ``oobleck`` command line (default $OOBLECK_BUILD_DIR/oobleck, PATH, or build/release/oobleck
    of this checkout); progress: pass the command's progress lines (one per run started and
    finished) to stderr.

    Returns a DataFrame with one row per run: a column per varied key, ``run`` (the folder's name),
    every scalar of the run's summary.json under its dotted key, ``status`` (ok / failed) and
    ``message``; ``df.attrs["units"]`` holds the units that sweep.csv's first line gives ({column: unit}).
    Failed runs are rows (the command's exit status 3, ``df.attrs["returncode"]``);
    check=True raises NumericalError instead. Bad input raises InputError with the command's
    message. Ctrl-C stops the running runs with checkpoints (calling again resumes) and raises
    KeyboardInterrupt.
    """
    from . import InputError, NumericalError
    import pandas as pd

    if not isinstance(scene, (str, os.PathLike)):
        raise InputError(f"scene = {scene!r} ({type(scene).__name__}): must be the path of a scene file (TOML)")
    if not isinstance(vary, dict) or not vary:
        raise InputError(f"vary = {vary!r}: must be a non-empty dict {{key: values}}")
    scene = os.fspath(scene)
    if out is None:
        out = os.path.join("out", "sweep_" + Path(scene).stem)
    args = [_find_executable(executable), "sweep", scene, "--out", os.fspath(out)]
    for key, values in vary.items():
        args += ["--vary", f"{key}={_spec(key, values)}"]
    if sets:
        if not isinstance(sets, dict):
            raise InputError(f"sets = {sets!r}: must be a dict {{key: value}}")
        for key, value in sets.items():
            args += ["--set", f"{key}={_value(value)}"]
    if isinstance(jobs, bool) or not isinstance(jobs, numbers.Integral):
        raise InputError(f"jobs = {jobs!r}: must be an integer >= 1")
    args += ["--jobs", str(int(jobs))]
    if threads is not None:
        if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
            raise InputError(f"threads = {threads!r}: must be an integer >= 0")
        args += ["--threads", str(int(threads))]
    if plot is not None:
        args += ["--plot", str(plot)]
    # Its own session: a Ctrl-C at the terminal reaches Python only, which passes it on once (the
    # sweep forwards it to its runs, which stop with checkpoints, and writes sweep.csv).
    tail = []
    with subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          start_new_session=True) as p:
        try:
            for line in p.stdout:
                tail = (tail + [line.rstrip("\n")])[-20:]
                if progress:
                    print(line, end="", file=sys.stderr, flush=True)
            p.wait()
        except KeyboardInterrupt:
            p.send_signal(signal.SIGINT)
            p.wait()
            raise
    returncode = p.returncode
    errors = [line for line in tail if line.startswith("oobleck")]
    message = (errors or tail or [f"exit {returncode}"])[-1]
    if returncode not in (0, 3):
        if returncode == 2:
            raise InputError(message)
        raise NumericalError(f"oobleck sweep failed (exit {returncode}): {message}")
    if returncode == 3 and check:
        raise NumericalError(message)
    path = Path(out) / "sweep.csv"
    units, comments = {}, 0  # the leading '# units: name=unit, ...' line
    with open(path) as fh:
        for line in fh:
            if not line.startswith("#"):
                break
            comments += 1
            if line.startswith("# units:"):
                units.update(item.strip().split("=", 1) for item in line[len("# units:"):].split(",") if "=" in item)
    df = pd.read_csv(path, skiprows=comments, float_precision="round_trip", keep_default_na=False, na_values=[""])
    df.attrs["units"] = units
    df.attrs["out"] = os.fspath(out)
    df.attrs["returncode"] = returncode
    return df
