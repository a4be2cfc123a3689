"""Argument checking shared by the package's functions: numbers, integers, lists of numbers and
parameter sets, each raising InputError that names the argument; pandas, imported on first use."""
from __future__ import annotations

import math
import numbers
import os

import numpy as np

from . import InputError, Params
from ._parameters import load_params


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


_pd = None


def _pandas():
    global _pd
    if _pd is None:
        import pandas
        _pd = pandas
    return _pd


def _frame(columns: dict, order):
    return _pandas().DataFrame({k: columns[k] for k in order})
