from typing import Any, Dict, Mapping, Optional, Tuple

import numpy as np
import numpy.typing as npt

DEFAULT_PROTOCOL: Dict[str, Any]
CHANNELS: Tuple[str, ...]

def unit_truth(unit_id: int, seed: int = 0, spread: float = 0.25) -> Dict[str, npt.NDArray[np.float64]]: ...
def simulate_unit(
    unit_id: int, seed: int = 0, protocol: Optional[Mapping[str, Any]] = None, spread: float = 0.25
) -> Dict[str, Any]: ...
def calibrate_unit(unit: Mapping[str, Any], order: int = 3, t_ref_c: float = 25.0) -> Dict[str, float]: ...
def unit_row(
    unit_id: int, seed: int = 0, protocol: Optional[Mapping[str, Any]] = None, order: int = 3
) -> Dict[str, float]: ...
