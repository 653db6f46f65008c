"""Thermal calibration of a fleet of units, one pure function call per unit.

Every function here is module-level, takes and returns plain picklable values (ints,
floats, strings, dicts of NumPy arrays) and is deterministic given its arguments, so the
calls can be shipped to any number of worker processes or machines (Dask, joblib,
multiprocessing, a batch queue) and the table they give is the same as a serial run's,
float for float.

* :func:`unit_truth` — a unit's true thermal coefficients: the ``adi-like`` preset's
  bias polynomials (cubics in ΔT = T − 25 °C) with c₁ … c₃ scaled per axis by
  1 + ``spread``·N(0, 1), drawn from ``numpy.random.default_rng([seed, unit_id])``.
* :func:`simulate_unit` — the unit's chamber session (a short soak protocol at a low
  rate, :data:`DEFAULT_PROTOCOL`) simulated with those coefficients: the log's columns,
  the segment manifest and the truth.
* :func:`calibrate_unit` — the soak-method thermal fit of one unit's log
  (:func:`driftless.thermal_fit`) as one flat row: unit id, fitted coefficients per
  channel, the truth, and the fit error.
* :func:`unit_row` — both, in one call (what a worker runs per unit).
"""

import json

import numpy as np

from . import _driftless
from ._calib import thermal_fit

__all__ = ["DEFAULT_PROTOCOL", "unit_truth", "simulate_unit", "calibrate_unit", "unit_row",
           "CHANNELS"]

#: The six channels of a row, in order.
CHANNELS = ("gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z")

#: The chamber protocol of a simulated unit: the ``[trajectory]`` keys of a chamber
#: scenario (:mod:`driftless`'s ``sim::chamber``) and the IMU rate: seven set
#: temperatures −20 … 70 °C, short dwells (one unit is about 0.3 s of CPU); the sensor
#: settles in each soak (lag 5 s against 60 s: e^−12 of the step left).
DEFAULT_PROTOCOL = {
    "rate_hz": 200.0,
    "temperatures_c": [-20.0, -5.0, 10.0, 25.0, 40.0, 55.0, 70.0],
    "soak_s": 60.0,
    "position_dwell_s": 30.0,
    "move_s": 3.0,
    "rate_deg_s": 60.0,
    "rate_revolutions": 1,
    "spin_s": 1.0,
    "lag_tau_s": 5.0,
}

_PRESET = "adi-like"


def _preset_config():
    return json.loads(_driftless.sensor_preset_json(_PRESET))


def unit_truth(unit_id, seed=0, spread=0.25):
    """The true bias polynomials of unit ``unit_id``: a dict mapping each channel of
    :data:`CHANNELS` to its coefficients c₀ … c₃ of ΔT = T − 25 °C (rad/s or m/s² per
    °C^k), the preset's with c₁ … c₃ each scaled by 1 + spread·N(0, 1)."""
    if not (isinstance(unit_id, (int, np.integer)) and unit_id >= 0):
        raise ValueError(f"unit_id must be a non-negative integer, got {unit_id!r}")
    if not (isinstance(seed, (int, np.integer)) and seed >= 0):
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    rng = np.random.default_rng([int(seed), int(unit_id)])
    cfg = _preset_config()
    polys = cfg["gyro"]["bias_poly_rad_s"] + cfg["accel"]["bias_poly_m_s2"]
    truth = {}
    for ch, p in zip(CHANNELS, polys):
        c = np.zeros(4)
        c[:len(p)] = p
        c[1:] *= 1.0 + spread * rng.standard_normal(3)
        truth[ch] = c
    return truth


def _scenario(protocol, sim_seed):
    traj = "\n".join(f"{k} = {json.dumps(v)}" for k, v in protocol.items() if k != "rate_hz")
    return (f"seed = {sim_seed}\n[imu]\nrate_hz = {float(protocol['rate_hz'])!r}\n"
            f'preset = "{_PRESET}"\noutput = "rates"\n'
            f'[trajectory]\ntype = "chamber"\n{traj}\n')


def simulate_unit(unit_id, seed=0, protocol=None, spread=0.25):
    """The chamber session of unit ``unit_id``: ``{"unit_id", "imu" (columns time_s,
    gyro_x … acc_z, temp as NumPy arrays), "manifest_toml", "truth"}`` — the simulated
    log of the ``adi-like`` preset (noise, turn-on biases, scale factors, misalignment,
    g-sensitivity) with the unit's true bias polynomials (:func:`unit_truth`) over the
    protocol ``protocol`` (default :data:`DEFAULT_PROTOCOL`). The noise seed is drawn
    from the same generator, so the log is a function of (unit_id, seed)."""
    truth = unit_truth(unit_id, seed, spread)
    proto = dict(DEFAULT_PROTOCOL if protocol is None else protocol)
    cfg = _preset_config()
    cfg["gyro"]["bias_poly_rad_s"] = [truth[c].tolist() for c in CHANNELS[:3]]
    cfg["accel"]["bias_poly_m_s2"] = [truth[c].tolist() for c in CHANNELS[3:]]
    sim_seed = int(np.random.default_rng([int(seed), int(unit_id), 1]).integers(1, 2**62))
    raw = _driftless.chamber_simulate(_scenario(proto, sim_seed), f"unit-{unit_id}",
                                      json.dumps(cfg))
    return {"unit_id": int(unit_id), "imu": raw["imu"], "manifest_toml": raw["manifest_toml"],
            "truth": truth}


def _delta(c, t):
    """Σ_{k≥1} c_k·ΔT^k (the polynomial without its constant)."""
    return sum(c[k] * t ** k for k in range(1, len(c)))


def calibrate_unit(unit, order=3, t_ref_c=25.0):
    """One flat row of floats for a simulated unit (:func:`simulate_unit`): ``unit_id``,
    per channel ch ``ch_c0`` … ``ch_c3`` (the fitted bias polynomial, absolute: c₀ is
    the bias at 25 °C including the turn-on bias), ``ch_c1_se`` … (standard errors),
    ``ch_true_c1`` … ``ch_true_c3``, ``ch_err_max`` (the largest |Δb_fit(T) − Δb_true(T)|
    over the set temperatures, Δb(T) = b(T) − b(25 °C), rad/s or m/s²) and
    ``ch_swing`` (the true Δb's largest |value| there), and ``model_id``."""
    model = thermal_fit(unit["imu"], manifest_toml=unit["manifest_toml"], order=order,
                        t_ref_c=t_ref_c, name=f"unit-{unit['unit_id']}")
    temps = np.asarray(model.temperatures_c, dtype=np.float64) - t_ref_c
    row = {"unit_id": int(unit["unit_id"]), "model_id": int(model.model_id)}
    for ch in CHANNELS:
        triad = "gyro" if ch.startswith("gyro") else "accel"
        f = model.fit(triad, "bias", ch[-1])
        c, se = np.asarray(f["coefficients"]), np.asarray(f["std_errors"])
        for k in range(order + 1):
            row[f"{ch}_c{k}"] = float(c[k])
        for k in range(1, order + 1):
            row[f"{ch}_c{k}_se"] = float(se[k])
        truth = unit.get("truth", {}).get(ch)
        if truth is not None:
            for k in range(1, len(truth)):
                row[f"{ch}_true_c{k}"] = float(truth[k])
            err = _delta(c, temps) - _delta(truth, temps)
            row[f"{ch}_err_max"] = float(np.max(np.abs(err)))
            row[f"{ch}_swing"] = float(np.max(np.abs(_delta(truth, temps))))
    return row


def unit_row(unit_id, seed=0, protocol=None, order=3):
    """:func:`calibrate_unit` of :func:`simulate_unit` — the work of one unit."""
    return calibrate_unit(simulate_unit(unit_id, seed, protocol), order=order)
