#!/usr/bin/python3
"""Plot one column of an `oobleck sweep` table against the first varied key, one line per value
of the second varied key (if any). Rows whose status is not ok, or whose cell is empty or not a
number, are left out.

usage: plot_sweep.py SWEEP.csv QUANTITY --x KEY [--group KEY] OUT.png
"""
import argparse
import csv
import math
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError as e:
    sys.exit(f"plot_sweep.py: matplotlib is not available ({e})")


def number(s):
    try:
        x = float(s)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


ap = argparse.ArgumentParser()
ap.add_argument("csv")
ap.add_argument("quantity")
ap.add_argument("out")
ap.add_argument("--x", required=True, help="column on the horizontal axis (the first varied key)")
ap.add_argument("--group", default=None, help="one line per value of this column (the second varied key)")
args = ap.parse_args()

with open(args.csv, newline="") as fh:
    lines = fh.readlines()
while lines and lines[0].startswith("#"):  # the '# units: ...' line
    lines.pop(0)
rows = list(csv.DictReader(lines))
if not rows:
    sys.exit(f"{args.csv}: no rows")
for col in (args.quantity, args.x, args.group):
    if col is not None and col not in rows[0]:
        sys.exit(f"{args.csv}: no column '{col}'")

groups = {}  # group value -> [(x label, x number or None, y)], in file order
for r in rows:
    if r.get("status") != "ok":
        continue
    y = number(r[args.quantity])
    if y is None:
        continue
    g = r[args.group] if args.group else None
    groups.setdefault(g, []).append((r[args.x], number(r[args.x]), y))
if not groups:
    sys.exit(f"{args.csv}: no ok run has a number in column '{args.quantity}'")

numeric_x = all(xn is not None for pts in groups.values() for _, xn, _ in pts)
labels = []  # categorical x: positions in order of first appearance
if not numeric_x:
    for pts in groups.values():
        for xl, _, _ in pts:
            if xl not in labels:
                labels.append(xl)

fig, ax = plt.subplots(figsize=(5.6, 4.2))
for g, pts in groups.items():
    if numeric_x:
        pts = sorted(pts, key=lambda p: p[1])
        xs = [p[1] for p in pts]
    else:
        xs = [labels.index(p[0]) for p in pts]
    ax.plot(xs, [p[2] for p in pts], "o-", label=f"{args.group} = {g}" if args.group else None)
if not numeric_x:
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels)
ax.set_xlabel(args.x)
ax.set_ylabel(args.quantity)
ax.set_title(f"oobleck sweep: {args.quantity}", fontsize=9)
if args.group:
    ax.legend(fontsize=8)
ax.grid(True, alpha=0.3)
fig.tight_layout()
fig.savefig(args.out, dpi=130, format="png")
plt.close(fig)
