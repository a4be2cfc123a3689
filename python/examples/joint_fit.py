# %% A joint fit of synthetic noisy flow curves (singh2018b, 3 % log-normal noise at 5 phi), then
# the paper's asymptote fit of docs/fitting/ data.
import sys
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import numpy as np
import pandas as pd

import oobleck

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_examples")
out.mkdir(parents=True, exist_ok=True)
truth = oobleck.load_params("singh2018b")
rng = np.random.default_rng(0)
rows = []
for phi in (0.50, 0.54, 0.56, 0.58, 0.60):
    tau = truth.tau_star * np.geomspace(0.01, 1000, 15)
    rate = tau / oobleck.viscosity_at(truth, phi, shear_stress=tau)[:, 0]
    rows += [(phi, r * np.exp(rng.normal(0, 0.03)), t) for r, t in zip(rate, tau)]
data = pd.DataFrame(rows, columns=["phi", "shear_rate", "shear_stress"])

# %% fit from a start 10 % off; print values +- standard errors against the truth
start = truth.copy()
start.a_0, start.a_inf, start.tau_star = 0.5, 0.8, 1.6
r = oobleck.fit("curves", data, start)
print(r)
print(r.correlation.round(2))
r.plot().figure.savefig(out / "joint_fit.png", dpi=120)
r.params.to_toml(out / "joint_fit.toml")

# %% the low-viscosity asymptote (E12) of docs/fitting/min_viscosity.csv, as the CLI
root = Path(__file__).resolve().parents[2]
low = oobleck.fit("low", root / "docs" / "fitting" / "min_viscosity.csv", "dhaene1993")
print(low)
low.plot().figure.savefig(out / "low_fit.png", dpi=120)
print("wrote", out / "joint_fit.png", out / "joint_fit.toml", out / "low_fit.png")
