#!/usr/bin/python3
"""Plot a fit of `oobleck rheology fit`: measured points and the fitted asymptote.

Usage: plot_fit.py DATA.csv CURVE.csv --kind low|high|dst --phi-m PHI_M [--title T] OUT.png
       plot_fit.py DATA.csv CURVE.csv --kind curves --residual rate|stress [--title T] OUT.png
  low/high/dst:
  DATA.csv : phi,data,model   (measured values and the fitted model at the same phi)
  CURVE.csv: phi,model        (the fitted model on a fine grid up to the asymptote phi_m)
  curves:
  DATA.csv : phi,shear_rate,shear_stress,model,residual (the model's rate or stress at each point
             and the log residual, as FitResult.residuals in Python)
  CURVE.csv: phi,shear_rate,shear_stress (the fitted flow curves, every branch, per data phi)
low/high: relative viscosity eta_r vs phi (E12/E13), asymptote at phi_j/phi_c (dashed);
dst: DST shear rate vs phi_j - phi on log-log axes (E14);
curves: shear stress vs shear rate per phi (log-log), data as points, fitted curves as lines.
Written by the oobleck CLI; run with /usr/bin/python3 (matplotlib).
"""
import argparse
import csv
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    return {k: [float(r[k]) for r in rows] for k in (rows[0].keys() if rows else [])}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("data")
    ap.add_argument("curve")
    ap.add_argument("out")
    ap.add_argument("--kind", choices=["low", "high", "dst", "curves"], required=True)
    ap.add_argument("--phi-m", type=float, help="asymptote phi_j (low, dst) or phi_c (high)")
    ap.add_argument("--residual", choices=["rate", "stress"], default="rate", help="curves: the residual's quantity")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    d, c = read(a.data), read(a.curve)
    if a.kind == "curves":
        plot_curves(a, d, c)
        return
    if a.phi_m is None:
        ap.error(f"--phi-m is required for --kind {a.kind}")

    fig, (ax, axr) = plt.subplots(2, 1, figsize=(6.4, 6.4), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1]})
    label_m = {"low": r"$\phi_j$", "high": r"$\phi_c$", "dst": r"$\phi_j$"}[a.kind]
    if a.kind == "dst":
        x_d = [a.phi_m - p for p in d["phi"]]
        x_c = [a.phi_m - p for p in c["phi"]]
        ax.set_xscale("log")
        axr.set_xlabel(r"$\phi_j - \phi$  ($\phi_j$ = %.4g)" % a.phi_m)
        ax.set_ylabel(r"$\dot\gamma_{\mathrm{DST}}$ [1/s]")
        model_label = "fit: E14 with fitted $\\eta_B$ (E8)"
    else:
        x_d, x_c = d["phi"], c["phi"]
        ax.axvline(a.phi_m, color="k", ls="--", lw=1, label="%s = %.4g" % (label_m, a.phi_m))
        axr.set_xlabel(r"$\phi$")
        ax.set_ylabel(r"$\eta_r = \eta/\eta_0$")
        model_label = "fit: E12 (low branch)" if a.kind == "low" else "fit: E13 (high branch)"
    ax.set_yscale("log")
    ax.plot(x_c, c["model"], "r-", lw=1.5, label=model_label)
    ax.plot(x_d, d["data"], "o", mfc="none", color="tab:blue", label="data")
    if a.kind != "dst":
        lo, hi = min(d["data"]), max(d["data"])
        ax.set_ylim(lo / 1.5, hi * 5)
    ax.legend(loc="best", fontsize=9)
    ax.set_title(a.title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)

    res = [math.log(m / v) for m, v in zip(d["model"], d["data"])]
    axr.axhline(0.0, color="k", lw=0.8)
    axr.plot(x_d, res, "o", mfc="none", color="tab:blue")
    axr.set_ylabel("ln(model/data)")
    axr.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110, format="png")


def plot_curves(a, d, c):
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(6.4, 7.0), gridspec_kw={"height_ratios": [3, 1]})
    phis = sorted(set(d["phi"]))
    cmap = plt.get_cmap("viridis")
    for k, phi in enumerate(phis):
        color = cmap(0.9 * k / max(len(phis) - 1, 1))
        i = [j for j, p in enumerate(d["phi"]) if p == phi]
        ic = [j for j, p in enumerate(c.get("phi", [])) if p == phi]
        ax.loglog([c["shear_rate"][j] for j in ic], [c["shear_stress"][j] for j in ic], "-", color=color, lw=1.3)
        ax.loglog([d["shear_rate"][j] for j in i], [d["shear_stress"][j] for j in i], "o", mfc="none", ms=4,
                  color=color, label=r"$\phi$ = %.4g" % phi)
        x = d["shear_stress"] if a.residual == "rate" else d["shear_rate"]
        axr.semilogx([x[j] for j in i], [d["residual"][j] for j in i], "o", mfc="none", ms=4, color=color)
    ax.set_xlabel(r"shear rate $\dot\gamma$ [1/s]")
    ax.set_ylabel(r"shear stress $\tau$ [Pa]")
    ax.legend(loc="best", fontsize=8, title="points: data; lines: fit (every branch)", title_fontsize=8)
    ax.set_title(a.title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    axr.axhline(0.0, color="k", lw=0.8)
    if a.residual == "rate":
        axr.set_xlabel(r"measured shear stress $\tau$ [Pa]")
        axr.set_ylabel(r"ln($\dot\gamma$ model/data)")
    else:
        axr.set_xlabel(r"measured shear rate $\dot\gamma$ [1/s]")
        axr.set_ylabel(r"ln($\tau$ model/data)")
    axr.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110, format="png")


if __name__ == "__main__":
    main()
