"""Material point experiments with the granular law: homogeneous simple shear and stress
relaxation, as ``oobleck point shear`` and ``oobleck point relax``."""
from __future__ import annotations

from . import InputError, Params, _core
from ._args import _frame, _integer, _number, _numbers, _opt_number, _params
from ._parameters import _GRANULAR_FIELDS, _PARAM_FIELDS


def _with_overrides(params, overrides):
    p = _params(params)
    if not overrides:
        return p
    q = Params(p)
    for k, v in overrides.items():
        if not hasattr(q, k) or k in ("name", "source", "units", "file"):
            raise InputError(f"{k}: not a parameter of Params (use one of {', '.join(_PARAM_FIELDS + _GRANULAR_FIELDS)})")
        setattr(q, k, _number(v, k))
    return q


SHEAR_COLUMNS = ("time", "strain", "shear_rate", "shear_stress", "granular_shear_stress", "granular_pressure",
                 "sigma_xy", "f", "phi", "regime", "gamma_dot_p", "I_v", "I_m", "beta", "mu_p", "phi_eq", "iterations")


def point_shear(params, phi, *, shear_rate=None, shear_stress=None, duration, dt=None, f0=0.0, samples=1000,
                **overrides):
    """Homogeneous simple shear at fixed volume with the granular law (E16–E24), rate- or
    stress-controlled, as ``oobleck point shear``.

    phi [-]; shear_rate [1/s] or shear_stress (mixture tau) [Pa]; duration [s]; dt [s] (default as the
    CLI: resolves eta/G of the low-viscosity branch and 1e-3 strain); f0 initial structure [-];
    samples (rows, evenly spaced in time). Keyword overrides set Params attributes (G [Pa], K_0,
    eta_0 [Pa s], …) on a copy. Returns a DataFrame with the CLI's columns (SHEAR_COLUMNS); its
    ``attrs`` hold dt [s] and steps.
    """
    p = _with_overrides(params, overrides)
    raw = _core.point_shear(p, _number(phi, "phi"), _opt_number(shear_rate, "shear_rate"),
                            _opt_number(shear_stress, "shear_stress"), _number(duration, "duration"),
                            _opt_number(dt, "dt"), _number(f0, "f0"), _integer(samples, "samples"))
    df = _frame(raw, SHEAR_COLUMNS)
    df["iterations"] = df["iterations"].astype(int)
    df.attrs.update(dt=raw["dt"], steps=raw["steps"])
    return df


RELAX_COLUMNS = _core.RELAX_COLUMNS  # (material::relax_columns)


def point_relax(params, phi, *, shear_rate=None, shear_stress=None, duration, dt=None, samples=200, G=None, K0=None,
                **overrides):
    """Stress relaxation after cessation of steady shear beside the SI's reduced ODE, as
    ``oobleck point relax``: pre-shear at shear_rate [1/s] or shear_stress [Pa] to steady state, then
    relax for duration [s]; dt the first step [s]; samples rows per case (log-spaced); G [Pa] and K0
    [-] a number or a list (one case per combination; default the set's). Returns a DataFrame with
    the CLI's columns (RELAX_COLUMNS)."""
    p = _with_overrides(params, overrides)
    Gs = [] if G is None else _numbers(G, "G")
    K0s = [] if K0 is None else _numbers(K0, "K0")
    raw = _core.point_relax(p, _number(phi, "phi"), _opt_number(shear_rate, "shear_rate"),
                            _opt_number(shear_stress, "shear_stress"), _number(duration, "duration"),
                            _opt_number(dt, "dt"), _integer(samples, "samples"), Gs, K0s)
    df = _frame(raw, RELAX_COLUMNS)
    df["case"] = df["case"].astype(int)
    return df
