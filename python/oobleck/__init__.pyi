# Type stubs of the oobleck package (units: see the docstrings in the modules of oobleck/).
import os
from typing import Any, Literal, Optional, Sequence, Union, overload

import numpy as np
import pandas as pd

class InputError(ValueError): ...
class NumericalError(RuntimeError): ...

class Params:
    name: str
    source: str
    units: str
    file: str
    phi_c: float  # [-]
    phi_j: float  # [-]
    a_0: float  # [-]
    a_inf: float  # [-]
    tau_star: float  # [Pa]
    eta_0: float  # [Pa s]
    mu_c: float  # [-]
    Delta: float  # [-]
    xi_dot_eps: float  # [1/s]
    eta_B: list[tuple[float, float]]  # [(phi_i [1/(Pa s)], alpha [-])]
    d: float  # [m]
    rho_s: float  # [kg/m^3]
    mu_2: float  # [-]
    b: float  # [-]
    K_3: float  # [-]
    K_4: float  # [-]
    G: float  # [Pa]
    K: float  # [Pa]
    K_0: float  # [-]
    def __init__(self, other: Params) -> None: ...
    @staticmethod
    def from_dict(values: dict[str, Any]) -> Params: ...
    def toml(self) -> str: ...
    def to_toml(self, path: Optional[Union[str, os.PathLike]] = None) -> str: ...
    def to_dict(self) -> dict[str, Any]: ...
    def copy(self) -> Params: ...

ParamsLike = Union[Params, str, os.PathLike]
Numbers = Union[float, Sequence[float], np.ndarray]

class FitResult:
    kind: str
    params: Params
    base: Params
    values: dict[str, float]
    stderr: dict[str, float]
    correlation: pd.DataFrame
    covariance: Optional[pd.DataFrame]
    residuals: pd.DataFrame
    residual_kind: str
    n: int
    p: int
    rms: float
    cost: float
    iterations: int
    held: list[tuple[str, str]]
    def plot(self, ax: Any = None, y: Literal["stress", "viscosity"] = "stress",
             x: Literal["rate", "stress"] = "rate") -> Any: ...

class Frame:
    path: str
    time: float
    step: int
    bodies: list[str]
    def fields(self, body: str) -> list[str]: ...
    def __getitem__(self, body: str) -> Any: ...

class Run:
    summary: Optional[dict[str, Any]]
    series: pd.DataFrame
    frames: list[Frame]
    times: list[float]
    def field(self, body: str, field: str) -> list[np.ndarray]: ...

def version() -> str: ...
def presets() -> list[str]: ...
def parameter_table() -> Any: ...  # pandas.DataFrame
def load_params(name_or_path: Union[str, os.PathLike]) -> Params: ...
FLOW_CURVE_COLUMNS: tuple[str, ...]
@overload
def flow_curve(params: ParamsLike, phi: Numbers, points: int = 200, *,
               as_frame: Literal[True] = True) -> pd.DataFrame: ...
@overload
def flow_curve(params: ParamsLike, phi: Numbers, points: int = 200, *,
               as_frame: Literal[False]) -> dict[str, np.ndarray]: ...
def shear_rate_dst(params: ParamsLike, phi: Numbers) -> Union[Optional[float], list[Optional[float]]]: ...
def structure(params: ParamsLike, points: int = 200) -> pd.DataFrame: ...
def volume_fraction(mass_fraction: float, rho_cs: float, rho_liquid: float, rho_water: float,
                    lambda_: float = 0.3, beta: float = 0.1) -> float: ...
def viscosity_at(params: ParamsLike, phi: float, shear_rate: Optional[Numbers] = None,
                 shear_stress: Optional[Numbers] = None,
                 full: bool = False) -> Union[np.ndarray, dict[str, np.ndarray]]: ...
def fit(kind: str, data: Union[pd.DataFrame, str, os.PathLike, Sequence[Union[str, os.PathLike]]],
        params: Optional[ParamsLike] = None, *,
        terms: Optional[int] = None, parameters: Optional[Sequence[str]] = None, residual: str = "rate",
        bounds: Optional[dict[str, tuple[Optional[float], Optional[float]]]] = None,
        phi: Optional[Numbers] = None, step: Optional[Union[str, int, list]] = None,
        strict: bool = False) -> FitResult: ...
RHEOMETER_COLUMNS: tuple[str, ...]
def read_rheometer(path: Union[str, os.PathLike], format: str = "auto", *,
                   step: Optional[Union[str, int]] = None) -> pd.DataFrame: ...
SHEAR_COLUMNS: tuple[str, ...]
RELAX_COLUMNS: tuple[str, ...]
def point_shear(params: ParamsLike, phi: float, *, shear_rate: Optional[float] = None,
                shear_stress: Optional[float] = None, duration: float, dt: Optional[float] = None,
                f0: float = 0.0, samples: int = 1000, **overrides: float) -> pd.DataFrame: ...
def point_relax(params: ParamsLike, phi: float, *, shear_rate: Optional[float] = None,
                shear_stress: Optional[float] = None, duration: float, dt: Optional[float] = None,
                samples: int = 200, G: Optional[Numbers] = None, K0: Optional[Numbers] = None,
                **overrides: float) -> pd.DataFrame: ...
def run(scene: Optional[Union[str, os.PathLike]] = None, out: Optional[Union[str, os.PathLike]] = None,
        threads: Optional[int] = None, set: Optional[dict[str, Any]] = None, progress: bool = True, *,
        checkpoint_every: Optional[int] = None, stop_after: Optional[int] = None,
        restart: bool = False) -> dict[str, Any]: ...
def open_run(dir: Union[str, os.PathLike]) -> Run: ...
