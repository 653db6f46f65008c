"""Calibration and thermal calibration from NumPy arrays or log files.

The functions here call the same library jobs as ``driftless calibrate`` and
``driftless thermal`` (with the GIL released) and return typed results whose
``to_dict()`` / ``to_toml()`` / ``save()`` are the model files those commands write.

Data layout, shared by every function: ``data`` is either a log file path (read as the
CLI reads it: time in column 1, channels by their header units) or a mapping of NumPy
columns as ``driftless.simulate`` returns them (``gyro_x``, ``gyro_y``, ``gyro_z`` in
rad/s, ``acc_x``, ``acc_y``, ``acc_z`` in m/s², optional ``temp`` in °C and ``time_s``);
instead of a mapping, ``gyro=`` and ``accel=`` take (N, 3) arrays and
``temperature_c=`` an (N,) array. The sample interval comes from ``rate_hz`` or, without
it, from the median step of ``time_s``.
"""

import json
import math
import numbers
import os
from collections.abc import Mapping

import numpy as np

from . import _driftless

__all__ = [
    "CalibrationResult", "calibrate_six_position", "calibrate_multi_position",
    "ThermalModel", "thermal_fit", "thermal_compensate", "ChamberSession", "simulate_chamber",
    "sensor_preset",
]

_GYRO = ("gyro_x", "gyro_y", "gyro_z")
_ACCEL = ("acc_x", "acc_y", "acc_z")
_TEMP_KEYS = ("temp", "temperature_c")


def _column(values, what, n=None):
    a = np.ascontiguousarray(values, dtype=np.float64)
    if a.ndim != 1:
        raise ValueError(f"{what} must be one-dimensional, got shape {a.shape}")
    if n is not None and len(a) != n:
        raise ValueError(f"{what} has {len(a)} samples, expected {n} (as the other columns)")
    bad = np.flatnonzero(~np.isfinite(a))
    if len(bad):
        raise ValueError(
            f"{what}: sample {bad[0]} is {a[bad[0]]} ({len(bad)} non-finite samples); "
            "every sample must be a finite number"
        )
    return a


def _triad(values, what):
    a = np.asarray(values, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{what} must have shape (N, 3) (x, y, z columns), got {a.shape}")
    return [a[:, k] for k in range(3)]


def _is_path(data):
    return isinstance(data, (str, bytes, os.PathLike))


class _Log:
    """A log as the extension takes it: a path, or named columns with quantities."""

    def __init__(self, path=None, columns=(), time_s=None, tau0_s=None, name="<arrays>"):
        self.path, self.columns, self.time_s = path, list(columns), time_s
        self.tau0_s, self.name = tau0_s, name

    def args(self):
        return (self.path, self.columns, self.time_s, self.tau0_s, self.name)


def _log(data, gyro, accel, temperature_c, time_s, rate_hz, name, need_temperature=False,
         units="si", accel_first=False):
    """The log of ``data`` (path or mapping) or of the gyro/accel/temperature arrays."""
    if data is not None and _is_path(data):
        if any(v is not None for v in (gyro, accel, temperature_c, time_s)):
            raise ValueError("give a log file or arrays, not both")
        path = os.fsdecode(data)
        return _Log(path=path, name=name or path)
    if data is not None:
        if not isinstance(data, Mapping):
            raise ValueError(
                f"data must be a log file path or a mapping of columns (gyro_x … acc_z), "
                f"got {type(data).__name__}"
            )
        missing = [k for k in _GYRO + _ACCEL if k not in data]
        if missing:
            raise ValueError(
                f"data lacks the columns {missing}; expected {list(_GYRO + _ACCEL)} "
                "(rad/s, m/s^2), optional 'temp' (°C) and 'time_s'"
            )
        g = [data[k] for k in _GYRO]
        a = [data[k] for k in _ACCEL]
        if temperature_c is None:
            temperature_c = next((data[k] for k in _TEMP_KEYS if k in data), None)
        if time_s is None:
            time_s = data.get("time_s")
    else:
        if gyro is None or accel is None:
            raise ValueError("give data (a log file or a mapping of columns), or gyro= and accel=")
        g, a = _triad(gyro, "gyro"), _triad(accel, "accel")
    if units not in ("si", "raw"):
        raise ValueError(f'units must be "si" (rad/s, m/s^2) or "raw" (counts), got {units!r}')
    qg, qa = ("angular_rate", "specific_force") if units == "si" else ("other", "other")
    gcols = [(c, qg, _column(v, c)) for c, v in zip(_GYRO, g)]
    n = len(gcols[0][2])
    if n < 2:
        raise ValueError(f"the log has {n} samples; a calibration needs many")
    gcols = [(c, q, _column(v, c, n)) for c, q, v in gcols]
    acols = [(c, qa, _column(v, c, n)) for c, v in zip(_ACCEL, a)]
    # raw columns are taken by position: six-position gyro then accel, multi-position
    # accel then gyro (as the CLI reads a file of counts)
    cols = acols + gcols if accel_first else gcols + acols
    if temperature_c is not None:
        cols.append(("temp", "temperature", _column(temperature_c, "temperature_c", n)))
    elif need_temperature:
        raise ValueError("the ramp method needs temperature_c (or a 'temp' column), °C per sample")
    t = None if time_s is None else _column(time_s, "time_s", n)
    if t is not None and np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise ValueError(f"time_s must increase: sample {i + 1} ({t[i + 1]}) is not after {t[i]}")
    if rate_hz is not None:
        if not (isinstance(rate_hz, numbers.Real) and not isinstance(rate_hz, bool)
                and math.isfinite(rate_hz) and rate_hz > 0):
            raise ValueError(f"rate_hz must be a positive number of samples per second, got {rate_hz!r}")
        tau0 = 1.0 / float(rate_hz)
    elif t is not None:
        tau0 = float(np.median(np.diff(t)))
    else:
        raise ValueError("give rate_hz or time_s (the sample interval is needed)")
    return _Log(columns=cols, time_s=t, tau0_s=tau0, name=name or "<arrays>")


def _manifest(manifest, manifest_toml):
    if (manifest is None) == (manifest_toml is None):
        raise ValueError(
            "give the segment manifest as a file (manifest=PATH) or as TOML text "
            "(manifest_toml=TEXT), one of the two"
        )
    if manifest_toml is not None:
        return str(manifest_toml), "<manifest>"
    path = os.fsdecode(manifest)
    try:
        with open(path, encoding="utf-8") as f:
            return f.read(), path
    except OSError as e:
        raise ValueError(f"{path}: {e.strerror}") from None


def _arr(v):
    return None if v is None else np.asarray(v, dtype=np.float64)


class _ModelFile:
    """What a result backed by a model file shares: its dict, text, writing and
    reading through the library (``_save``, ``_load``, ``_from_json``: the extension's
    functions of the file type)."""

    _save = _load = _from_json = None

    def to_dict(self):
        """The model file as plain Python data (the TOML's structure)."""
        return json.loads(json.dumps(self._dict))

    def to_toml(self):
        """The model file's text (what the CLI's ``--out`` writes)."""
        return self._toml

    def save(self, path):
        """Writes the model file (temporary file + rename)."""
        self._save(self._toml, os.fsdecode(path))

    @classmethod
    def load(cls, path):
        """Reads a model file, checked by the library as the CLI checks it."""
        text, as_json = cls._load(os.fsdecode(path))
        return cls(text, as_json)

    @classmethod
    def from_dict(cls, d):
        """The object of a model file's dict (``to_dict()``), checked by the library."""
        text, as_json = cls._from_json(json.dumps(d))
        return cls(text, as_json)


class CalibrationResult(_ModelFile):
    """A room-temperature calibration, calibrated = M·(raw − b) per triad (SI out: m/s²,
    rad/s; raw in the input's units).

    Attributes per triad (``accel_…`` and ``gyro_…``): ``_bias`` b (3,), ``_bias_sigma``
    its 1σ, ``_matrix`` M (3, 3), ``_matrix_sigma`` 1σ of each entry, ``_forward`` the
    sensor model A = M⁻¹ (raw = A·x + b), ``_scale_factor`` diag(A) (3,),
    ``_misalignment`` diag(A)⁻¹·A − I (dimensionless, zero diagonal), ``_residual_rms``
    (multi-position: RMS |a| − g in m/s² and the gravity-direction RMS in rad; None for
    six-position). ``gyro_g_sensitivity`` is G (raw gyro per m/s²) when estimated;
    ``static_intervals`` the (K, 2) start/end times used (multi-position);
    ``quality`` maps ``accel``/``gyro`` to χ²/dof, dof, warnings and implausible;
    ``residuals_m_s2`` is |a| − g of the calibrated accelerometer per static position or
    interval; ``details`` holds the method's other figures.

    ``to_dict()`` is the calibration model file (the serde form the CLI's ``--out``
    writes as TOML), ``to_toml()`` its text, ``save(path)`` writes it through the
    library's writer, ``CalibrationResult.load(path)`` reads one.
    """

    _save = staticmethod(_driftless.calib_save)
    _load = staticmethod(_driftless.calib_load)
    _from_json = staticmethod(_driftless.calib_from_json)

    def __init__(self, file_toml, file_json, quality=None, residuals_m_s2=None, details=None):
        self._toml = file_toml
        self._dict = json.loads(file_json)
        d = self._dict
        self.method = d["method"]
        self.source = d["source"]
        self.gravity_m_s2 = d["gravity_m_s2"]
        for triad in ("accel", "gyro"):
            t = d[triad]
            m = np.array(t["matrix"], dtype=np.float64)
            a = np.linalg.inv(m)
            setattr(self, f"{triad}_raw_unit", t["raw_unit"])
            setattr(self, f"{triad}_bias", np.array(t["bias"], dtype=np.float64))
            setattr(self, f"{triad}_bias_sigma", np.array(t["bias_sigma"], dtype=np.float64))
            setattr(self, f"{triad}_matrix", m)
            setattr(self, f"{triad}_matrix_sigma", np.array(t["matrix_sigma"], dtype=np.float64))
            setattr(self, f"{triad}_forward", a)
            setattr(self, f"{triad}_scale_factor", np.diag(a).copy())
            setattr(self, f"{triad}_misalignment", a / np.diag(a)[:, None] - np.eye(3))
            setattr(self, f"{triad}_residual_rms", t.get("residual_rms"))
        self.gyro_g_sensitivity = _arr(d.get("gyro_g_sensitivity"))
        self.static_intervals = np.array(d.get("static_intervals", []), dtype=np.float64).reshape(-1, 2)
        self.quality = quality
        self.residuals_m_s2 = residuals_m_s2
        self.details = details or {}

    def apply(self, accel=None, gyro=None):
        """Calibrates raw samples ((N, 3) arrays, or (3,)): M·(raw − b) per triad.
        Returns (accel, gyro), None for a triad not given."""
        def one(raw, b, m, what):
            if raw is None:
                return None
            r = np.asarray(raw, dtype=np.float64)
            if r.shape[-1] != 3:
                raise ValueError(f"{what} must have x, y, z as its last axis, got shape {r.shape}")
            return (r - b) @ m.T
        return (one(accel, self.accel_bias, self.accel_matrix, "accel"),
                one(gyro, self.gyro_bias, self.gyro_matrix, "gyro"))

    def __repr__(self):
        return (f"CalibrationResult(method={self.method!r}, "
                f"accel_scale_factor={np.array2string(self.accel_scale_factor, precision=6)}, "
                f"gyro_scale_factor={np.array2string(self.gyro_scale_factor, precision=6)})")


def calibrate_six_position(data=None, *, manifest=None, manifest_toml=None, gyro=None,
                           accel=None, time_s=None, rate_hz=None, temperature_c=None,
                           gravity_m_s2=None, g_sensitivity=False, units="si", name=None):
    """Six-position (accelerometer) + rate-table (gyro) calibration with covariances
    (IEEE Std 1293; Titterton & Weston §8.3) — ``driftless calibrate six-position LOG
    --manifest MANIFEST``.

    data: log file path, or mapping of columns (module docs); or gyro=/accel= (N, 3)
    arrays. Sample k must be at k/rate from the protocol start (the manifest's time
    base). manifest / manifest_toml: the segment manifest (file, or its TOML text; the
    ``manifest.toml`` of a simulated chamber session) naming every static position and
    rate-table segment. temperature_c: the set temperature to calibrate when the
    manifest has several. gravity_m_s2: replaces the manifest's gravity (9.7–9.9).
    g_sensitivity: also estimate the gyro g-sensitivity G. units: "si" (arrays in
    rad/s and m/s²) or "raw" (counts: the result's bias is in counts and M in SI per
    count).

    Returns a :class:`CalibrationResult`; ``details`` has ``positions`` (the up axis of
    each position), ``a_minus_g_m_s2`` (P, 3), ``rate_segments`` and ``temperature_c``.
    Raises ValueError with the library's message on bad input.
    """
    text, mname = _manifest(manifest, manifest_toml)
    log = _log(data, gyro, accel, None, time_s, rate_hz, name, units=units)
    # the six-position job reads no temperature; drop it so it need not be finite
    log.columns = [c for c in log.columns if c[1] != "temperature"]
    raw = _driftless.calib_six_position(
        log.args(), text, mname,
        None if temperature_c is None else float(temperature_c),
        None if gravity_m_s2 is None else float(gravity_m_s2), bool(g_sensitivity),
    )
    details = {
        "positions": raw["positions"],
        "a_minus_g_m_s2": raw["a_minus_g_m_s2"].reshape(-1, 3),
        "rate_segments": raw["rate_segments"],
        "temperature_c": raw["temperature_c"],
        "seconds": raw["seconds"],
    }
    return CalibrationResult(raw["file_toml"], raw["file_json"], json.loads(raw["quality_json"]),
                             raw["residuals_m_s2"], details)


def calibrate_multi_position(data=None, *, gyro=None, accel=None, time_s=None, rate_hz=None,
                             gravity_m_s2=None, lat_deg=45.0, height_m=0.0,
                             gyro_scale_guess=None, accel_offset=None, accept_poor_fit=False,
                             units="si", name=None):
    """Fixture-free multi-position calibration from hand-placed static poses (Tedaldi,
    Pretto & Menegatti, ICRA 2014) — ``driftless calibrate multi-position LOG``.

    data: log file path or mapping of columns with both triads, or gyro=/accel= (N, 3)
    arrays; time_s is required (static intervals are found in time). The log starts at
    rest, then many static orientations with rotations between. gravity_m_s2: default
    normal gravity at lat_deg/height_m. gyro_scale_guess: rad/s per raw unit within
    ±20 % (default: found from the data). accel_offset: raw accelerometer zero offset
    (default per axis the middle of the 1st and 99th percentiles). An implausible result
    raises ValueError with the reasons unless accept_poor_fit. units: "si" or "raw"
    (counts, as the imu_tk recordings).

    Returns a :class:`CalibrationResult`; ``details`` has ``before_rms_m_s2``,
    ``accel_norm_rms_m_s2``, ``gravity_angle_rms_rad``, ``threshold_multiple``,
    ``gyro_scale_estimate`` and ``accepted_poor_fit``.
    """
    log = _log(data, gyro, accel, None, time_s, rate_hz, name, units=units, accel_first=True)
    log.columns = [c for c in log.columns if c[1] != "temperature"]
    if log.path is None and log.time_s is None:
        raise ValueError("calibrate_multi_position needs time_s (static intervals are found in time)")
    raw = _driftless.calib_multi_position(
        log.args(), None if gravity_m_s2 is None else float(gravity_m_s2), float(lat_deg),
        float(height_m), None if gyro_scale_guess is None else float(gyro_scale_guess),
        None if accel_offset is None else float(accel_offset), bool(accept_poor_fit),
    )
    details = {k: raw[k] for k in ("before_rms_m_s2", "accel_norm_rms_m_s2", "gravity_angle_rms_rad",
                                   "threshold_multiple", "gyro_scale_estimate", "accepted_poor_fit",
                                   "seconds")}
    return CalibrationResult(raw["file_toml"], raw["file_json"], json.loads(raw["quality_json"]),
                             raw["residuals_m_s2"], details)


class ThermalModel(_ModelFile):
    """A thermal compensation model: the room calibration at ``t_ref_c`` (b and M per
    triad) and per axis the bias and scale-factor deltas as polynomials in
    ΔT = T − T_ref (seed paper §3.3 eqs. 1–2: cubics about 25 °C), valid over
    ``range_c`` with the ``out_of_range`` policy (clamp, extrapolate, error).

    Compensation (``compensate``) is the library's real-time kernel, per sample:
    r = raw − b − Δb(T); r_k ← r_k / (1 + Δs_k(T)); out = M·r (then the gyro
    g-sensitivity G·f with the compensated specific force, when the model has G).

    Attributes: ``accel_bias``/``gyro_bias`` (3,), ``accel_matrix``/``gyro_matrix``
    (3, 3), ``accel_bias_delta``, ``accel_scale_delta``, ``gyro_bias_delta``,
    ``gyro_scale_delta`` (3, order + 1) coefficients c₀ (= 0) … c_p of ΔT^k per axis,
    ``gyro_g_sensitivity`` (3, 3) or None, ``model_id``. From a fit also: ``method``
    (soak or ramp), ``fits`` — one dict per fitted series (soak: ``triad``,
    ``quantity`` bias/scale, ``axis``; ramp: ``channel``) with ``coefficients`` (the
    absolute polynomial c₀ … c_p of the series, e.g. the bias at T_ref in c₀),
    ``std_errors``, ``residual_rms``, ``chi2_per_dof``, ``scatter_ratio``,
    ``sigma_scale``, ``dof``, ``n_points`` (soak: also the per-step ``values`` and
    ``sigma``) — ``temperatures_c`` (soak steps) and ``warnings`` of the log checks.

    ``to_dict()`` is the model file (what ``driftless thermal soak --out`` writes),
    ``to_toml()`` its text, ``save(path)`` writes it, ``ThermalModel.load(path)``
    reads one.
    """

    _save = staticmethod(_driftless.thermal_save)
    _load = staticmethod(_driftless.thermal_load)
    _from_json = staticmethod(_driftless.thermal_from_json)

    def __init__(self, model_toml, model_json, method=None, fits=None, temperatures_c=None,
                 warnings=None):
        self._toml = model_toml
        self._dict = json.loads(model_json)
        d = self._dict
        self.model_id = d["model_id"]
        self.t_ref_c = d["t_ref_c"]
        self.range_c = tuple(d["range_c"])
        self.out_of_range = d["out_of_range"]
        self.gyro_g_sensitivity = _arr(d.get("gyro_g_sensitivity"))
        for triad in ("accel", "gyro"):
            t = d[triad]
            setattr(self, f"{triad}_raw_unit", t["raw_unit"])
            setattr(self, f"{triad}_bias", np.array(t["bias"], dtype=np.float64))
            setattr(self, f"{triad}_matrix", np.array(t["matrix"], dtype=np.float64))
            for part in ("bias_delta", "scale_delta"):
                rows = t[part]
                width = max(len(r) for r in rows)
                a = np.zeros((3, width))
                for k, r in enumerate(rows):
                    a[k, :len(r)] = r
                setattr(self, f"{triad}_{part}", a)
        self.method = method
        self.fits = fits or []
        self.temperatures_c = None if temperatures_c is None else np.asarray(temperatures_c)
        self.warnings = warnings or []

    def fit(self, triad, quantity, axis):
        """The soak fit of one series (triad accel/gyro, quantity bias/scale, axis x/y/z)."""
        for f in self.fits:
            if (f.get("triad"), f.get("quantity"), f.get("axis")) == (triad, quantity, axis):
                return f
        raise ValueError(f"no fit of {triad} {quantity} {axis}; this model has "
                         f"{[(f.get('triad'), f.get('quantity'), f.get('axis')) for f in self.fits]}")

    def compensate(self, gyro, accel, temperature_c):
        """Raw gyro and accelerometer samples ((N, 3) each, the model's raw units) at
        sensor temperature temperature_c ((N,), °C) through the real-time compensation.
        Returns (gyro_rad_s, accel_m_s2) as (N, 3) arrays. Samples outside ``range_c``
        follow ``out_of_range`` (``error``: ValueError naming the sample)."""
        g = np.ascontiguousarray(gyro, dtype=np.float64)
        a = np.ascontiguousarray(accel, dtype=np.float64)
        for arr, what in ((g, "gyro"), (a, "accel")):
            if arr.ndim != 2 or arr.shape[1] != 3:
                raise ValueError(f"{what} must have shape (N, 3), got {arr.shape}")
        t = _column(temperature_c, "temperature_c")
        if not (len(g) == len(a) == len(t)):
            raise ValueError(f"gyro, accel and temperature_c differ in length ({len(g)}, {len(a)}, {len(t)})")
        _column(g.ravel(), "gyro")
        _column(a.ravel(), "accel")
        go, ao = _driftless.thermal_compensate(self._toml, g.ravel(), a.ravel(), t)
        return go.reshape(-1, 3), ao.reshape(-1, 3)

    def __repr__(self):
        return (f"ThermalModel(method={self.method!r}, t_ref_c={self.t_ref_c}, "
                f"range_c={self.range_c}, order={self.gyro_bias_delta.shape[1] - 1}, "
                f"model_id={self.model_id:#x})")


def thermal_fit(data=None, *, manifest=None, manifest_toml=None, method=None, gyro=None,
                accel=None, temperature_c=None, time_s=None, rate_hz=None, order=3,
                t_ref_c=25.0, out_of_range="clamp", min_rise_c=10.0, bin_c=1.0, name=None):
    """Thermal calibration: bias (and, soak, scale factor) per axis as a polynomial of
    order ``order`` in ΔT = T − ``t_ref_c`` (default a cubic about 25 °C).

    method "soak" (the default when a manifest is given) — ``driftless thermal soak
    LOG --manifest M``: six-position + rate-table calibration at every set temperature of
    a chamber recording, then a weighted fit per bias and scale series. method "ramp"
    (the default without a manifest) — ``driftless thermal ramp LOG --out M``: binned
    (``bin_c`` °C) bias versus the logged temperature of a static warm-up or cool-down,
    a bias-only model (needs a temperature per sample and a time column).

    data: log file path or mapping of columns (module docs), or gyro=/accel= (N, 3) and
    temperature_c= (N,) arrays. The checks of ``driftless thermal check`` run first
    (``min_rise_c``: the rise the data must span). out_of_range: the model's policy
    outside the calibrated range. Returns a :class:`ThermalModel`.
    """
    if method is None:
        method = "ramp" if manifest is None and manifest_toml is None else "soak"
    if method not in ("soak", "ramp"):
        raise ValueError(f'method must be "soak" or "ramp", got {method!r}')
    if not (isinstance(order, numbers.Integral) and not isinstance(order, bool) and 1 <= order <= 5):
        raise ValueError(f"order must be an integer 1–5, got {order!r}")
    if not (isinstance(t_ref_c, numbers.Real) and math.isfinite(t_ref_c)):
        raise ValueError(f"t_ref_c must be a finite temperature in °C, got {t_ref_c!r}")
    log = _log(data, gyro, accel, temperature_c, time_s, rate_hz, name,
               need_temperature=(method == "ramp"))
    if method == "soak":
        text, mname = _manifest(manifest, manifest_toml)
        raw = _driftless.thermal_soak(log.args(), text, mname, int(order), float(t_ref_c),
                                      str(out_of_range), float(min_rise_c))
    else:
        if manifest is not None or manifest_toml is not None:
            raise ValueError("the ramp method takes no manifest (it bins the logged temperature)")
        if log.path is None and log.time_s is None:
            raise ValueError("the ramp method needs time_s")
        raw = _driftless.thermal_ramp(log.args(), int(order), float(t_ref_c), float(bin_c),
                                      float(min_rise_c))
    return ThermalModel(raw["model_toml"], raw["model_json"], method=raw["method"],
                        fits=list(raw["fits"]), temperatures_c=raw.get("temperatures_c"),
                        warnings=list(raw["warnings"]))


def thermal_compensate(model, gyro, accel, temperature_c):
    """``model.compensate(gyro, accel, temperature_c)``; model is a
    :class:`ThermalModel` or a model file path."""
    if not isinstance(model, ThermalModel):
        model = ThermalModel.load(model)
    return model.compensate(gyro, accel, temperature_c)


class ChamberSession:
    """A simulated thermal-chamber session: ``imu`` maps ``time_s``, ``gyro_x`` …
    ``acc_z`` (rad/s, m/s²) and ``temp`` (°C, the IMU's reading) to NumPy arrays;
    ``manifest_toml`` is the segment manifest (every soak, static position and rate
    segment with its set temperature, what ``driftless simulate`` writes as
    ``manifest.toml``); ``sensor`` the resolved sensor configuration; ``tau0_s`` the
    sample interval. Pass ``imu`` and ``manifest_toml=`` to
    :func:`calibrate_six_position` or :func:`thermal_fit`."""

    def __init__(self, raw):
        self.tau0_s = raw["tau0_s"]
        self.imu = raw["imu"]
        self.manifest_toml = raw["manifest_toml"]
        self.sensor = json.loads(raw["sensor_json"])

    def __repr__(self):
        n = len(self.imu["time_s"]) if "time_s" in self.imu else 0
        return f"ChamberSession(samples={n}, tau0_s={self.tau0_s})"


def simulate_chamber(scenario_toml, name="<scenario>", sensor=None):
    """Run a chamber scenario (TOML text of ``driftless simulate`` with
    ``[trajectory] type = "chamber"``). sensor: a sensor configuration (the
    ``[imu.sensor]`` table as a dict, e.g. ``ChamberSession.sensor`` edited) used instead
    of the scenario's preset or table. Returns a :class:`ChamberSession`."""
    sensor_json = None if sensor is None else json.dumps(sensor)
    return ChamberSession(_driftless.chamber_simulate(str(scenario_toml), str(name), sensor_json))


def sensor_preset(name):
    """A sensor preset's configuration (adi-like, adis16465-like, consumer, tactical) as
    a dict, the ``[imu.sensor]`` table of a scenario."""
    return json.loads(_driftless.sensor_preset_json(str(name)))
