#!/usr/bin/python3
"""Plot steady flow curves written by `oobleck rheology flow-curve`, one colour per phi: shear
stress vs shear rate (default), viscosity vs shear rate (--y viscosity) or viscosity vs shear
stress (--x stress --y viscosity), log-log. Every branch is drawn (unstable ones, where the rate
falls as the stress rises, dotted); with --x rate the DST rate (E14) is a dashed vertical line.
With --data, measured points (columns phi, shear_rate, shear_stress) are drawn as markers over the
model curves at the same phi, and the axes span the data unless --xlim/--ylim say otherwise.

usage: plot_flow_curves.py CURVES.csv [--data DATA.csv [--data-label NAME]] [--x rate|stress]
                           [--y stress|viscosity] [--xlim LO,HI] [--ylim LO,HI] [--title T]
                           [--normalized] OUT.png
Lines starting with '#' in either CSV (the `# units: ...` line) are skipped.
"""
import argparse
import math
import os

from matplotlib.lines import Line2D

from oobleck_plot import finite, group_by, plt, read_csv, save


def limits(text, option):
    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        raise SystemExit(f"plot_flow_curves.py: {option} = {text!r}: must be LO,HI") from None
    if not (0 < lo < hi and math.isfinite(hi)):
        raise SystemExit(f"plot_flow_curves.py: {option} = {text!r}: must satisfy 0 < LO < HI (log axes)")
    return lo, hi


def span(values, factor=1.6):
    v = [x for x in values if x > 0 and finite(x)]
    return (min(v) / factor, max(v) * factor) if v else None


ap = argparse.ArgumentParser()
ap.add_argument("csv")
ap.add_argument("out")
ap.add_argument("--title", default="")
ap.add_argument("--normalized", action="store_true")
ap.add_argument("--data", help="measured points: CSV with phi, shear_rate, shear_stress")
ap.add_argument("--data-label", default="", help="names the data in the legend (default: the file name)")
ap.add_argument("--x", choices=["rate", "stress"], default="rate")
ap.add_argument("--y", choices=["stress", "viscosity"], default="stress")
ap.add_argument("--xlim")
ap.add_argument("--ylim")
args = ap.parse_args()
if args.x == "stress" and args.y == "stress":
    raise SystemExit("plot_flow_curves.py: --x stress with --y stress draws the stress against itself")
xlim = limits(args.xlim, "--xlim") if args.xlim else None
ylim = limits(args.ylim, "--ylim") if args.ylim else None


def axes(rate, stress):
    """The plotted (x, y) of points given by shear rate and stress."""
    x = rate if args.x == "rate" else stress
    y = stress if args.y == "stress" else [t / g if g > 0 else math.nan for g, t in zip(rate, stress)]
    return x, y


curves = group_by(read_csv(args.csv), "phi")
data = group_by(read_csv(args.data), "phi") if args.data else {}
phis = sorted(set(curves) | set(data))

# The model's window without data, like the paper's figures: stresses over 1e-2 .. 1e4 tau*,
# estimated from the curves as the stress where f = 1/2 (tau ~ tau* there); the CSV keeps the full range.
ref = []
for c in curves.values():
    i = min(range(len(c["f"])), key=lambda j: abs(c["f"][j] - 0.5 * max(c["f"])))
    ref.append(c["shear_stress"][i])
tau_ref = sorted(ref)[len(ref) // 2] if ref else 1.0
t_lo, t_hi = 1e-2 * tau_ref, 1e4 * tau_ref

fig, ax = plt.subplots(figsize=(8.4, 5.2))
cmap = plt.get_cmap("viridis")
unit_rate, unit_stress, unit_visc = ("", "", "") if args.normalized else (" [1/s]", " [Pa]", " [Pa s]")
norm = " (normalized)" if args.normalized else ""
handles, window_x, window_y = [], [], []
for k, phi in enumerate(phis):
    color = cmap(0.9 * k / max(len(phis) - 1, 1))
    c = curves.get(phi)
    if c:
        g, t = c["shear_rate"], c["shear_stress"]
        x, y = axes(g, t)
        # runs of stable (gamma_dot increasing with tau) and unstable pieces of the curve
        runs, first = [], 0
        for i in range(1, len(g) - 1):
            if (g[i + 1] >= g[i]) != (g[i] >= g[i - 1]):
                runs.append((first, i))
                first = i
        runs.append((first, len(g) - 1))
        for a, b in runs:
            stable = g[b] >= g[a]
            ax.loglog(x[a:b + 1], y[a:b + 1], color=color, lw=1.8 if stable else 1.0, ls="-" if stable else ":")
        for xi, yi, ti in zip(x, y, t):
            if t_lo <= ti <= t_hi:
                window_x.append(xi)
                window_y.append(yi)
        dst = c["shear_rate_dst"][0]
        if finite(dst) and args.x == "rate":
            ax.axvline(dst, color=color, ls="--", lw=0.8)
    d = data.get(phi)
    label = f"φ = {phi:.4g}"
    if d:
        xd, yd = axes(d["shear_rate"], d["shear_stress"])
        ax.loglog(xd, yd, "o", ms=5, color=color, mec="k", mew=0.5, zorder=3)
        label += f"  ({len(xd)} points)"
    handles.append(Line2D([], [], color=color, lw=1.8 if c else 0, marker="o" if d else None, ms=5, mec="k", mew=0.5,
                          label=label))

if data:
    all_x, all_y = [], []
    for d in data.values():
        xd, yd = axes(d["shear_rate"], d["shear_stress"])
        all_x += xd
        all_y += yd
    auto_x, auto_y = span(all_x), span(all_y)
else:
    auto_x, auto_y = span(window_x, 2.0), span(window_y, 2.0)
if xlim or auto_x:
    ax.set_xlim(*(xlim or auto_x))
if ylim or auto_y:
    ax.set_ylim(*(ylim or auto_y))

ax.set_xlabel(f"shear rate γ̇{unit_rate}{norm}" if args.x == "rate" else f"shear stress τ{unit_stress}{norm}")
ax.set_ylabel(f"shear stress τ{unit_stress}{norm}" if args.y == "stress" else f"viscosity η = τ/γ̇{unit_visc}{norm}")
notes = ["lines: model, every branch (dotted: unstable)"]
if args.x == "rate":
    notes.append("dashed: γ̇_DST (E14)")
if data:
    notes.insert(0, "points: " + (args.data_label or os.path.basename(args.data)))
ax.set_title((args.title + "\n" if args.title else "") + "; ".join(notes), fontsize=9)
ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
ax.grid(True, which="major", alpha=0.3)
save(fig, args.out)
