"""Scene runs (two-phase MPM) through the library: run (with progress, checkpoints and restart),
and open_run, which reads a run folder's summary, series and frames."""
from __future__ import annotations

import json
import numbers
import os
import sys
import time as _time
from pathlib import Path

import numpy as np

from . import InputError, _core
from ._args import _integer


class _TextProgress:
    def __init__(self, label):
        self.label, self.last, self.t0 = label, 0.0, _time.monotonic()

    def __call__(self, done, total, sim_time):
        now = _time.monotonic()
        if now - self.last < 1.0 and done < total:
            return
        self.last = now
        print(f"{self.label}: {100.0 * done / total:5.1f}% ({done}/{total} steps, t = {sim_time:.4g} s, "
              f"{now - self.t0:.1f} s)", file=sys.stderr, flush=True)

    def close(self):
        pass


class _TqdmProgress:
    def __init__(self, label, tqdm):
        self.bar, self.n = tqdm(desc=label, unit="step"), 0

    def __call__(self, done, total, sim_time):
        if self.bar.total != total:
            self.bar.total = total
        self.bar.update(done - self.n)
        self.n = done
        self.bar.set_postfix(t=f"{sim_time:.4g} s", refresh=False)

    def close(self):
        self.bar.close()


def _set_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (numbers.Real, np.floating, np.integer)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    return str(v)


def run(scene=None, out=None, threads=None, set=None, progress=True, *, checkpoint_every=None, stop_after=None,
        restart=False) -> dict:
    """Run a scene file (two-phase MPM), as ``oobleck run SCENE --out OUT``; returns the summary
    (summary.json) as a dict.

    scene: the scene file (TOML); out: the run folder (default out/<scene name>); threads: OpenMP
    threads (default all cores); set: {key: value} overrides (``key.path`` or an [aliases] name, as
    --set); progress: a tqdm bar when tqdm is installed, else a text line on stderr every second
    (False: none); checkpoint_every: steps between checkpoints; stop_after: stop (with a
    checkpoint) after this many steps in total; restart=True continues the run in ``out`` from its
    checkpoint (``set`` may then hold [time] keys only, e.g. {"time.cfl": 0.2} after a numerical
    failure). Ctrl-C (SIGINT) stops after the current step, writes a checkpoint and
    summary.json (complete: false) and raises KeyboardInterrupt. The GIL is released while the
    run steps.
    """
    if restart:
        if out is None:
            raise InputError("restart=True: out (the run folder to continue) is required")
        if scene is not None:
            raise InputError("restart=True continues the stored scene of out: give no scene")
        scene_path = ""
    else:
        if not isinstance(scene, (str, os.PathLike)):
            raise InputError(f"scene = {scene!r} ({type(scene).__name__}): must be the path of a scene file (TOML)")
        scene_path = os.fspath(scene)
        if not os.path.exists(scene_path):
            raise InputError(f"scene = {scene_path!r}: no such file")
    if out is not None and not isinstance(out, (str, os.PathLike)):
        raise InputError(f"out = {out!r} ({type(out).__name__}): must be a folder path")
    sets = []
    if set is not None:
        if not isinstance(set, dict):
            raise InputError(f"set = {set!r}: must be a dict {{key: value}}")
        sets = [f"{k}={_set_value(v)}" for k, v in set.items()]
    nthreads = 0 if threads is None else _integer(threads, "threads")
    cp = -1 if checkpoint_every is None else _integer(checkpoint_every, "checkpoint_every")
    stop = -1 if stop_after is None else _integer(stop_after, "stop_after")
    bar = None
    if progress:
        label = Path(scene_path).stem if scene_path else Path(os.fspath(out)).name
        try:
            from tqdm.auto import tqdm
            bar = _TqdmProgress(label, tqdm)
        except ImportError:
            bar = _TextProgress(label)
    try:
        text, out_dir, err = _core.run_scene(scene_path, sets, "" if out is None else os.fspath(out), nthreads, cp,
                                             stop, bool(restart), bar)
    finally:
        if bar is not None:
            bar.close()
    summary = json.loads(text)
    summary.setdefault("out", out_dir)
    if err is not None:
        raise err
    return summary


class Frame:
    """One output frame (frames/frame_N.h5), read lazily with h5py: ``frame.time`` [s],
    ``frame.step``, ``frame.bodies``, ``frame[body][field]`` -> numpy array (position (N, dim),
    scalars (N), vectors (N, 3), tensors (N, 6) or (N, 9)), ``frame.fields(body)``."""

    def __init__(self, path):
        self.path = path
        self._attrs = None

    def _file(self):
        import h5py
        return h5py.File(self.path, "r")

    def _meta(self):
        if self._attrs is None:
            with self._file() as f:
                self._attrs = {"time": float(f.attrs["time"]), "step": int(f.attrs["step"]),
                               "bodies": sorted(f["bodies"].keys()) if "bodies" in f else []}
        return self._attrs

    @property
    def time(self) -> float:
        return self._meta()["time"]

    @property
    def step(self) -> int:
        return self._meta()["step"]

    @property
    def bodies(self) -> list:
        return self._meta()["bodies"]

    def fields(self, body) -> list:
        with self._file() as f:
            return sorted(k for k in f["bodies"][body].keys())

    def __getitem__(self, body):
        frame = self

        class _Body:
            def __getitem__(self, field):
                with frame._file() as f:
                    return np.asarray(f["bodies"][body][field])

            def keys(self):
                return frame.fields(body)

        if body not in self.bodies:
            raise KeyError(f"{body!r}: not a body of {self.path} (bodies: {', '.join(self.bodies)})")
        return _Body()

    def __repr__(self):
        return f"Frame({self.path!r})"


class Run:
    """A run folder opened by :func:`open_run`: ``summary`` (dict), ``series`` (DataFrame of
    series.csv, read on first access), ``frames`` (list of :class:`Frame`, each read lazily),
    ``times`` (simulated time of each frame [s]) and ``field(body, field)`` (list of arrays over
    the frames)."""

    def __init__(self, path):
        self.path = Path(path)
        if not self.path.is_dir():
            raise InputError(f"dir = {os.fspath(path)!r}: not a folder")
        sp = self.path / "summary.json"
        self.summary = json.loads(sp.read_text()) if sp.exists() else None
        self._series = None
        self.frames = [Frame(str(p)) for p in sorted((self.path / "frames").glob("frame_*.h5"))]

    @property
    def series(self):
        if self._series is None:
            import pandas as pd
            self._series = pd.read_csv(self.path / "series.csv", comment="#")
        return self._series

    @property
    def times(self) -> list:
        return [fr.time for fr in self.frames]

    def field(self, body, field) -> list:
        return [fr[body][field] for fr in self.frames]

    def __repr__(self):
        return f"Run({os.fspath(self.path)!r}, {len(self.frames)} frames)"


def open_run(dir) -> Run:
    """Open a run folder (``oobleck run`` or :func:`run`): its summary, series and frames."""
    if not isinstance(dir, (str, os.PathLike)):
        raise InputError(f"dir = {dir!r} ({type(dir).__name__}): must be a folder path")
    return Run(dir)
