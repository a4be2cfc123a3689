"""Shared helpers for oobleck's matplotlib scripts (run with /usr/bin/python3)."""
import csv
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    """Read a CSV with a header into a dict of column name -> list of floats."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
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
