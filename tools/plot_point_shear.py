"""Plot `oobleck point shear` output: stresses and structure against strain.

usage: plot_point_shear.py CSV --title TITLE OUT.png
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
    cols = {}
    with open(a.csv) as fh:  # (the '# units: ...' line first)
        for row in csv.DictReader(line for line in fh if not line.startswith("#")):
            for k, v in row.items():
                cols.setdefault(k, []).append(v)
    num = lambda k: [float(x) for x in cols[k]]  # noqa: E731
    t, gam = num("time"), num("strain")
    x, xl = (gam, "shear strain") if gam[-1] > 0 else (t, "time [s]")
    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    ax[0].plot(x, num("shear_stress"), label=r"mixture $\tau$")
    ax[0].plot(x, num("granular_shear_stress"), "--", label=r"granular $\bar\tau$")
    ax[0].plot(x, num("granular_pressure"), ":", label=r"granular $\tilde p$")
    ax[0].set_xlabel(xl)
    ax[0].set_ylabel("stress [Pa]")
    ax[0].legend()
    ax[1].plot(x, num("f"))
    ax[1].set_xlabel(xl)
    ax[1].set_ylabel("structure f")
    ax[2].plot(t, num("shear_rate"), label="applied")
    ax[2].plot(t, num("gamma_dot_p"), "--", label="plastic")
    ax[2].set_xlabel("time [s]")
    ax[2].set_ylabel("shear rate [1/s]")
    ax[2].legend()
    fig.suptitle(a.title)
    fig.tight_layout()
    fig.savefig(a.png, dpi=110)


if __name__ == "__main__":
    main()
