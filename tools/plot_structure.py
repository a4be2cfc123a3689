#!/usr/bin/python3
"""Plot the steady structure f(tau) of the model (eta_B -> infinity) beside the forms of
Wyart & Cates (2014) and Singh et al. (2018) (paper SI figure).

usage: plot_structure.py STRUCTURE.csv [--tau-star T] [--title T] OUT.png
"""
import argparse

from oobleck_plot import plt, read_csv, save

ap = argparse.ArgumentParser()
ap.add_argument("csv")
ap.add_argument("out")
ap.add_argument("--tau-star", type=float, default=1.0)
ap.add_argument("--title", default="")
args = ap.parse_args()
c = read_csv(args.csv)
x = [s / args.tau_star for s in c["stress"]]
fig, ax = plt.subplots(figsize=(5.6, 4.2))
ax.semilogx(x, c["f_model"], "k-", lw=2, label="this model, H = (τ/τ*)^{3/2}")
ax.semilogx(x, c["f_wyart_cates"], "b--", label="Wyart–Cates: 1 − exp(−τ/τ*)")
ax.semilogx(x, c["f_singh"], "r-.", label="Singh et al.: exp(−τ*/τ)")
ax.set_xlabel("τ / τ*")
ax.set_ylabel("f")
ax.set_ylim(0, 1.02)
ax.set_title(f"steady structure f(τ) {args.title}", fontsize=9)
ax.legend(fontsize=8)
ax.grid(True, alpha=0.3)
save(fig, args.out)
