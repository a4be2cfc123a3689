"""Rheometer exports: read_rheometer (TRIOS, RheoCompass, rSpace, CSV with units) and the
(phi, shear_rate, shear_stress) table of exports that fit('curves', ..., phi=...) reads."""
from __future__ import annotations

import os

from . import InputError, _core
from ._args import _numbers, _pandas


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
