"""Steady rheology: flow curves (E11), the DST shear rate (E14), the steady structure (E7/E10),
the volume fraction of swelling starch (E15) and the steady states at a rate or a stress."""
from __future__ import annotations

import numpy as np

from . import InputError, Params, _core
from ._args import _frame, _integer, _number, _numbers, _pandas, _params


FLOW_CURVE_COLUMNS = _core.FLOW_CURVE_COLUMNS  # (rheology::kFlowCurveColumns)
_flow_curve_index = None  # pandas.Index of FLOW_CURVE_COLUMNS, built on first use


def flow_curve(params, phi, points: int = 200, *, as_frame: bool = True):
    """Steady flow curves with every branch (E11), swept in the structure f as
    ``oobleck rheology flow-curve``: ``points`` rows per phi, f from 1e-10 f_u to f_u (1 − 1e-10).

    params: Params, preset name or file (a Params is fastest: a name or file is read every call);
    phi: volume fraction(s) in (0, phi_j) [-].
    Returns a DataFrame with the CLI's columns: phi [-], f [-], shear_rate [1/s], shear_stress [Pa],
    granular_pressure [Pa], granular_shear_stress [Pa], viscosity [Pa s], eta_r [-],
    shear_rate_dst [1/s] (E14 at that phi, NaN where DST does not apply).
    as_frame=False returns the same columns as a dict {column: 1-D numpy array} (the same numbers,
    without pandas: about 1.5x faster for one 200-point curve, see docs/python.md).
    """
    global _flow_curve_index
    p = params if type(params) is Params else _params(params)
    if type(phi) is not float:
        phi = _numbers(phi, "phi")
    if type(points) is not int:
        points = _integer(points, "points")
    block = _core.flow_curve(p, phi, points)  # (9, rows): row k = column k
    if as_frame is False:
        return dict(zip(FLOW_CURVE_COLUMNS, block))
    if as_frame is not True:
        raise InputError(f"as_frame = {as_frame!r} ({type(as_frame).__name__}): must be True or False")
    pd = _pandas()
    if _flow_curve_index is None:
        _flow_curve_index = pd.Index(FLOW_CURVE_COLUMNS)
    # One float64 block, wrapped without a copy; the columns a view of a prebuilt Index (its own
    # .name, as pandas' DataFrame.copy does): pandas' dict-of-arrays and list-of-names paths cost
    # 5-10x more.
    return pd.DataFrame(block.T, columns=_flow_curve_index.view(), copy=False)


def shear_rate_dst(params, phi):
    """The DST shear rate gamma_dot_DST [1/s] (E14) at phi [-]; None where DST does not apply
    (phi < phi_c: CST; phi > phi*: shear jamming; no eta_B terms). A list for a list of phi."""
    p = _params(params)
    values = [_core.shear_rate_dst(p, v) for v in _numbers(phi, "phi")]
    return values[0] if np.ndim(phi) == 0 else values


def structure(params, points: int = 200):
    """Steady f(tau) of this model (eta_B -> infinity, E7/E10) beside Wyart–Cates and Singh et al., as
    ``oobleck rheology structure``: columns stress [Pa] (log-spaced over 1e-3..1e3 tau*),
    f_model, f_wyart_cates, f_singh [-]."""
    p = _params(params)
    return _frame(_core.structure(p, _integer(points, "points")), ("stress", "f_model", "f_wyart_cates", "f_singh"))


def volume_fraction(mass_fraction, rho_cs, rho_liquid, rho_water, lambda_=0.3, beta=0.1) -> float:
    """Volume fraction phi [-] of swelling starch from its mass fraction (E15), as
    ``oobleck rheology volume-fraction``: mass_fraction = m_cs/(m_cs + m_l) [-]; densities of the
    cornstarch, the suspending liquid and water [kg/m^3]; lambda_ (pore-space) and beta (swelling)
    corrections [-]."""
    return _core.volume_fraction(_number(mass_fraction, "mass_fraction"), _number(rho_cs, "rho_cs"),
                                 _number(rho_liquid, "rho_liquid"), _number(rho_water, "rho_water"),
                                 _number(lambda_, "lambda_"), _number(beta, "beta"))


def viscosity_at(params, phi, shear_rate=None, shear_stress=None, full: bool = False):
    """Every steady branch's viscosity [Pa s] at a shear rate [1/s] or a mixture shear stress [Pa].

    Give exactly one of ``shear_rate`` and ``shear_stress`` (a number or an array). An S-shaped
    curve has up to three states at one rate; a DST curve none above gamma_dot_DST; at a given
    stress there is one. Returns, for a number, a 1-D array of the branches' viscosities ordered by
    increasing structure f (the first is the low-viscosity branch); for an array of N values an
    (N, B) array, B the largest number of branches, NaN-padded. With ``full=True`` a dict of such
    arrays: viscosity [Pa s], f [-], shear_rate [1/s], shear_stress [Pa].
    """
    p = _params(params)
    phi_v = _number(phi, "phi")
    if (shear_rate is None) == (shear_stress is None):
        raise InputError("viscosity_at: give exactly one of shear_rate [1/s] or shear_stress [Pa]")
    by_rate = shear_rate is not None
    raw = shear_rate if by_rate else shear_stress
    values = _numbers(raw, "shear_rate" if by_rate else "shear_stress")
    out = _core.states_at(p, phi_v, values, by_rate)
    if np.ndim(raw) == 0:
        out = {k: v[0][~np.isnan(v[0])] for k, v in out.items()}
    return out if full else out["viscosity"]
