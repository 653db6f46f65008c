"""``driftless.navigate``: GNSS/INS navigation (the loosely coupled error-state Kalman
filter and its Rauch–Tung–Striebel smoother) on NumPy columns or files.

The same library calls as ``driftless nav``: the configuration is the one
``driftless nav --config nav.toml`` reads (``driftless nav --print-config`` prints every
key with its meaning), given here as a dict of its sections, or the path of such a TOML
file, or the path of a KF-GINS YAML configuration (``driftless nav --kf-gins``).
"""

import json
import math
import os

import numpy as np

from . import _driftless

__all__ = ["navigate", "NavResult", "Solution", "default_nav_config"]

#: IMU columns ``navigate`` reads from a mapping: GPS seconds of week, angular rate of the
#: body (rad/s) and specific force (m/s^2) along the body x, y, z axes — the names
#: ``simulate()`` returns.
IMU_COLUMNS = ("time_s", "gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z")
#: GNSS columns: GPS seconds of week, geodetic latitude and longitude (rad), ellipsoidal
#: height (m), and the position σ north, east, down (m).
GNSS_COLUMNS = ("time_s", "lat_rad", "lon_rad", "height_m", "sigma_n_m", "sigma_e_m", "sigma_d_m")
#: Optional GNSS velocity north, east, down (m/s) and its σ; used when all six are given.
GNSS_VELOCITY_COLUMNS = ("vel_n_m_s", "vel_e_m_s", "vel_d_m_s",
                         "sigma_vel_n_m_s", "sigma_vel_e_m_s", "sigma_vel_d_m_s")


def default_nav_config():
    """The default navigation configuration as a dict of sections (``imu``, ``gnss``,
    ``noise``, ``align``, ``aids``, ``filter``, ``outages``): every key ``navigate``'s
    ``config`` dict may set, with its default value."""
    return json.loads(_driftless.nav_default_config())


class Solution:
    """One navigation solution, one entry per IMU epoch; every attribute is a NumPy
    column of that length:

    * ``time_s`` (GPS s), ``lat_rad``, ``lon_rad``, ``height_m`` (IMU centre, WGS-84);
    * ``vel_n_m_s``, ``vel_e_m_s``, ``vel_d_m_s`` (NED);
    * ``roll_rad``, ``pitch_rad``, ``yaw_rad`` (body FRD to NED, z-y-x Euler angles,
      yaw in (−π, π]);
    * the estimated sensor errors ``gyro_bias_{x,y,z}_rad_s``,
      ``accel_bias_{x,y,z}_m_s2``, ``gyro_scale_{x,y,z}``, ``accel_scale_{x,y,z}``;
    * the filter's (or smoother's) standard deviations ``sigma_{n,e,d}_m``,
      ``sigma_vel_{n,e,d}_m_s``, ``sigma_att_{n,e,d}_rad`` (attitude error about the
      NED axes), ``sigma_gyro_bias_{x,y,z}_rad_s``, ``sigma_accel_bias_{x,y,z}_m_s2``,
      ``sigma_gyro_scale_{x,y,z}``, ``sigma_accel_scale_{x,y,z}``.

    ``columns()`` is a dict ``pandas.DataFrame`` takes as it is; ``to_dict()`` the same
    as plain lists."""

    def __init__(self, columns):
        self._columns = dict(columns)
        for key, value in self._columns.items():
            setattr(self, key, value)

    def columns(self):
        """Every column as a dict of NumPy arrays (a copy of the dict, not of the data)."""
        return dict(self._columns)

    def to_dict(self):
        """Every column as a plain list (JSON-serialisable)."""
        return {k: v.tolist() for k, v in self._columns.items()}

    def horizontal_rms_m(self, reference, *, from_s=None, max_reference_gap_s=2.0):
        """Horizontal RMS error (m) against ``reference`` over the epochs at or after
        ``from_s`` (default: all) where the reference can be interpolated linearly (gaps
        of at most ``max_reference_gap_s``): √(Σ e² / n), e the horizontal distance
        between the positions. ``reference``: a mapping with ``time_s``, ``lat_rad``,
        ``lon_rad``, ``height_m`` (e.g. ``Simulation.truth``), or another ``Solution``."""
        ref = reference.columns() if isinstance(reference, Solution) else reference
        cols = _columns(ref, ("time_s", "lat_rad", "lon_rad", "height_m"), "reference")
        mine = [self._columns[k] for k in ("time_s", "lat_rad", "lon_rad", "height_m")]
        start = -math.inf if from_s is None else float(from_s)
        rms, _ = _driftless.horizontal_rms(cols, mine, start, float(max_reference_gap_s))
        return rms

    def __len__(self):
        return len(self.time_s)

    def __repr__(self):
        if len(self) == 0:
            return "Solution(epochs=0)"
        return f"Solution(epochs={len(self)}, time_s={self.time_s[0]:.3f}…{self.time_s[-1]:.3f})"


class NavResult:
    """What ``navigate`` returns.

    * ``forward``: the real-time (forward filter) ``Solution``;
    * ``smoothed``: the RTS-smoothed ``Solution`` (``None`` with ``smooth=False``);
    * ``gnss_accepted``, ``gnss_rejected``, ``gnss_withheld`` (inside outage windows),
      ``gnss_fixes`` (inside the IMU span), ``start_time_s`` (the filter's first epoch);
    * ``prediction_rms_m``: RMS horizontal one-step prediction error at the accepted
      fixes after convergence (what ``driftless nav`` prints as the full-GNSS accuracy;
      ``None`` for a KF-GINS job);
    * ``outages``: per simulated outage window a dict with ``start_s``, ``end_s``,
      ``end_horizontal_m`` (forward error at the first fix after it), ``max_horizontal_m``;
    * ``config``: the configuration in effect as a dict (``navigate(…, config=r.config)``
      repeats the run); ``None`` for a KF-GINS job;
    * ``notes``: what the readers and the job noted; ``files``: outputs a KF-GINS job
      wrote.

    ``horizontal_rms_m(reference)`` is the forward solution's horizontal RMS error
    against a reference (``smoothed=True`` for the smoothed one)."""

    def __init__(self, raw):
        self.forward = Solution(raw["forward"])
        self.smoothed = Solution(raw["smoothed"]) if "smoothed" in raw else None
        self.gnss_accepted = raw["gnss_accepted"]
        self.gnss_rejected = raw["gnss_rejected"]
        self.gnss_withheld = raw["gnss_withheld"]
        self.gnss_fixes = raw["gnss_fixes"]
        self.start_time_s = raw["start_time_s"]
        self.prediction_rms_m = raw.get("prediction_rms_m")
        self.outages = [
            {"start_s": s, "end_s": e, "end_horizontal_m": end, "max_horizontal_m": mx}
            for (s, e, end, mx) in raw.get("outages", [])
        ]
        self.config = json.loads(raw["config_json"]) if "config_json" in raw else None
        self.notes = list(raw.get("notes", []))
        self.files = list(raw.get("files", []))

    def horizontal_rms_m(self, reference, *, smoothed=False, from_s=None, max_reference_gap_s=2.0):
        """``Solution.horizontal_rms_m`` of the forward (or, ``smoothed=True``, the
        smoothed) solution."""
        sol = self.smoothed if smoothed else self.forward
        if sol is None:
            raise ValueError("no smoothed solution: call navigate with smooth=True")
        return sol.horizontal_rms_m(reference, from_s=from_s, max_reference_gap_s=max_reference_gap_s)

    def to_dict(self):
        """Plain Python lists and dicts (JSON-serialisable)."""
        return {
            "forward": self.forward.to_dict(),
            "smoothed": None if self.smoothed is None else self.smoothed.to_dict(),
            "gnss_accepted": self.gnss_accepted,
            "gnss_rejected": self.gnss_rejected,
            "gnss_withheld": self.gnss_withheld,
            "gnss_fixes": self.gnss_fixes,
            "start_time_s": self.start_time_s,
            "prediction_rms_m": self.prediction_rms_m,
            "outages": [dict(o) for o in self.outages],
            "config": self.config,
            "notes": list(self.notes),
            "files": list(self.files),
        }

    def __repr__(self):
        return (f"NavResult(epochs={len(self.forward)}, smoothed={self.smoothed is not None}, "
                f"gnss_accepted={self.gnss_accepted}, gnss_rejected={self.gnss_rejected}, "
                f"outages={len(self.outages)})")


def _is_path(x):
    return isinstance(x, (str, bytes, os.PathLike))


def _columns(mapping, names, what):
    """The named columns of ``mapping`` as contiguous float64 arrays of one length, every
    value finite; errors name the column."""
    try:
        keys = list(mapping.keys())
    except AttributeError:
        raise ValueError(f"{what} must be a mapping of column name to array or a file path, "
                         f"got {type(mapping).__name__}") from None
    out = []
    n = None
    for name in names:
        if name not in mapping:
            raise ValueError(f"{what}: no column {name!r} (has {sorted(map(str, keys))}; "
                             f"needs {list(names)})")
        col = np.ascontiguousarray(mapping[name], dtype=np.float64)
        if col.ndim != 1:
            raise ValueError(f"{what}[{name!r}] must be one-dimensional, got shape {col.shape}")
        if n is None:
            n = len(col)
        elif len(col) != n:
            raise ValueError(f"{what}[{name!r}] has {len(col)} values but {what}[{names[0]!r}] "
                             f"has {n}: every column needs one value per epoch")
        bad = np.flatnonzero(~np.isfinite(col))
        if len(bad):
            raise ValueError(f"{what}[{name!r}][{bad[0]}] is {col[bad[0]]} ({len(bad)} non-finite "
                             f"values): every value must be finite")
        out.append(col)
    return out


def _config_args(config):
    """(JSON text, path) of a ``config`` argument; unknown keys refused here, naming them."""
    if config is None:
        return None, None
    if _is_path(config):
        return None, os.fsdecode(config)
    if not hasattr(config, "items"):
        raise ValueError(f"config must be a dict, a nav TOML path or a KF-GINS YAML path, "
                         f"got {type(config).__name__}")
    defaults = default_nav_config()
    for section, values in config.items():
        if section not in defaults:
            raise ValueError(f"config: unknown section {section!r}; sections: {sorted(defaults)}")
        if not hasattr(values, "items"):
            raise ValueError(f"config[{section!r}] must be a dict of keys, got {type(values).__name__}")
        for key in values:
            if key not in defaults[section]:
                raise ValueError(f"config: unknown key {section}.{key!r}; keys of [{section}]: "
                                 f"{sorted(defaults[section])}")
    # None = not set (the default applies), as an absent key.
    config = {section: {k: v for k, v in values.items() if v is not None}
              for section, values in config.items()}
    try:
        text = json.dumps(config, allow_nan=False, default=_plain)
    except ValueError as e:
        raise ValueError(f"config: {e}") from None
    return text, None


def _plain(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, os.PathLike):
        return os.fspath(x)
    raise TypeError(f"config value {x!r} of type {type(x).__name__} is not a number, text, "
                    "flag or list")


def _kf_gins_path(config):
    return _is_path(config) and os.fsdecode(config).lower().endswith((".yaml", ".yml"))


def navigate(imu=None, gnss=None, config=None, *, smooth=True, outages=None, gate=None):
    """Run the GNSS/INS filter (and, with ``smooth``, the RTS smoother) and return a
    ``NavResult``.

    imu: a mapping of NumPy columns ``time_s`` (GPS s), ``gyro_x``, ``gyro_y``,
    ``gyro_z`` (rad/s), ``acc_x``, ``acc_y``, ``acc_z`` (m/s^2) — ``Simulation.imu`` is
    one — or the path of an IMU file ``driftless nav`` reads (KF-GINS increments, a rates
    CSV whose first column is the time, RTKLIB-tagged CSV).

    gnss: a mapping of columns ``time_s``, ``lat_rad``, ``lon_rad``, ``height_m``,
    ``sigma_n_m``, ``sigma_e_m``, ``sigma_d_m`` and optionally ``vel_n_m_s``,
    ``vel_e_m_s``, ``vel_d_m_s`` with ``sigma_vel_n_m_s``, ``sigma_vel_e_m_s``,
    ``sigma_vel_d_m_s`` (``Simulation.gnss`` is one), or the path of a GNSS file (KF-GINS
    text or RTKLIB ``.pos``). Give both as mappings or both as paths.

    config: ``None`` (the defaults), a dict of sections as ``default_nav_config()``
    returns (any subset; an unknown key is a ``ValueError`` naming it), the path of a
    ``driftless nav --config`` TOML file, or the path of a KF-GINS YAML configuration
    (``.yaml``/``.yml``; imu and gnss are then None: the YAML names its files, and the
    job writes KF-GINS's output files to its ``outputpath``, as ``driftless nav --kf-gins``
    does). With a dict or TOML file, simulated GNSS outages are ``outages.spec`` and the
    smoother runs when ``smooth`` is true (``filter.smooth`` adds the smoothed errors
    inside the outages).

    outages, gate: for a KF-GINS YAML only — the outage specification (``driftless nav
    --outages`` grammar, default none) and the innovation gate (default off, as KF-GINS).

    Errors (bad configuration, columns of different lengths, non-finite values, too few
    fixes, a diverging filter) raise ``ValueError`` with the library's message. The GIL
    is released while the filter runs.
    """
    if _kf_gins_path(config):
        if imu is not None or gnss is not None:
            raise ValueError("a KF-GINS configuration names its own IMU and GNSS files "
                             "(imupath, gnsspath): pass imu=None and gnss=None")
        raw = _driftless.navigate_kf_gins(os.fsdecode(config), outages or "none", gate, bool(smooth))
        return NavResult(raw)
    if outages is not None or gate is not None:
        raise ValueError("outages and gate are arguments of a KF-GINS job; with a dict or TOML "
                         "configuration set config['outages']['spec'] and config['filter']['gate']")
    config_json, config_path = _config_args(config)
    if _is_path(imu) and _is_path(gnss):
        raw = _driftless.navigate_files(config_json, config_path, os.fsdecode(imu),
                                        os.fsdecode(gnss), bool(smooth))
        return NavResult(raw)
    if imu is None and gnss is None:
        raise ValueError("navigate needs imu and gnss (mappings of columns or file paths), "
                         "or a KF-GINS YAML as config")
    if _is_path(imu) or _is_path(gnss) or imu is None or gnss is None:
        raise ValueError("give imu and gnss both as mappings of columns or both as file paths")
    imu_cols = _columns(imu, IMU_COLUMNS, "imu")
    gnss_cols = _columns(gnss, GNSS_COLUMNS, "gnss")
    velocity = None
    present = [k for k in GNSS_VELOCITY_COLUMNS if k in gnss]
    if present:
        if len(present) != len(GNSS_VELOCITY_COLUMNS):
            missing = [k for k in GNSS_VELOCITY_COLUMNS if k not in gnss]
            raise ValueError(f"gnss: velocity columns {present} given without {missing}: give "
                             "all six or none")
        velocity = _columns(gnss, GNSS_VELOCITY_COLUMNS, "gnss")
        if len(velocity[0]) != len(gnss_cols[0]):
            raise ValueError(f"gnss['vel_n_m_s'] has {len(velocity[0])} values but "
                             f"gnss['time_s'] has {len(gnss_cols[0])}")
    raw = _driftless.navigate_arrays(config_json, config_path, imu_cols, gnss_cols, velocity,
                                     bool(smooth))
    return NavResult(raw)
