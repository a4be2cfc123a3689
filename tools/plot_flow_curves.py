#!/usr/bin/python3
"""Plot steady flow curves written by `oobleck rheology flow-curve`: mixture shear stress vs
shear rate (log-log), one curve per phi, with the DST rate (E14) as a dashed asymptote.
Unstable branches (d gamma_dot/d tau < 0) are drawn thin.

usage: plot_flow_curves.py CURVES.csv [--title T] OUT.png
"""
import argparse

from oobleck_plot import finite, group_by, plt, read_csv, save

ap = argparse.ArgumentParser()
ap.add_argument("csv")
ap.add_argument("out")
ap.add_argument("--title", default="")
ap.add_argument("--normalized", action="store_true")
args = ap.parse_args()

cols = read_csv(args.csv)
curves = group_by(cols, "phi")
# Window like the paper's figures: stresses over 1e-2 .. 1e4 tau*, estimated from the curves as
# the stress where f = 1/2 (tau ~ tau* there); the CSV keeps the full range.
ref = []
for c in curves.values():
    i = min(range(len(c["f"])), key=lambda j: abs(c["f"][j] - 0.5 * max(c["f"])))
    ref.append(c["shear_stress"][i])
tau_ref = sorted(ref)[len(ref) // 2]
t_lo, t_hi = 1e-2 * tau_ref, 1e4 * tau_ref

fig, ax = plt.subplots(figsize=(6.4, 4.8))
cmap = plt.get_cmap("viridis")
n = len(curves)
g_lo, g_hi = float("inf"), 0.0
for k, (phi, c) in enumerate(sorted(curves.items())):
    color = cmap(k / max(n - 1, 1))
    g, t = c["shear_rate"], c["shear_stress"]
    # split into runs of stable (gamma_dot increasing with tau) and unstable pieces
    runs, first = [], 0
    for i in range(1, len(g) - 1):
        if (g[i + 1] >= g[i]) != (g[i] >= g[i - 1]):
            runs.append((first, i))
            first = i
    runs.append((first, len(g) - 1))
    for j, (a, b) in enumerate(runs):
        stable = g[b] >= g[a]
        ax.loglog(g[a:b + 1], t[a:b + 1], color=color, lw=1.8 if stable else 0.8,
                  ls="-" if stable else ":", label=f"φ = {phi:.3f}" if j == 0 else None)
    for gi, ti in zip(g, t):
        if t_lo <= ti <= t_hi and gi > 0:
            g_lo, g_hi = min(g_lo, gi), max(g_hi, gi)
    dst = c["shear_rate_dst"][0]
    if finite(dst):
        ax.axvline(dst, color=color, ls="--", lw=0.8)
units = "(normalized)" if args.normalized else ""
ax.set_xlabel(f"shear rate γ̇ [1/s] {units}")
ax.set_ylabel(f"shear stress τ [Pa] {units}")
ax.set_ylim(t_lo, t_hi)
if g_hi > 0:
    ax.set_xlim(g_lo / 2, g_hi * 2)
ax.set_title(args.title + "\n(dashed: γ̇_DST, E14; dotted: unstable branch)", fontsize=9)
ax.legend(fontsize=7, loc="upper left")
ax.grid(True, which="major", alpha=0.3)
save(fig, args.out)
