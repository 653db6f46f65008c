"""driftless: MEMS IMU noise analysis from NumPy arrays, computed in Rust.

The functions ``adev``, ``oadev``, ``mdev``, ``hdev``, ``ohdev``, ``tdev`` and ``totdev``
take the arguments of the same functions in allantools and return the same
``(taus, devs, errs, ns)`` tuple: τ = m/rate for the averaging factors m chosen as
allantools chooses them, ``errs = devs / sqrt(ns)``, and factors with ``ns <= 1`` left out.
The GIL is released while the deviations are computed.

``analyse`` is driftless's own analysis of one channel (what ``driftless allan`` does for
each column of a log): the curve with confidence bounds per tau and, for a gyro or
accelerometer channel, the fitted noise model.
"""

import json
import math
import numbers

import numpy as np

from . import _driftless

__version__ = _driftless.__version__

__all__ = [
    "adev", "oadev", "mdev", "hdev", "ohdev", "tdev", "totdev",
    "analyse", "AnalysisResult", "NoiseModel", "simulate", "Simulation",
    "calibrate_six_position", "calibrate_multi_position", "CalibrationResult",
    "thermal_fit", "thermal_compensate", "ThermalModel", "simulate_chamber", "ChamberSession",
    "sensor_preset", "fleet",
    "navigate", "NavResult", "Solution", "default_nav_config",
    "experiment", "ExperimentResult", "montecarlo",
]


def _positive_rate(rate):
    return (isinstance(rate, numbers.Real) and not isinstance(rate, bool)
            and math.isfinite(rate) and rate > 0)


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
    if not _positive_rate(rate):
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


class NoiseModel:
    """A fitted noise model (the content of the TOML file ``driftless allan --save-model``
    writes). ``to_dict()`` is that file's structure; ``to_toml()`` its text; ``table()``
    the human-readable summary. Term values are SI (rad/s, m/s^2 based)."""

    def __init__(self, as_json, as_toml, table):
        self._dict = json.loads(as_json)
        self._toml = as_toml
        self._table = table

    @property
    def channels(self):
        """The channels' entries (name, quantity, unit, fit, discrete, …)."""
        return self._dict["channels"]

    def to_dict(self):
        return json.loads(json.dumps(self._dict))

    def to_toml(self):
        return self._toml

    def table(self):
        return self._table

    def __repr__(self):
        names = ", ".join(c["name"] for c in self.channels)
        return f"NoiseModel(channels=[{names}])"


class AnalysisResult:
    """One channel's stability curve: per tau the averaging factor ``m``, ``tau_s``, the
    number of terms ``n``, the deviation ``dev`` and its confidence bounds
    ``dev_lo``/``dev_hi`` (at ``confidence``), the noise exponent ``alpha`` and the
    equivalent degrees of freedom ``edf`` the bounds used, and ``rate_acf1`` (lag-1
    autocorrelation of the τ-averaged rates, NaN where too few blocks). All columns are
    NumPy arrays of equal length: ``pandas.DataFrame(result.columns())`` tabulates them.
    ``noise_model`` is the fitted model when ``analyse`` was given a ``quantity``."""

    COLUMNS = ("m", "tau_s", "n", "dev", "dev_lo", "dev_hi", "alpha", "edf", "rate_acf1")

    def __init__(self, raw):
        self.name = raw["name"]
        self.estimator = raw["estimator"]
        self.tau0_s = raw["tau0_s"]
        self.confidence = raw["confidence"]
        for key in self.COLUMNS:
            setattr(self, key, raw[key])
        self._curve_json = raw["curve_json"]
        self.noise_model = (
            NoiseModel(raw["model_json"], raw["model_toml"], raw["model_table"])
            if "model_json" in raw else None
        )

    def columns(self):
        """The per-tau columns as a dict of NumPy arrays."""
        return {key: getattr(self, key) for key in self.COLUMNS}

    def to_dict(self):
        """The curve in the library's serialised form (plus the model, if fitted)."""
        out = json.loads(self._curve_json)
        if self.noise_model is not None:
            out["noise_model"] = self.noise_model.to_dict()
        return out

    def __len__(self):
        return len(self.tau_s)

    def __repr__(self):
        return (f"AnalysisResult(name={self.name!r}, estimator={self.estimator!r}, "
                f"points={len(self)}, noise_model={'yes' if self.noise_model else 'no'})")


def _tau_spec(taus):
    if isinstance(taus, str):
        return taus
    tau_s = np.asarray(taus, dtype=np.float64).ravel()
    if len(tau_s) == 0:
        raise ValueError("taus is empty")
    return ",".join(repr(float(t)) for t in tau_s)


def analyse(data, rate, *, estimator="oadev", taus="log:100", data_type="freq",
            confidence=0.683, alpha=None, quantity=None, terms=None, name="channel"):
    """Stability curve of one channel with confidence bounds, and its noise model.

    data: rate samples (``data_type="freq"``, e.g. rad/s) or their integral
    (``"phase"``); rate: samples per second; estimator: adev, oadev, mdev, hdev, ohdev,
    tdev or totdev; taus: "octave", "decade", "all", "log:N" (N log-spaced factors, the
    default of ``driftless allan``) or taus in seconds; alpha: a fixed noise exponent
    for the bounds (None: identified per tau); quantity: "angular_rate" (gyro, rad/s) or
    "specific_force" (accelerometer, m/s^2) to fit a noise model; terms: the model's
    terms as ``driftless allan --fit`` takes them ("q,n,b,k,r,gm"; default: the IEEE 952
    terms and one Gauss-Markov term).
    """
    if not _positive_rate(rate):
        raise ValueError(f"rate must be a positive number of samples per second, got {rate!r}")
    raw = _driftless.analyse_channel(
        _samples(data), float(rate), str(name), estimator, _tau_spec(taus), data_type,
        alpha, float(confidence), quantity, terms,
    )
    return AnalysisResult(raw)


class Simulation:
    """The output of a scenario: ``imu`` maps ``time_s`` and each channel (``gyro_x`` …
    rad/s, ``acc_x`` … m/s^2, as ``driftless simulate`` names them) to NumPy arrays;
    ``gnss`` maps ``time_s``, ``lat_rad``, ``lon_rad``, ``height_m`` to arrays (None
    without a receiver, plus ``sigma_n_m``, ``sigma_e_m``, ``sigma_d_m`` and, when
    simulated, the velocity ``vel_n_m_s`` … with its σ); ``sensor`` is the resolved
    sensor configuration; ``tau0_s`` the IMU sample interval; ``truth`` the true
    trajectory of the IMU centre (``time_s``, ``lat_rad``, ``lon_rad``, ``height_m``,
    ``vel_n_m_s`` …, ``roll_rad`` …); ``lever_arm_b_m`` the GNSS antenna from the IMU,
    body FRD, m."""

    def __init__(self, raw):
        self.tau0_s = raw["tau0_s"]
        self.imu = raw["imu"]
        self.gnss = raw.get("gnss")
        self.sensor = json.loads(raw["sensor_json"])
        self.truth = raw["truth"]
        self.lever_arm_b_m = list(raw["lever_arm_b_m"])

    def to_dict(self):
        """Plain Python lists and dicts (JSON-serialisable)."""
        def plain(columns):
            return None if columns is None else {k: v.tolist() for k, v in columns.items()}
        return {"tau0_s": self.tau0_s, "imu": plain(self.imu), "gnss": plain(self.gnss),
                "sensor": json.loads(json.dumps(self.sensor)), "truth": plain(self.truth),
                "lever_arm_b_m": list(self.lever_arm_b_m)}

    def __repr__(self):
        n = len(next(iter(self.imu.values()))) if self.imu else 0
        return f"Simulation(samples={n}, channels={sorted(self.imu)}, gnss={self.gnss is not None})"


def simulate(scenario_toml, name="<scenario>"):
    """Run a scenario given as TOML text (the file format of ``driftless simulate``;
    relative paths in it resolve against the working directory). ``name`` appears in
    error messages."""
    return Simulation(_driftless.simulate_scenario(str(scenario_toml), str(name)))


from ._calib import (  # noqa: E402  (after the module's own API)
    CalibrationResult, ChamberSession, ThermalModel, calibrate_multi_position,
    calibrate_six_position, sensor_preset, simulate_chamber, thermal_compensate, thermal_fit,
)
from . import fleet  # noqa: E402
from ._nav import NavResult, Solution, default_nav_config, navigate  # noqa: E402
from . import montecarlo  # noqa: E402
from .montecarlo import ExperimentResult, experiment  # noqa: E402
