"""Plot `oobleck point relax` output: tau_bar(t)/tau_bar_0 and f(t) for each (G, K_0) case, with the
SI reduced ODE dashed (the SI figure "stress relaxation after the cessation of flow").

usage: plot_point_relax.py CSV --title TITLE OUT.png
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("png")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    cases = {}
    with open(a.csv) as fh:  # (the '# units: ...' line first)
        for row in csv.DictReader(line for line in fh if not line.startswith("#")):
            cases.setdefault(int(row["case"]), []).append(row)
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    for c, rows in sorted(cases.items()):
        G, K0 = float(rows[0]["G"]), float(rows[0]["K_0"])
        t = [float(r["time"]) for r in rows][1:]
        tau0 = float(rows[0]["granular_shear_stress"])
        f = [float(r["f"]) for r in rows][1:]
        tau = [float(r["granular_shear_stress"]) / tau0 for r in rows][1:]
        otau = [float(r["ode_granular_shear_stress"]) / tau0 for r in rows][1:]
        of = [float(r["ode_f"]) for r in rows][1:]
        lab = f"G = {G:g} Pa, K0 = {K0:g}"
        (ln,) = ax[0].semilogx(t, tau, label=lab)
        ax[0].semilogx(t, otau, "--", color=ln.get_color(), lw=1)
        ax[1].semilogx(t, f, color=ln.get_color(), label=lab)
        ax[1].semilogx(t, of, "--", color=ln.get_color(), lw=1)
    ax[0].set_xlabel("time after cessation [s]")
    ax[0].set_ylabel(r"$\bar\tau(t)/\bar\tau_0$")
    ax[0].set_title("return map (solid), reduced ODE (dashed)", fontsize=9)
    ax[0].legend(fontsize=8)
    ax[1].set_xlabel("time after cessation [s]")
    ax[1].set_ylabel("structure f")
    ax[1].legend(fontsize=8)
    fig.suptitle(a.title)
    fig.tight_layout()
    fig.savefig(a.png, dpi=110)


if __name__ == "__main__":
    main()
