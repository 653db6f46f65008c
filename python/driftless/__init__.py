"""driftless: MEMS IMU noise analysis from NumPy arrays, computed in Rust.

The functions ``adev``, ``oadev``, ``mdev``, ``hdev``, ``ohdev``, ``tdev`` and ``totdev``
take the arguments of the same functions in allantools and return the same
``(taus, devs, errs, ns)`` tuple: τ = m/rate for the averaging factors m chosen as
allantools chooses them, ``errs = devs / sqrt(ns)``, and factors with ``ns <= 1`` left out.
The GIL is released while the deviations are computed.
"""

import math

import numpy as np

from . import _driftless

__version__ = _driftless.__version__

__all__ = ["adev", "oadev", "mdev", "hdev", "ohdev", "tdev", "totdev"]


def _samples(data):
    values = np.ascontiguousarray(data, dtype=np.float64)
    if values.ndim != 1:
        raise ValueError(f"data must be one-dimensional, got shape {values.shape}")
    return values


def _averaging_factors(taus, rate, n_phase):
    """The averaging factors m (as floats) for a tau request on ``n_phase`` phase points.

    Keywords: "all" = 1, 2, …, n_phase − 1; "octave" (the default, also for None or an
    empty list) = powers of two; "decade" = 1, 2, 4 × 10^k; "log10" = about ten
    log-spaced factors per decade up to n_phase. An array of taus is turned into
    m = round(tau·rate) (round half to even). Factors outside 1 ≤ m < n_phase are left
    out and the rest sorted without duplicates.
    """
    if taus is None or (isinstance(taus, (list, tuple)) and len(taus) == 0):
        taus = "octave"
    if isinstance(taus, str):
        if taus == "all":
            m = np.arange(1.0, n_phase)
        elif taus == "octave":
            m = 2.0 ** np.arange(0, math.floor(math.log2(n_phase)) + 1)
        elif taus == "decade":
            k = np.arange(0, math.floor(math.log10(n_phase)) + 1)
            m = (np.array([1.0, 2.0, 4.0])[None, :] * 10.0 ** k[:, None]).ravel()
        elif taus == "log10":
            top = np.log10(n_phase)
            m = np.round((1.0 / rate) * np.logspace(0, top, int(10 * top)) * rate)
        else:
            raise ValueError(
                f'unknown taus keyword {taus!r}; expected "all", "octave", "decade", '
                '"log10", or an array of taus in seconds'
            )
    else:
        tau_s = np.asarray(taus, dtype=np.float64).ravel()
        if not np.all(np.isfinite(tau_s)):
            raise ValueError(f"taus must be finite seconds, got {tau_s[~np.isfinite(tau_s)][:3]}")
        m = np.round(tau_s * rate)
    return np.unique(m[(m > 0) & (m < n_phase)])


def _deviation(name, data, rate, data_type, taus):
    if not (isinstance(rate, (int, float)) and math.isfinite(rate) and rate > 0):
        raise ValueError(f"rate must be a positive number of samples per second, got {rate!r}")
    values = _samples(data)
    n_phase = len(values) + 1 if data_type == "freq" else len(values)
    if n_phase < 2:
        raise ValueError(f"{name} needs at least 2 samples, got {len(values)}")
    ms = _averaging_factors(taus, float(rate), n_phase)
    if len(ms) == 0:
        raise ValueError(
            f"{name}: no tau in {taus!r} gives an averaging factor between 1 and "
            f"{n_phase - 1} samples at rate {rate} Hz"
        )
    return _driftless.allan_compat(name, values, float(rate), data_type, ms.astype(np.int64).tolist())


def adev(data, rate=1.0, data_type="phase", taus=None):
    """Non-overlapping Allan deviation (NIST SP 1065 eq. 7); allantools' ``adev``."""
    return _deviation("adev", data, rate, data_type, taus)


def oadev(data, rate=1.0, data_type="phase", taus=None):
    """Overlapping Allan deviation (SP 1065 eq. 11); allantools' ``oadev``."""
    return _deviation("oadev", data, rate, data_type, taus)


def mdev(data, rate=1.0, data_type="phase", taus=None):
    """Modified Allan deviation (SP 1065 eq. 14); allantools' ``mdev``."""
    return _deviation("mdev", data, rate, data_type, taus)


def hdev(data, rate=1.0, data_type="phase", taus=None):
    """Non-overlapping Hadamard deviation (SP 1065 eq. 17); allantools' ``hdev``."""
    return _deviation("hdev", data, rate, data_type, taus)


def ohdev(data, rate=1.0, data_type="phase", taus=None):
    """Overlapping Hadamard deviation (SP 1065 eq. 18); allantools' ``ohdev``."""
    return _deviation("ohdev", data, rate, data_type, taus)


def tdev(data, rate=1.0, data_type="phase", taus=None):
    """Time deviation τ/√3·MDEV (SP 1065 eq. 16); allantools' ``tdev``."""
    return _deviation("tdev", data, rate, data_type, taus)


def totdev(data, rate=1.0, data_type="phase", taus=None):
    """Total deviation on the reflection-extended phase (SP 1065 eq. 25); allantools'
    ``totdev``."""
    return _deviation("totdev", data, rate, data_type, taus)
