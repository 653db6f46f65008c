"""driftless.simulate on a scenario text: the seed decides the noise, the record has the
asked length and rate, the gyro's white noise shows in its Allan deviation at the
configured density, and a bad scenario is refused with where and why."""

import math

import numpy as np
import pytest

import driftless

SCENARIO = """
seed = {seed}
[imu]
rate_hz = 100.0
preset = "adis16465-like"
output = "rates"
errors = "noise"
[trajectory]
type = "static"
lat_deg = 30.5
duration_s = 600.0
"""


def test_static_scenario_has_the_length_and_is_reproducible():
    a = driftless.simulate(SCENARIO.format(seed=3))
    b = driftless.simulate(SCENARIO.format(seed=3))
    c = driftless.simulate(SCENARIO.format(seed=4))
    assert a.tau0_s == pytest.approx(0.01)
    gyro = [k for k in a.imu if k.startswith("gyro")]
    assert len(gyro) == 3, sorted(a.imu)
    n = len(a.imu[gyro[0]])
    assert abs(n - 60_000) <= 1, n
    assert all(len(v) == n for v in a.imu.values())
    for k in a.imu:
        assert np.array_equal(a.imu[k], b.imu[k]), k
    assert not np.array_equal(a.imu[gyro[0]], c.imu[gyro[0]])
    assert a.gnss is None
    assert isinstance(a.sensor, dict) and a.sensor
    assert a.to_dict()["imu"][gyro[0]][:5] == list(a.imu[gyro[0]][:5])


def test_bad_scenario_names_the_problem():
    with pytest.raises(ValueError, match="bad.toml"):
        driftless.simulate(SCENARIO.format(seed=1).replace("rate_hz", "rate_hzz"), name="bad.toml")


def test_simulated_gyro_white_noise_is_what_the_analysis_finds():
    sim = driftless.simulate(SCENARIO.format(seed=7))
    white_true = sim.sensor["gyro"]["noise"][0]["white"]
    r = driftless.analyse(sim.imu["gyro_x"], 1.0 / sim.tau0_s, quantity="angular_rate", name="gyro_x")
    white = r.noise_model.to_dict()["channels"][0]["fit"]["white"]
    assert abs(white["value"] / white_true - 1) < 0.05, (white, white_true)
    # OADEV at τ0 of white rate noise is N/√τ0.
    assert r.dev[0] == pytest.approx(white_true / math.sqrt(sim.tau0_s), rel=0.05)
