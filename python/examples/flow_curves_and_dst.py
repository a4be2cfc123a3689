# %% Flow curves and DST of a preset (hermes2016, cornstarch): CST below phi_c, DST above.
import sys
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

import oobleck

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_examples")
out.mkdir(parents=True, exist_ok=True)
p = oobleck.load_params("hermes2016")
phis = [0.40, 0.44, 0.47, 0.50]
fc = oobleck.flow_curve(p, phis, points=200)

# %% plot stress vs rate per phi, and print the DST rates (E14)
fig, ax = plt.subplots()
for phi, curve in fc.groupby("phi"):
    ax.loglog(curve["shear_rate"], curve["shear_stress"], label=f"phi = {phi}")
    print(f"phi = {phi}: gamma_dot_DST = {oobleck.shear_rate_dst(p, phi)}")
ax.set_xlabel("shear rate [1/s]"), ax.set_ylabel("shear stress [Pa]"), ax.legend()
fig.savefig(out / "flow_curves.png", dpi=120)
print("wrote", out / "flow_curves.png")
