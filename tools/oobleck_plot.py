"""Shared helpers for oobleck's matplotlib scripts (run with /usr/bin/python3)."""
import csv
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    """Read a CSV with a header into a dict of column name -> list of floats; lines starting with
    '#' (the `# units: ...` line oobleck writes first) are skipped."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(line for line in fh if not line.startswith("#")))
    if not rows:
        raise SystemExit(f"{path}: no data rows")
    return {k: [float(r[k]) for r in rows] for k in rows[0].keys()}


def group_by(cols, key):
    """Split columns into groups of equal cols[key] (kept in file order)."""
    groups = {}
    for i, v in enumerate(cols[key]):
        groups.setdefault(v, []).append(i)
    return {v: {k: [cols[k][i] for i in idx] for k in cols} for v, idx in groups.items()}


def finite(x):
    return x is not None and not math.isnan(x) and not math.isinf(x)


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=130, format="png")
    plt.close(fig)


# --- run-folder helpers (plot_intrusion.py, plot_rod.py, plot_wheel.py) -------------------------

def frame_nearest(run, t=None, tool="oobleck_plot"):
    """Path of the run's frame file (frames/frame_*.h5) whose time is nearest t seconds; the last
    frame when t is None. SystemExit naming `tool` when the run wrote no frames."""
    import glob
    import os

    import h5py
    import numpy as np

    paths = sorted(glob.glob(os.path.join(run, "frames", "frame_*.h5")))
    if not paths:
        raise SystemExit(f"{tool}: {run}/frames holds no frame_*.h5 (run with output.frame_interval > 0)")
    if t is None:
        return paths[-1]
    times = []
    for p in paths:
        with h5py.File(p, "r") as h:
            times.append(float(h.attrs["time"]))
    return paths[int(np.argmin(np.abs(np.array(times) - t)))]


def need_file(path, what):
    """SystemExit naming the path and what it should have held, unless path is a readable file."""
    import os

    if not os.path.isfile(path):
        raise SystemExit(f"{path}: missing ({what})")
    return path


def load_summary(run, required=True):
    """summary.json of a run folder as a dict; None if absent and not required."""
    import json
    import os

    path = os.path.join(run, "summary.json")
    if not os.path.isfile(path):
        if required:
            raise SystemExit(f"{path}: missing (summary.json is written when `oobleck run` finishes)")
        return None
    with open(path) as fh:
        return json.load(fh)


def need(d, path, *keys):
    """d[k0][k1]... or SystemExit naming the file and the missing key chain."""
    cur = d
    for i, k in enumerate(keys):
        if not isinstance(cur, dict) or k not in cur or cur[k] is None:
            chain = "".join(f"[{k!r}]" for k in keys[: i + 1])
            raise SystemExit(f"{path}: no {chain}")
        cur = cur[k]
    return cur


def load_scene(run):
    """The scene.toml copied into a run folder as a dict, or {} when absent/unreadable."""
    import os

    path = os.path.join(run, "scene.toml")
    try:
        import tomllib

        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except (OSError, ImportError, ValueError):
        return {}


def scene_body(scene, name):
    """The [[body]] entry called name in a scene dict, or {}."""
    for b in scene.get("body", []) or []:
        if b.get("name") == name:
            return b
    return {}


def read_snapshot(path):
    """A nodal snapshot CSV -> (time, x, y, fields): x, y the 1-D node coordinates and fields a dict
    of 2-D numpy arrays indexed [iy, ix] (rows are written x fastest)."""
    import re

    import numpy as np

    need_file(path, "nodal snapshot CSV")
    with open(path) as fh:
        first = fh.readline()
        header = fh.readline().strip().split(",")
    m = re.search(r"t\s*=\s*([-+0-9.eE]+)", first)
    if not m or "x" not in header or "y" not in header:
        raise SystemExit(f"{path}: not a snapshot (expected '# t = ...' then a header with x,y,...)")
    data = np.loadtxt(path, delimiter=",", skiprows=2, ndmin=2)
    if data.shape[0] == 0:
        raise SystemExit(f"{path}: no data rows")
    ycol = data[:, header.index("y")]
    nx = int(np.sum(ycol == ycol[0]))
    ny = data.shape[0] // nx
    if nx * ny != data.shape[0]:
        raise SystemExit(f"{path}: {data.shape[0]} rows are not a regular grid (nx = {nx})")
    fields = {h: data[:, i].reshape(ny, nx) for i, h in enumerate(header)}
    return float(m.group(1)), fields["x"][0, :].copy(), fields["y"][:, 0].copy(), fields


def run_title(s, extra=""):
    """One title line: scene, phi, eta_0, K_0 and the resolution, from a summary dict."""
    p = s.get("parameters", {})
    cells = p.get("cells")
    res = f"{cells[0]}×{cells[1]} cells" if cells else "? cells"
    h = p.get("cell_size")
    if h is not None:
        res += f" of {h * 1e3:.3g} mm"
    bits = [s.get("scene", "?"), f"φ = {p.get('phi', '?')}", f"η_0 = {p.get('eta_0', float('nan')) * 1e3:.3g} mPa·s",
            f"K_0 = {p.get('K_0', '?')}", res]
    return ", ".join(bits) + (f", {extra}" if extra else "")
