import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Taus = Union[None, str, Sequence[float], npt.NDArray[np.floating]]
_Curve = Tuple[
    npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]
]

def adev(data: npt.ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: _Taus = None) -> _Curve: ...
def oadev(data: npt.ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: _Taus = None) -> _Curve: ...
def mdev(data: npt.ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: _Taus = None) -> _Curve: ...
def hdev(data: npt.ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: _Taus = None) -> _Curve: ...
def ohdev(data: npt.ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: _Taus = None) -> _Curve: ...
def tdev(data: npt.ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: _Taus = None) -> _Curve: ...
def totdev(data: npt.ArrayLike, rate: float = 1.0, data_type: str = "phase", taus: _Taus = None) -> _Curve: ...

class NoiseModel:
    @property
    def channels(self) -> List[Dict[str, Any]]: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def to_toml(self) -> str: ...
    def table(self) -> str: ...

class AnalysisResult:
    COLUMNS: Tuple[str, ...]
    name: str
    estimator: str
    tau0_s: float
    confidence: float
    m: npt.NDArray[np.float64]
    tau_s: npt.NDArray[np.float64]
    n: npt.NDArray[np.float64]
    dev: npt.NDArray[np.float64]
    dev_lo: npt.NDArray[np.float64]
    dev_hi: npt.NDArray[np.float64]
    alpha: npt.NDArray[np.int32]
    edf: npt.NDArray[np.float64]
    rate_acf1: npt.NDArray[np.float64]
    noise_model: Optional[NoiseModel]
    def columns(self) -> Dict[str, npt.NDArray[Any]]: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def __len__(self) -> int: ...

def analyse(
    data: npt.ArrayLike,
    rate: float,
    *,
    estimator: str = "oadev",
    taus: Union[str, Sequence[float], npt.NDArray[np.floating]] = "log:100",
    data_type: str = "freq",
    confidence: float = 0.683,
    alpha: Optional[int] = None,
    quantity: Optional[str] = None,
    terms: Optional[str] = None,
    name: str = "channel",
) -> AnalysisResult: ...

class Simulation:
    tau0_s: float
    imu: Dict[str, npt.NDArray[np.float64]]
    gnss: Optional[Dict[str, npt.NDArray[np.float64]]]
    sensor: Dict[str, Any]
    truth: Dict[str, npt.NDArray[np.float64]]
    lever_arm_b_m: List[float]
    def to_dict(self) -> Dict[str, Any]: ...

def simulate(scenario_toml: str, name: str = "<scenario>") -> Simulation: ...

_Columns = Mapping[str, npt.ArrayLike]
_Path = Union[str, "os.PathLike[str]"]

class Solution:
    time_s: npt.NDArray[np.float64]
    lat_rad: npt.NDArray[np.float64]
    lon_rad: npt.NDArray[np.float64]
    height_m: npt.NDArray[np.float64]
    vel_n_m_s: npt.NDArray[np.float64]
    vel_e_m_s: npt.NDArray[np.float64]
    vel_d_m_s: npt.NDArray[np.float64]
    roll_rad: npt.NDArray[np.float64]
    pitch_rad: npt.NDArray[np.float64]
    yaw_rad: npt.NDArray[np.float64]
    sigma_n_m: npt.NDArray[np.float64]
    sigma_e_m: npt.NDArray[np.float64]
    sigma_d_m: npt.NDArray[np.float64]
    def __getattr__(self, name: str) -> npt.NDArray[np.float64]: ...
    def columns(self) -> Dict[str, npt.NDArray[np.float64]]: ...
    def to_dict(self) -> Dict[str, List[float]]: ...
    def horizontal_rms_m(
        self, reference: Union[_Columns, "Solution"], *, from_s: Optional[float] = None,
        max_reference_gap_s: float = 2.0,
    ) -> float: ...
    def __len__(self) -> int: ...

class NavResult:
    forward: Solution
    smoothed: Optional[Solution]
    gnss_accepted: int
    gnss_rejected: int
    gnss_withheld: int
    gnss_fixes: int
    start_time_s: float
    prediction_rms_m: Optional[float]
    outages: List[Dict[str, Optional[float]]]
    config: Optional[Dict[str, Any]]
    notes: List[str]
    files: List[str]
    def horizontal_rms_m(
        self, reference: Union[_Columns, Solution], *, smoothed: bool = False,
        from_s: Optional[float] = None, max_reference_gap_s: float = 2.0,
    ) -> float: ...
    def to_dict(self) -> Dict[str, Any]: ...

def default_nav_config() -> Dict[str, Dict[str, Any]]: ...
def navigate(
    imu: Union[None, _Columns, _Path] = None,
    gnss: Union[None, _Columns, _Path] = None,
    config: Union[None, Mapping[str, Mapping[str, Any]], _Path] = None,
    *,
    smooth: bool = True,
    outages: Optional[str] = None,
    gate: Optional[str] = None,
) -> NavResult: ...

from . import montecarlo as montecarlo
from .montecarlo import ExperimentResult as ExperimentResult, experiment as experiment
