#!/usr/bin/python3
"""Writes docs/fitting/rate_curves.csv, the rate-controlled flow curves of docs/fitting.md's first
curves fit: hermes2016 at five phi from 0.40 to 0.49, 12 shear rates per curve log-spaced from
1e-3 1/s to 0.8 gamma_dot_DST (10 1/s where there is no DST), the stress of the low-viscosity
branch times exp(N(0, 0.02)) (numpy seed 1; python/tests/test_fit_curves.py uses the same
curves). Run from the repository root: /usr/bin/python3 docs/fitting/make_rate_curves.py
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
import oobleck  # noqa: E402

p = oobleck.load_params("hermes2016")
rng = np.random.default_rng(1)
lines = ["# synthetic example: hermes2016 rate-controlled below 0.8 gamma_dot_DST, 2 % log-normal scatter on the "
         "stress; docs/fitting/make_rate_curves.py", "# units: phi=1, shear_rate=1/s, shear_stress=Pa",
         "phi,shear_rate,shear_stress"]
for phi in np.linspace(0.40, 0.49, 5):
    dst = oobleck.shear_rate_dst(p, phi)
    rates = np.geomspace(1e-3, 0.8 * dst if dst else 10.0, 12)
    tau = rates * oobleck.viscosity_at(p, phi, shear_rate=rates)[:, 0]
    lines += [f"{phi:.4f},{g:.6g},{t * np.exp(rng.normal(0.0, 0.02)):.6g}" for g, t in zip(rates, tau)]
(ROOT / "docs" / "fitting" / "rate_curves.csv").write_text("\n".join(lines) + "\n")
