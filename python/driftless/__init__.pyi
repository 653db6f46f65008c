from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

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
    def to_dict(self) -> Dict[str, Any]: ...

def simulate(scenario_toml: str, name: str = "<scenario>") -> Simulation: ...
