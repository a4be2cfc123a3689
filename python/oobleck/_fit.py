"""Least-squares fits of the model to rheometer data: fit, FitResult and its plot."""
from __future__ import annotations

import math
import os

import numpy as np

from . import InputError, _core
from ._args import _frame, _integer, _number, _params
from ._rheology import flow_curve, shear_rate_dst
from ._rheometer import _read_exports


def _read_data(data, name="data"):
    import pandas as pd
    if isinstance(data, (str, os.PathLike)):
        path = os.fspath(data)
        if not os.path.exists(path):
            raise InputError(f"{name} = {path!r}: no such file")
        return pd.read_csv(path, comment="#", skipinitialspace=True, float_precision="round_trip"), path
    if isinstance(data, pd.DataFrame):
        return data, name
    raise InputError(f"{name} = {data!r} ({type(data).__name__}): must be a pandas DataFrame or the path of a CSV file")


def _column(df, col, where):
    if col not in df.columns:
        raise InputError(f"{where}: missing column '{col}' (columns present: {', '.join(map(str, df.columns))})")
    values = []
    for k, v in enumerate(df[col].tolist()):
        try:
            x = float(v)
        except (TypeError, ValueError):
            raise InputError(f"{where}: row {k + 1}: column '{col}' = {v!r}: is not a number") from None
        if not math.isfinite(x):
            raise InputError(f"{where}: row {k + 1}: column '{col}' = {v!r}: must be a finite number")
        values.append(x)
    return values


class FitResult:
    """The result of :func:`fit`.

    Attributes: ``kind``; ``params`` (the complete fitted :class:`Params`: the base set with the
    fitted values replaced); ``values`` and ``stderr`` (dicts name -> value, 1-sigma standard error,
    in the parameters' units; NaN where not identifiable); ``correlation`` (DataFrame, fitted
    parameters x fitted parameters); ``residuals`` (DataFrame: the data, the model's value and the
    log residual ln(model) − ln(data) per point); ``n``, ``p``, ``rms`` (RMS log residual),
    ``cost``, ``iterations``; ``held``: a list of ``(name, reason)`` tuples, the requested
    parameters the data do not determine, held at the base set's values (their values are in
    ``params``; 'curves' only, empty otherwise and with ``strict=True``).
    """

    def __init__(self, kind, raw, data, base):
        import pandas as pd
        self.kind = kind
        self.params = raw["params"]
        self.base = base
        names = [n for n, _, _ in raw["parameters"]]
        self.values = {n: v for n, v, _ in raw["parameters"]}
        self.stderr = {n: s for n, _, s in raw["parameters"]}
        self.n, self.p, self.rms = raw["n"], raw["p"], raw["rms"]
        self.cost, self.iterations = raw["cost"], raw["iterations"]
        self.held = [(name, reason) for name, _, reason in raw.get("held", [])]
        if "correlation" in raw:
            corr = raw["correlation"]
            self.covariance = pd.DataFrame(raw["covariance"], index=names, columns=names)
            self.residual_kind = raw["residual"]
        else:  # the asymptote fits report standard errors only
            corr = np.full((len(names), len(names)), np.nan)
            np.fill_diagonal(corr, 1.0)
            self.covariance = None
            self.residual_kind = "value"
        self.correlation = pd.DataFrame(corr, index=names, columns=names)
        res = data.copy()
        res["model"] = raw["model"]
        res["residual"] = raw["residuals"]
        self.residuals = res

    def __repr__(self):
        lines = [f"FitResult(kind={self.kind!r}, n={self.n}, p={self.p}, rms={self.rms:.4g})"]
        for k, v in self.values.items():
            lines.append(f"  {k:<16} = {v:<14.6g} +- {self.stderr[k]:.3g}")
        for k, reason in self.held:
            lines.append(f"  {k:<16} held at the base value ({reason})")
        return "\n".join(lines)

    def plot(self, ax=None, y: str = "stress", x: str = "rate"):
        """Data and fitted model on a matplotlib Axes (created when None); returns the Axes.

        curves: per phi (one colour, one legend entry each), the data as markers and the fitted flow
        curve as lines, every branch (unstable ones, where the rate falls as the stress rises,
        dotted), log-log: ``y='stress'`` (default) or ``'viscosity'`` (tau/gamma_dot) against
        ``x='rate'`` (default; the DST rate, E14, dashed) or ``'stress'``; the axes span the data
        (``ax.set_xlim``/``set_ylim`` afterwards to change them). low/high: relative viscosity vs
        phi; dst: DST rate vs phi (x and y must keep their defaults there). The same picture as
        ``oobleck rheology flow-curve --params FIT.toml --data DATA --plot P.png [--x] [--y]``."""
        import matplotlib.pyplot as plt
        from matplotlib.lines import Line2D
        if y not in ("stress", "viscosity"):
            raise InputError(f"y = {y!r}: must be 'stress' or 'viscosity'")
        if x not in ("rate", "stress"):
            raise InputError(f"x = {x!r}: must be 'rate' or 'stress'")
        if x == "stress" and y == "stress":
            raise InputError("x = 'stress' with y = 'stress' draws the stress against itself: use y='viscosity'")
        if self.kind != "curves" and (x, y) != ("rate", "stress"):
            raise InputError(f"x, y: only for kind 'curves' (not {self.kind!r})")
        if ax is None:
            _, ax = plt.subplots(figsize=(7.5, 4.8))
        d = self.residuals
        if self.kind == "curves":
            def axes(rate, stress):
                rate, stress = np.asarray(rate, dtype=float), np.asarray(stress, dtype=float)
                return (rate if x == "rate" else stress), (stress if y == "stress" else stress / rate)

            phis = sorted(d["phi"].unique())
            colors = plt.cm.viridis(np.linspace(0, 0.9, len(phis)))
            handles, xs, ys = [], [], []
            for phi, c in zip(phis, colors):
                sel = d[d["phi"] == phi]
                xd, yd = axes(sel["shear_rate"], sel["shear_stress"])
                xs.append(xd)
                ys.append(yd)
                ax.loglog(xd, yd, "o", color=c, ms=5, mec="k", mew=0.5, zorder=3)
                fc = flow_curve(self.params, float(phi), 400, as_frame=False)
                g, t = fc["shear_rate"], fc["shear_stress"]
                xm, ym = axes(g, t)
                rising = np.diff(g) >= 0  # stable where the rate rises with the stress
                start = 0
                for i in range(1, len(rising) + 1):
                    if i == len(rising) or rising[i] != rising[start]:
                        ok = bool(rising[start])
                        ax.loglog(xm[start:i + 1], ym[start:i + 1], color=c, lw=1.8 if ok else 1.0,
                                  ls="-" if ok else ":")
                        start = i
                dst = shear_rate_dst(self.params, float(phi))
                if dst is not None and x == "rate":
                    ax.axvline(dst, color=c, ls="--", lw=0.8)
                handles.append(Line2D([], [], color=c, lw=1.8, marker="o", ms=5, mec="k", mew=0.5,
                                      label=f"φ = {phi:.4g}  ({len(sel)} points)"))
            xs, ys = np.concatenate(xs), np.concatenate(ys)
            ax.set_xlim(xs.min() / 1.6, xs.max() * 1.6)
            ax.set_ylim(ys.min() / 1.6, ys.max() * 1.6)
            ax.set_xlabel("shear rate γ̇ [1/s]" if x == "rate" else "shear stress τ [Pa]")
            ax.set_ylabel("shear stress τ [Pa]" if y == "stress" else "viscosity η = τ/γ̇ [Pa s]")
            notes = "points: data; lines: fit, every branch (dotted: unstable)" + ("; dashed: γ̇_DST" if x == "rate" else "")
            held = f"; held: {', '.join(n for n, _ in self.held)}" if self.held else ""
            ax.set_title(f"oobleck fit (curves): rms log residual {self.rms:.3g}{held}\n{notes}", fontsize=9)
            ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
            ax.grid(True, which="major", alpha=0.3)
            return ax
        col = "shear_rate_dst" if self.kind == "dst" else "value"
        y = d[col] if col in d else d["model"] * np.exp(-d["residual"])
        ax.semilogy(d["phi"], y, "o", label="data")
        phi_m = self.params.phi_c if self.kind == "high" else self.params.phi_j
        lo = self.params.phi_c if self.kind == "dst" else d["phi"].min() - 0.05 * (phi_m - d["phi"].min())
        grid = phi_m - (phi_m - lo) * np.geomspace(1, 1e-3, 300)
        model = [_core.fit_model_value(self.kind, self.params, float(x)) for x in grid]
        ax.semilogy(grid, model, "-", label=f"fit --kind {self.kind}")
        ax.set_xlabel("phi [-]")
        ax.set_ylabel("gamma_dot_DST [1/s]" if self.kind == "dst" else "relative viscosity [-]")
        ax.set_title(f"oobleck fit ({self.kind}): rms log residual {self.rms:.3g}")
        ax.legend(fontsize=7)
        return ax


def fit(kind: str, data, params=None, *, terms=None, parameters=None, residual: str = "rate", bounds=None, phi=None,
        step=None, strict: bool = False):
    """Least-squares fit (Ceres) of the model to rheometer data; returns a :class:`FitResult`.

    kind: 'low' (a_0, phi_j; E12), 'high' (a_inf, phi_c; E13), 'dst' (eta_B terms; E14) exactly as
    ``oobleck rheology fit --kind KIND``, or 'curves': a joint fit to whole flow curves.
    data: a DataFrame or the path of a CSV file with columns
      low/high: phi and viscosity [Pa s] or relative_viscosity [-];
      dst: phi, shear_rate_dst [1/s];
      curves: phi, shear_rate [1/s], shear_stress [Pa] (any number of points per phi).
    params: the base set (Params, preset name or file; default 'hermes2016' as the CLI): every
      value not fitted, and for 'curves' the starting point.
    terms: dst only, the number of eta_B terms.
    parameters: curves only, the fitted subset (default a_0, phi_j, a_inf, phi_c, tau_star and every
      eta_B term's phi_i and alpha; also 'Delta').
    residual: curves only, 'rate' (ln shear rate at the measured stress; default) or 'stress'
      (ln shear stress at the measured rate, nearest branch).
    bounds: curves only, {name: (lower, upper)} in the parameter's unit, on top of the model's rules.
    phi, step: curves only, instrument exports as ``rheology fit --data FILE [--step S] --phi PHI``:
      data is one export's path or a list of them (TRIOS, RheoCompass, rSpace, CSV with units; see
      :func:`read_rheometer`), phi their volume fractions (a number or a list as long), step the
      step of each (a name or 1-based index, one for all or a list; default: the file's one step
      with shear rate and stress).
    strict: curves only. False (default): a parameter the data do not determine (the residuals do
      not change with it, a rank-deficient Jacobian, or a 1-sigma range wider than a factor 1000,
      +-0.1 in phi, +-10 in alpha) is held at the base set's value and the fit redone without it,
      one at a time; ``FitResult.held`` lists them with the reason and a UserWarning names them.
      True: such a parameter raises InputError naming it. Every parameter undetermined is always
      an InputError.
    """
    if not isinstance(kind, str) or kind not in ("low", "high", "dst", "curves"):
        raise InputError(f"kind = {kind!r}: must be one of 'low', 'high', 'dst', 'curves'")
    base = _params("hermes2016" if params is None else params)
    df, where = _fit_data(kind, data, phi, step)
    if kind != "curves":
        for arg, v in (("parameters", parameters), ("bounds", bounds)):
            if v is not None:
                raise InputError(f"{arg}: only for kind 'curves' (not {kind!r})")
        if residual != "rate":
            raise InputError(f"residual: only for kind 'curves' (not {kind!r})")
        if strict is not False:
            raise InputError(f"strict: only for kind 'curves' (not {kind!r})")
        return _fit_asymptote(kind, df, where, base, terms)
    if terms is not None:
        raise InputError(f"terms = {terms!r}: only for kind 'dst' (not 'curves')")
    return _fit_curves(df, where, base, parameters, residual, bounds, strict)


def _fit_data(kind, data, phi, step):
    """fit's data as (DataFrame, where): instrument exports with phi, else a DataFrame or CSV file;
    for 'curves', an instrument export given without phi is an InputError that says what to add."""
    if phi is not None:
        if kind != "curves":
            raise InputError(f"phi: only for kind 'curves' with instrument exports (not {kind!r})")
        return _read_exports(data, phi, step)
    if step is not None:
        raise InputError("step: only with phi (instrument exports, kind 'curves')")
    if kind == "curves" and isinstance(data, (str, os.PathLike)) and os.path.isfile(data):
        try:  # an instrument export is named with what it needs
            found = _core.read_rheometer(os.fspath(data), "auto", "")["attrs"]
        except InputError:
            found = {"format": "csv"}
        if found["format"] != "csv":
            raise InputError(f"{os.fspath(data)}: a {found['format']} export has no phi column: give its volume "
                             f"fraction, fit('curves', {os.fspath(data)!r}, phi=PHI, step=NAME_OR_INDEX)")
    return _read_data(data)


def _fit_asymptote(kind, df, where, base, terms):
    """fit for kind 'low', 'high' or 'dst': the asymptote of the viscosity (E12, E13) or the DST
    rate (E14) against phi, as ``oobleck rheology fit --kind KIND``."""
    if terms is not None and kind != "dst":
        raise InputError(f"terms = {terms!r}: only for kind 'dst' (not {kind!r})")
    n_terms = 0 if terms is None else _integer(terms, "terms")
    if terms is not None and n_terms < 1:
        raise InputError(f"terms = {n_terms}: must be >= 1")
    phi = _column(df, "phi", where)
    if kind == "dst":
        col = "shear_rate_dst"
        values = _column(df, col, where)
    else:
        has_v, has_r = "viscosity" in df.columns, "relative_viscosity" in df.columns
        if has_v == has_r:
            raise InputError(f"{where}: {'both' if has_v else 'neither'} of the columns 'viscosity' [Pa s] and "
                             f"'relative_viscosity' [-]: kind {kind!r} needs phi and exactly one of them")
        col = "viscosity" if has_v else "relative_viscosity"
        values = _column(df, col, where)
    for k, (x, v) in enumerate(zip(phi, values)):
        if not 0.0 < x < 1.0:
            raise InputError(f"{where}: data row {k + 1}: column 'phi' = {x}: must lie in (0, 1)")
        if not v > 0.0:
            raise InputError(f"{where}: data row {k + 1}: column '{col}' = {v}: must be positive")
    scale = 1.0 / base.eta_0 if col == "viscosity" else 1.0
    raw = _core.fit_asymptote(kind, phi, [v * scale for v in values], base, n_terms, where)
    table = _frame({"phi": phi, col: values}, ("phi", col))
    if col != "shear_rate_dst":
        table["value"] = [v * scale for v in values]
    return FitResult(kind, raw, table, base)


def _fit_bounds(bounds) -> list:
    """fit's bounds {name: (lower, upper)} as [(name, lower, upper)], None meaning unbounded."""
    blist = []
    if bounds is not None:
        if not isinstance(bounds, dict):
            raise InputError(f"bounds = {bounds!r}: must be a dict name -> (lower, upper)")
        for name, b in bounds.items():
            try:
                lo, hi = b
            except (TypeError, ValueError):
                raise InputError(f"bounds[{name!r}] = {b!r}: must be a pair (lower, upper)") from None
            lo = -math.inf if lo is None else _number(lo, f"bounds[{name!r}][0]")
            hi = math.inf if hi is None else _number(hi, f"bounds[{name!r}][1]")
            blist.append((str(name), lo, hi))
    return blist


def _fit_curves(df, where, base, parameters, residual, bounds, strict):
    """fit for kind 'curves': a joint fit to whole flow curves (phi, shear_rate, shear_stress); a
    UserWarning names the parameters held at the base set's values, at the caller of fit."""
    phi = _column(df, "phi", where)
    rate = _column(df, "shear_rate", where)
    stress = _column(df, "shear_stress", where)
    if parameters is None:
        names = []
    elif isinstance(parameters, str) or not all(isinstance(n, str) for n in parameters):
        raise InputError(f"parameters = {parameters!r}: must be a list of parameter names (str)")
    else:
        names = list(parameters)
    if not isinstance(residual, str):
        raise InputError(f"residual = {residual!r}: must be 'rate' or 'stress'")
    blist = _fit_bounds(bounds)
    if not isinstance(strict, bool):
        raise InputError(f"strict = {strict!r}: must be True or False")
    raw = _core.fit_curves(phi, rate, stress, base, names, residual, blist, where, strict)
    if raw["held"]:
        import warnings
        held = "; ".join(f"{name} = {value:.6g} ({reason})" for name, value, reason in raw["held"])
        warnings.warn(f"oobleck.fit('curves'): {len(raw['held'])} of {len(raw['held']) + raw['p']} parameters held "
                      f"at the base set's values because the data do not determine them: {held} "
                      f"(strict=True makes this an error)", UserWarning, stacklevel=3)
    table = _frame({"phi": phi, "shear_rate": rate, "shear_stress": stress}, ("phi", "shear_rate", "shear_stress"))
    return FitResult("curves", raw, table, base)
