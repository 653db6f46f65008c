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

# Calibration and thermal calibration (driftless._calib)

from . import fleet as fleet

_Path = Union[str, bytes, "os.PathLike[str]"]
_Columns = Mapping[str, npt.ArrayLike]
_Array = npt.NDArray[np.float64]

class CalibrationResult:
    method: str
    source: str
    gravity_m_s2: float
    accel_raw_unit: str
    accel_bias: _Array
    accel_bias_sigma: _Array
    accel_matrix: _Array
    accel_matrix_sigma: _Array
    accel_forward: _Array
    accel_scale_factor: _Array
    accel_misalignment: _Array
    accel_residual_rms: Optional[float]
    gyro_raw_unit: str
    gyro_bias: _Array
    gyro_bias_sigma: _Array
    gyro_matrix: _Array
    gyro_matrix_sigma: _Array
    gyro_forward: _Array
    gyro_scale_factor: _Array
    gyro_misalignment: _Array
    gyro_residual_rms: Optional[float]
    gyro_g_sensitivity: Optional[_Array]
    static_intervals: _Array
    quality: Optional[Dict[str, Dict[str, Any]]]
    residuals_m_s2: Optional[_Array]
    details: Dict[str, Any]
    def apply(
        self, accel: Optional[npt.ArrayLike] = None, gyro: Optional[npt.ArrayLike] = None
    ) -> Tuple[Optional[_Array], Optional[_Array]]: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def to_toml(self) -> str: ...
    def save(self, path: _Path) -> None: ...
    @classmethod
    def load(cls, path: _Path) -> "CalibrationResult": ...
    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "CalibrationResult": ...

def calibrate_six_position(
    data: Union[None, _Path, _Columns] = None,
    *,
    manifest: Optional[_Path] = None,
    manifest_toml: Optional[str] = None,
    gyro: Optional[npt.ArrayLike] = None,
    accel: Optional[npt.ArrayLike] = None,
    time_s: Optional[npt.ArrayLike] = None,
    rate_hz: Optional[float] = None,
    temperature_c: Optional[float] = None,
    gravity_m_s2: Optional[float] = None,
    g_sensitivity: bool = False,
    units: str = "si",
    name: Optional[str] = None,
) -> CalibrationResult: ...
def calibrate_multi_position(
    data: Union[None, _Path, _Columns] = None,
    *,
    gyro: Optional[npt.ArrayLike] = None,
    accel: Optional[npt.ArrayLike] = None,
    time_s: Optional[npt.ArrayLike] = None,
    rate_hz: Optional[float] = None,
    gravity_m_s2: Optional[float] = None,
    lat_deg: float = 45.0,
    height_m: float = 0.0,
    gyro_scale_guess: Optional[float] = None,
    accel_offset: Optional[float] = None,
    accept_poor_fit: bool = False,
    units: str = "si",
    name: Optional[str] = None,
) -> CalibrationResult: ...

class ThermalModel:
    model_id: int
    t_ref_c: float
    range_c: Tuple[float, float]
    out_of_range: str
    accel_raw_unit: str
    accel_bias: _Array
    accel_matrix: _Array
    accel_bias_delta: _Array
    accel_scale_delta: _Array
    gyro_raw_unit: str
    gyro_bias: _Array
    gyro_matrix: _Array
    gyro_bias_delta: _Array
    gyro_scale_delta: _Array
    gyro_g_sensitivity: Optional[_Array]
    method: Optional[str]
    fits: List[Dict[str, Any]]
    temperatures_c: Optional[_Array]
    warnings: List[str]
    def fit(self, triad: str, quantity: str, axis: str) -> Dict[str, Any]: ...
    def compensate(
        self, gyro: npt.ArrayLike, accel: npt.ArrayLike, temperature_c: npt.ArrayLike
    ) -> Tuple[_Array, _Array]: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def to_toml(self) -> str: ...
    def save(self, path: _Path) -> None: ...
    @classmethod
    def load(cls, path: _Path) -> "ThermalModel": ...
    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "ThermalModel": ...

def thermal_fit(
    data: Union[None, _Path, _Columns] = None,
    *,
    manifest: Optional[_Path] = None,
    manifest_toml: Optional[str] = None,
    method: Optional[str] = None,
    gyro: Optional[npt.ArrayLike] = None,
    accel: Optional[npt.ArrayLike] = None,
    temperature_c: Optional[npt.ArrayLike] = None,
    time_s: Optional[npt.ArrayLike] = None,
    rate_hz: Optional[float] = None,
    order: int = 3,
    t_ref_c: float = 25.0,
    out_of_range: str = "clamp",
    min_rise_c: float = 10.0,
    bin_c: float = 1.0,
    name: Optional[str] = None,
) -> ThermalModel: ...
def thermal_compensate(
    model: Union[ThermalModel, _Path],
    gyro: npt.ArrayLike,
    accel: npt.ArrayLike,
    temperature_c: npt.ArrayLike,
) -> Tuple[_Array, _Array]: ...

class ChamberSession:
    tau0_s: float
    imu: Dict[str, _Array]
    manifest_toml: str
    sensor: Dict[str, Any]

def simulate_chamber(
    scenario_toml: str, name: str = "<scenario>", sensor: Optional[Mapping[str, Any]] = None
) -> ChamberSession: ...
def sensor_preset(name: str) -> Dict[str, Any]: ...

# Navigation and the experiment (driftless._nav, driftless.montecarlo)

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
