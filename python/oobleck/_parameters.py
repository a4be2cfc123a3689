"""Parameter sets: the shipped presets, load_params, and the Python methods of Params (to_dict,
to_toml, copy, repr, equality)."""
from __future__ import annotations

import os

from . import InputError, Params, _core


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


# The parameters' names in the order of the table (src/oobleck/rheology/parameter_table.cpp).
_PARAM_FIELDS = tuple(r["name"] for r in _core.parameter_table() if r["section"] == "steady")
_GRANULAR_FIELDS = tuple(r["name"] for r in _core.parameter_table() if r["section"] == "granular")


def parameter_table():
    """Every steady, granular and fluid parameter as a pandas DataFrame, one row each: name,
    section (the TOML table: ``steady``/``granular`` in a preset or a scene's ``[material]``,
    ``fluid`` in a scene's ``[fluid]``), unit (SI, ``1`` for dimensionless), default (``required``
    for what a preset must give), range (and its ends lower/upper, open or not), equation
    (docs/equations.md) and meaning. The same table drives the preset reader, the checks,
    summary.json and the :class:`Params` properties (docs/scenes.md lists it)."""
    from ._args import _pandas  # (_args imports this module)
    return _pandas().DataFrame(_core.parameter_table())


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
