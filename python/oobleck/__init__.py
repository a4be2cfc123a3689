"""oobleck in Python: the Baumgarten–Kamrin (PNAS 2019) model of dense suspensions.

Every number comes from the same C++ library as the ``oobleck`` command line (liboobleck, through
the compiled module ``oobleck._oobleck``); this package converts arguments and builds pandas
DataFrames whose columns are exactly those of the CLI's CSV files. Units are SI (normalized
units for the Singh presets: stresses in eta_0 gamma_dot_0). Equations E1–E29 are those of
docs/equations.md. Bad input raises :class:`InputError` (a ``ValueError``) naming the argument and
the rule; a numerical failure (non-convergence) raises :class:`NumericalError`.
"""
from __future__ import annotations

import os
from pathlib import Path

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
    "run", "open_run", "version", "read_rheometer", "parameter_table",
]


def version() -> str:
    """oobleck's version and build, as ``oobleck --version``."""
    return _core.version()


# The topic modules import _core, InputError and Params from here, so these come
# first. Each public object is named oobleck.NAME (help(), repr, pickling), not by its module.
from ._parameters import load_params, parameter_table, presets  # noqa: E402
from ._rheology import (FLOW_CURVE_COLUMNS, flow_curve, shear_rate_dst, structure,  # noqa: E402,F401
                        viscosity_at, volume_fraction)
from ._rheometer import RHEOMETER_COLUMNS, read_rheometer  # noqa: E402,F401
from ._fit import FitResult, fit  # noqa: E402
from ._point import RELAX_COLUMNS, SHEAR_COLUMNS, point_relax, point_shear  # noqa: E402,F401
from ._run import Frame, Run, open_run, run  # noqa: E402

for _obj in (load_params, parameter_table, presets, flow_curve, shear_rate_dst, structure, viscosity_at, volume_fraction,
             read_rheometer, FitResult, fit, point_relax, point_shear, Frame, Run, open_run, run,
             Params.to_dict, Params.to_toml, Params.copy, Params.__repr__, Params.__eq__):
    _obj.__module__ = __name__
del _obj

from .sweep import sweep  # noqa: E402,F401  (oobleck.sweep: a grid of runs through the CLI, python/oobleck/sweep.py)
