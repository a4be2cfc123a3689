"""oobleck in Python: the Baumgarten–Kamrin (PNAS 2019) model of dense suspensions.

Every number comes from the same C++ library as the ``oobleck`` command line (liboobleck, through
the compiled module ``oobleck._oobleck``); this package converts arguments and builds pandas
DataFrames whose columns are exactly those of the CLI's CSV files. Units are SI (normalized
units for the Singh presets: stresses in eta_0 gamma_dot_0). Equations E1–E29 are those of
docs/equations.md. Bad input raises :class:`InputError` (a ``ValueError``) naming the argument and
the rule; a numerical failure (non-convergence) raises :class:`NumericalError`.
"""
from __future__ import annotations

import json
import math
import numbers
import os
import sys
import time as _time
from pathlib import Path

import numpy as np

_here = Path(__file__).resolve().parent


def _find_core():
    try:
        from . import _oobleck  # installed package: the module lies beside this file
        return _oobleck
    except ImportError:
        pass
    # A development tree: the module CMake built in <build>/python/oobleck (OOBLECK_BUILD_DIR, else
    # the release preset's build/release of this checkout).
    root = _here.parent.parent
    for build in (os.environ.get("OOBLECK_BUILD_DIR"), root / "build" / "release"):
        if build and (Path(build) / "python" / "oobleck").is_dir():
            __path__.append(str(Path(build) / "python" / "oobleck"))
            from . import _oobleck
            return _oobleck
    raise ImportError(
        "oobleck: the compiled module _oobleck was not found: install with "
        "`pip install --no-build-isolation ./python`, or build it with `cmake --preset release && "
        "cmake --build --preset release` (or set OOBLECK_BUILD_DIR to the build folder)")


# Presets shipped inside an installed package (python/setup.py copies presets/ there).
if (_here / "presets").is_dir() and not os.environ.get("OOBLECK_PRESETS"):
    os.environ["OOBLECK_PRESETS"] = str(_here / "presets")

_core = _find_core()

InputError = _core.InputError
InputError.__doc__ = "Bad input: the message names the argument (or file, key) and the rule. A ValueError."
NumericalError = _core.NumericalError
NumericalError.__doc__ = "A numerical failure (non-convergence, NaN) inside a law, solver or fit. A RuntimeError."
Params = _core.Params

__version__ = "0.1.0"
__all__ = [
    "InputError", "NumericalError", "Params", "FitResult", "Run", "presets", "load_params", "flow_curve",
    "shear_rate_dst", "structure", "volume_fraction", "viscosity_at", "fit", "point_shear", "point_relax",
    "run", "open_run", "version", "read_rheometer",
]


def version() -> str:
    """oobleck's version and build, as ``oobleck --version``."""
    return _core.version()


# ---------------------------------------------------------------------------------------------
# argument checking


def _number(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise InputError(f"{name} = {value!r} ({type(value).__name__}): must be a number")
    v = float(value)
    if math.isnan(v):
        raise InputError(f"{name} = nan: must be a finite number")
    return v


def _opt_number(value, name: str):
    return None if value is None else _number(value, name)


def _integer(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)):
        raise InputError(f"{name} = {value!r} ({type(value).__name__}): must be an integer")
    return int(value)


def _numbers(value, name: str) -> list:
    """A number or a sequence of numbers -> list of floats."""
    if isinstance(value, (str, bytes)):
        raise InputError(f"{name} = {value!r} (str): must be a number or a list of numbers")
    if np.ndim(value) == 0:
        return [_number(value, name)]
    try:
        items = list(np.asarray(value).ravel()) if isinstance(value, np.ndarray) else list(value)
    except TypeError:
        raise InputError(f"{name} = {value!r} ({type(value).__name__}): must be a number or a list of numbers") from None
    return [_number(v, f"{name}[{k}]") for k, v in enumerate(items)]


def _params(value, name: str = "params") -> Params:
    if isinstance(value, Params):
        return value
    if isinstance(value, (str, os.PathLike)):
        return load_params(value)
    raise InputError(f"{name} = {value!r} ({type(value).__name__}): must be a Params, a preset name "
                     f"(oobleck.presets()) or the path of a parameter file (.toml)")


# ---------------------------------------------------------------------------------------------
# parameters


def presets() -> list:
    """Names of the shipped parameter sets (presets/*.toml, the paper's Tables 1–3)."""
    return list(_core.preset_names())


def load_params(name_or_path) -> Params:
    """A parameter set: a preset name (``presets()``) or the path of a TOML file in the same format.

    Returns a :class:`Params` with attribute access (``p.phi_c``, ``p.eta_B`` …, each in its unit);
    every assignment is validated (``p.phi_c = 0.7`` with ``phi_j = 0.535`` raises InputError).
    """
    if isinstance(name_or_path, os.PathLike):
        return _core.load_params_file(os.fspath(name_or_path))
    if not isinstance(name_or_path, str):
        raise InputError(f"name_or_path = {name_or_path!r} ({type(name_or_path).__name__}): must be a preset name "
                         "or the path of a parameter file")
    s = name_or_path
    if s.endswith(".toml") or os.sep in s or os.path.exists(s):
        if not os.path.exists(s):
            raise InputError(f"name_or_path = {s!r}: no such parameter file")
        return _core.load_params_file(s)
    return _core.load_preset(s)


_PARAM_FIELDS = ("phi_c", "phi_j", "a_0", "a_inf", "tau_star", "eta_0", "mu_c", "Delta", "xi_dot_eps")
_GRANULAR_FIELDS = ("d", "rho_s", "mu_2", "b", "K_3", "K_4", "G", "K", "K_0")


def _to_dict(self) -> dict:
    """All values as a plain dict: name, source, units, file, the steady parameters, ``eta_B`` as a
    list of ``{"phi_i", "alpha"}`` and the granular parameters (units as the attributes)."""
    d = {"name": self.name, "source": self.source, "units": self.units, "file": self.file}
    for k in _PARAM_FIELDS:
        d[k] = getattr(self, k)
    d["eta_B"] = [{"phi_i": a, "alpha": b} for a, b in self.eta_B]
    for k in _GRANULAR_FIELDS:
        d[k] = getattr(self, k)
    return d


def _to_toml(self, path=None) -> str:
    """The parameter file's text (loads back with load_params to the same values, bit for bit);
    written to ``path`` as well when given (atomically: a temporary file, then renamed)."""
    text = self.toml()
    if path is not None:
        path = os.fspath(path)
        tmp = f"{path}.tmp-{os.getpid()}"
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    return text


def _copy(self) -> Params:
    """An independent copy."""
    return Params(self)


def _repr(self) -> str:
    vals = ", ".join(f"{k}={getattr(self, k)!r}" for k in _PARAM_FIELDS)
    return f"Params(name={self.name!r}, units={self.units!r}, {vals}, eta_B={self.eta_B!r})"


def _eq(self, other) -> bool:
    return isinstance(other, Params) and _to_dict(self) == _to_dict(other)


Params.to_dict = _to_dict
Params.to_toml = _to_toml
Params.copy = _copy
Params.__repr__ = _repr
Params.__eq__ = _eq
Params.__hash__ = None


# ---------------------------------------------------------------------------------------------
# steady rheology


_pd = None


def _pandas():
    global _pd
    if _pd is None:
        import pandas
        _pd = pandas
    return _pd


def _frame(columns: dict, order):
    return _pandas().DataFrame({k: columns[k] for k in order})


FLOW_CURVE_COLUMNS = ("phi", "f", "shear_rate", "shear_stress", "granular_pressure", "granular_shear_stress",
                      "viscosity", "eta_r", "shear_rate_dst")
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


# ---------------------------------------------------------------------------------------------
# fits


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


def _read_exports(data, phi, step):
    """The (phi, shear_rate, shear_stress) table of instrument exports, one per phi, as the CLI's
    --data FILE [--step S] --phi PHI."""
    files = [data] if isinstance(data, (str, os.PathLike)) else data
    if not isinstance(files, (list, tuple)) or not all(isinstance(f, (str, os.PathLike)) for f in files):
        raise InputError(f"data = {data!r}: with phi, the path of an instrument export or a list of them")
    files = [os.fspath(f) for f in files]
    phis = _numbers(phi, "phi")
    steps = list(step) if isinstance(step, (list, tuple)) else [step] * len(files)
    if len(phis) != len(files) or len(steps) != len(files):
        raise InputError(f"data: {len(files)} export(s), phi: {len(phis)} value(s)"
                         + (f", step: {len(steps)}" if isinstance(step, (list, tuple)) else "")
                         + ": give one volume fraction (and step) per export")
    pd = _pandas()
    parts = []
    for f, x, s in zip(files, phis, steps):
        if not os.path.exists(f):
            raise InputError(f"data = {f!r}: no such file")
        rate, stress, _, _ = _core.rheometer_flow_curve(f, "" if s is None else str(s))
        parts.append(pd.DataFrame({"phi": x, "shear_rate": rate, "shear_stress": stress}))
    return pd.concat(parts, ignore_index=True), ", ".join(files)


RHEOMETER_COLUMNS = ("step", "step_name", "time", "shear_rate", "shear_stress", "viscosity")


def read_rheometer(path, format: str = "auto", *, step=None):
    """A rheometer's export file as a DataFrame in SI, as ``oobleck rheology import``.

    Formats (``format='auto'`` detects them from the content): 'trios' (TA TRIOS "Export to LIMS"
    .txt), 'rheocompass' (Anton Paar RheoCompass CSV/TXT, also UTF-16 and decimal comma), 'rspace'
    (Malvern rSpace CSV) and 'csv' (a header row of names with optional units in brackets or
    parentheses; separator and decimal mark detected). Columns: RHEOMETER_COLUMNS (step: 1-based
    index; step_name on every row; time [s], shear_rate [1/s], shear_stress [Pa], viscosity [Pa s],
    NaN where the file has none), then the file's other columns under normalized names (step_time
    [s], strain [-], torque [N m], temperature as read, ...). Every step, or only ``step`` (a name,
    case-insensitive, TRIOS's ' - N' suffix optional, or an index). ``df.attrs``: file, format,
    encoding, separator, decimal, sample, geometry (and instrument, operator, date, procedure,
    project, test where the file names them), steps, units (the file's spellings per column),
    si_units and metadata (every key/value line). Errors name the file, the line and what was
    expected (InputError).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"path = {path!r} ({type(path).__name__}): must be the path of an export file")
    p = os.fspath(path)
    if not os.path.exists(p):
        raise InputError(f"path = {p!r}: no such file")
    if not isinstance(format, str):
        raise InputError(f"format = {format!r}: must be one of 'auto', 'trios', 'rheocompass', 'rspace', 'csv'")
    raw = _core.read_rheometer(p, format, "" if step is None else str(step))
    pd = _pandas()
    df = pd.DataFrame(dict(zip(raw["names"], raw["columns"])))
    df["step"] = df["step"].astype(int)
    df.attrs.update(raw["attrs"])
    return df


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
    if phi is not None:
        if kind != "curves":
            raise InputError(f"phi: only for kind 'curves' with instrument exports (not {kind!r})")
        df, where = _read_exports(data, phi, step)
    elif step is not None:
        raise InputError("step: only with phi (instrument exports, kind 'curves')")
    else:
        if kind == "curves" and isinstance(data, (str, os.PathLike)) and os.path.isfile(data):
            try:  # an instrument export is named with what it needs
                found = _core.read_rheometer(os.fspath(data), "auto", "")["attrs"]
            except InputError:
                found = {"format": "csv"}
            if found["format"] != "csv":
                raise InputError(f"{os.fspath(data)}: a {found['format']} export has no phi column: give its volume "
                                 f"fraction, fit('curves', {os.fspath(data)!r}, phi=PHI, step=NAME_OR_INDEX)")
        df, where = _read_data(data)
    if kind != "curves":
        for arg, v in (("parameters", parameters), ("bounds", bounds)):
            if v is not None:
                raise InputError(f"{arg}: only for kind 'curves' (not {kind!r})")
        if residual != "rate":
            raise InputError(f"residual: only for kind 'curves' (not {kind!r})")
        if strict is not False:
            raise InputError(f"strict: only for kind 'curves' (not {kind!r})")
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

    if terms is not None:
        raise InputError(f"terms = {terms!r}: only for kind 'dst' (not 'curves')")
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
    if not isinstance(strict, bool):
        raise InputError(f"strict = {strict!r}: must be True or False")
    raw = _core.fit_curves(phi, rate, stress, base, names, residual, blist, where, strict)
    if raw["held"]:
        import warnings
        held = "; ".join(f"{name} = {value:.6g} ({reason})" for name, value, reason in raw["held"])
        warnings.warn(f"oobleck.fit('curves'): {len(raw['held'])} of {len(raw['held']) + raw['p']} parameters held "
                      f"at the base set's values because the data do not determine them: {held} "
                      f"(strict=True makes this an error)", UserWarning, stacklevel=2)
    table = _frame({"phi": phi, "shear_rate": rate, "shear_stress": stress}, ("phi", "shear_rate", "shear_stress"))
    return FitResult("curves", raw, table, base)


# ---------------------------------------------------------------------------------------------
# material point experiments


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


RELAX_COLUMNS = ("case", "G", "K_0", "time", "granular_shear_stress", "granular_pressure", "f", "gamma_dot_p",
                 "regime", "ode_granular_shear_stress", "ode_f")


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


# ---------------------------------------------------------------------------------------------
# runs


class _TextProgress:
    def __init__(self, label):
        self.label, self.last, self.t0 = label, 0.0, _time.monotonic()

    def __call__(self, done, total, sim_time):
        now = _time.monotonic()
        if now - self.last < 1.0 and done < total:
            return
        self.last = now
        print(f"{self.label}: {100.0 * done / total:5.1f}% ({done}/{total} steps, t = {sim_time:.4g} s, "
              f"{now - self.t0:.1f} s)", file=sys.stderr, flush=True)

    def close(self):
        pass


class _TqdmProgress:
    def __init__(self, label, tqdm):
        self.bar, self.n = tqdm(desc=label, unit="step"), 0

    def __call__(self, done, total, sim_time):
        if self.bar.total != total:
            self.bar.total = total
        self.bar.update(done - self.n)
        self.n = done
        self.bar.set_postfix(t=f"{sim_time:.4g} s", refresh=False)

    def close(self):
        self.bar.close()


def _set_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (numbers.Real, np.floating, np.integer)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    return str(v)


def run(scene=None, out=None, threads=None, set=None, progress=True, *, checkpoint_every=None, stop_after=None,
        restart=False) -> dict:
    """Run a scene file (two-phase MPM), as ``oobleck run SCENE --out OUT``; returns the summary
    (summary.json) as a dict.

    scene: the scene file (TOML); out: the run folder (default out/<scene name>); threads: OpenMP
    threads (default all cores); set: {key: value} overrides (``key.path`` or an [aliases] name, as
    --set); progress: a tqdm bar when tqdm is installed, else a text line on stderr every second
    (False: none); checkpoint_every: steps between checkpoints; stop_after: stop (with a
    checkpoint) after this many steps in total; restart=True continues the run in ``out`` from its
    checkpoint (``set`` may then hold [time] keys only, e.g. {"time.cfl": 0.2} after a numerical
    failure). Ctrl-C (SIGINT) stops after the current step, writes a checkpoint and
    summary.json (complete: false) and raises KeyboardInterrupt. The GIL is released while the
    run steps.
    """
    if restart:
        if out is None:
            raise InputError("restart=True: out (the run folder to continue) is required")
        if scene is not None:
            raise InputError("restart=True continues the stored scene of out: give no scene")
        scene_path = ""
    else:
        if not isinstance(scene, (str, os.PathLike)):
            raise InputError(f"scene = {scene!r} ({type(scene).__name__}): must be the path of a scene file (TOML)")
        scene_path = os.fspath(scene)
        if not os.path.exists(scene_path):
            raise InputError(f"scene = {scene_path!r}: no such file")
    if out is not None and not isinstance(out, (str, os.PathLike)):
        raise InputError(f"out = {out!r} ({type(out).__name__}): must be a folder path")
    sets = []
    if set is not None:
        if not isinstance(set, dict):
            raise InputError(f"set = {set!r}: must be a dict {{key: value}}")
        sets = [f"{k}={_set_value(v)}" for k, v in set.items()]
    nthreads = 0 if threads is None else _integer(threads, "threads")
    cp = -1 if checkpoint_every is None else _integer(checkpoint_every, "checkpoint_every")
    stop = -1 if stop_after is None else _integer(stop_after, "stop_after")
    bar = None
    if progress:
        label = Path(scene_path).stem if scene_path else Path(os.fspath(out)).name
        try:
            from tqdm.auto import tqdm
            bar = _TqdmProgress(label, tqdm)
        except ImportError:
            bar = _TextProgress(label)
    try:
        text, out_dir, err = _core.run_scene(scene_path, sets, "" if out is None else os.fspath(out), nthreads, cp,
                                             stop, bool(restart), bar)
    finally:
        if bar is not None:
            bar.close()
    summary = json.loads(text)
    summary.setdefault("out", out_dir)
    if err is not None:
        raise err
    return summary


class Frame:
    """One output frame (frames/frame_N.h5), read lazily with h5py: ``frame.time`` [s],
    ``frame.step``, ``frame.bodies``, ``frame[body][field]`` -> numpy array (position (N, dim),
    scalars (N), vectors (N, 3), tensors (N, 6) or (N, 9)), ``frame.fields(body)``."""

    def __init__(self, path):
        self.path = path
        self._attrs = None

    def _file(self):
        import h5py
        return h5py.File(self.path, "r")

    def _meta(self):
        if self._attrs is None:
            with self._file() as f:
                self._attrs = {"time": float(f.attrs["time"]), "step": int(f.attrs["step"]),
                               "bodies": sorted(f["bodies"].keys()) if "bodies" in f else []}
        return self._attrs

    @property
    def time(self) -> float:
        return self._meta()["time"]

    @property
    def step(self) -> int:
        return self._meta()["step"]

    @property
    def bodies(self) -> list:
        return self._meta()["bodies"]

    def fields(self, body) -> list:
        with self._file() as f:
            return sorted(k for k in f["bodies"][body].keys())

    def __getitem__(self, body):
        frame = self

        class _Body:
            def __getitem__(self, field):
                with frame._file() as f:
                    return np.asarray(f["bodies"][body][field])

            def keys(self):
                return frame.fields(body)

        if body not in self.bodies:
            raise KeyError(f"{body!r}: not a body of {self.path} (bodies: {', '.join(self.bodies)})")
        return _Body()

    def __repr__(self):
        return f"Frame({self.path!r})"


class Run:
    """A run folder opened by :func:`open_run`: ``summary`` (dict), ``series`` (DataFrame of
    series.csv, read on first access), ``frames`` (list of :class:`Frame`, each read lazily),
    ``times`` (simulated time of each frame [s]) and ``field(body, field)`` (list of arrays over
    the frames)."""

    def __init__(self, path):
        self.path = Path(path)
        if not self.path.is_dir():
            raise InputError(f"dir = {os.fspath(path)!r}: not a folder")
        sp = self.path / "summary.json"
        self.summary = json.loads(sp.read_text()) if sp.exists() else None
        self._series = None
        self.frames = [Frame(str(p)) for p in sorted((self.path / "frames").glob("frame_*.h5"))]

    @property
    def series(self):
        if self._series is None:
            import pandas as pd
            self._series = pd.read_csv(self.path / "series.csv", comment="#")
        return self._series

    @property
    def times(self) -> list:
        return [fr.time for fr in self.frames]

    def field(self, body, field) -> list:
        return [fr[body][field] for fr in self.frames]

    def __repr__(self):
        return f"Run({os.fspath(self.path)!r}, {len(self.frames)} frames)"


def open_run(dir) -> Run:
    """Open a run folder (``oobleck run`` or :func:`run`): its summary, series and frames."""
    if not isinstance(dir, (str, os.PathLike)):
        raise InputError(f"dir = {dir!r} ({type(dir).__name__}): must be a folder path")
    return Run(dir)
from .sweep import sweep  # noqa: E402,F401  (oobleck.sweep: a grid of runs through the CLI, python/oobleck/sweep.py)
