"""driftless.analyse: the curve agrees with the allantools-compatible estimator, its
bounds bracket it, and the fitted noise model recovers the white noise and rate random
walk a simulated gyro was made with."""

import json
import math

import numpy as np
import pytest

import driftless

RATE_HZ = 100.0
WHITE_RAD_S = 1e-3  # per-sample σ of the white rate noise → N = σ/√fs
RRW_STEP_RAD_S = 1e-6  # per-sample step of the rate random walk → K = step·√fs


def gyro(n=200_000, seed=1):
    rng = np.random.default_rng(seed)
    return (rng.standard_normal(n) * WHITE_RAD_S
            + np.cumsum(rng.standard_normal(n)) * RRW_STEP_RAD_S + 0.01)


def test_curve_equals_the_estimator_and_bounds_bracket_it():
    y = gyro()
    for est in ["oadev", "mdev", "ohdev", "totdev"]:
        r = driftless.analyse(y, RATE_HZ, estimator=est, taus="octave", name="gx")
        cols = r.columns()
        assert set(cols) == set(driftless.AnalysisResult.COLUMNS)
        assert all(len(v) == len(r) > 10 for v in cols.values()), est
        taus, devs, _, ns = getattr(driftless, est)(y, rate=RATE_HZ, data_type="freq", taus=r.tau_s)
        assert np.array_equal(taus, r.tau_s), est
        assert np.array_equal(ns, r.n), est
        np.testing.assert_allclose(r.dev, devs, rtol=1e-12, err_msg=est)
        assert np.all(r.dev_lo < r.dev) and np.all(r.dev < r.dev_hi), est
        assert np.array_equal(r.tau_s, r.m / RATE_HZ)
        assert r.noise_model is None
        d = r.to_dict()
        assert d["name"] == "gx" and d["estimator"] == est and len(d["points"]) == len(r)
        assert d["points"][3]["dev"] == r.dev[3]


def test_noise_model_recovers_the_simulated_terms():
    r = driftless.analyse(gyro(), RATE_HZ, quantity="angular_rate", name="gyro_x")
    model = r.noise_model
    assert model is not None
    fit = model.to_dict()["channels"][0]["fit"]
    n_true = WHITE_RAD_S / math.sqrt(RATE_HZ)
    k_true = RRW_STEP_RAD_S * math.sqrt(RATE_HZ)
    white, rrw = fit["white"], fit["rate_random_walk"]
    assert abs(white["value"] / n_true - 1) < 0.02, white
    assert 0.7 < rrw["value"] / k_true < 1.3, rrw
    assert model.channels[0]["unit"] == "rad/s"
    assert "gyro_x" in model.table() and "white N" in model.table()
    assert "[[channels]]" in model.to_toml()
    json.dumps(r.to_dict())  # plain data all the way down
    assert r.to_dict()["noise_model"]["channels"][0]["name"] == "gyro_x"


def test_explicit_taus_and_other_estimators_fit_on_oadev():
    y = gyro(50_000, seed=2)
    r = driftless.analyse(y, RATE_HZ, estimator="adev", taus=[0.01, 0.1, 1.0],
                          quantity="specific_force", terms="n,k")
    assert np.array_equal(r.tau_s, [0.01, 0.1, 1.0])
    assert r.noise_model.to_dict()["estimator"] == "oadev"
    assert r.noise_model.channels[0]["unit"] == "m/s^2"


def test_bad_input_is_refused_with_the_reason():
    y = gyro(5_000)
    bad = y.copy()
    bad[42] = np.inf
    with pytest.raises(ValueError, match="sample 42 is not finite"):
        driftless.analyse(bad, RATE_HZ)
    with pytest.raises(ValueError, match="unknown quantity"):
        driftless.analyse(y, RATE_HZ, quantity="magnetic")
    with pytest.raises(ValueError, match="unknown noise term"):
        driftless.analyse(y, RATE_HZ, quantity="angular_rate", terms="n,x")
    with pytest.raises(ValueError, match="bad tau specification"):
        driftless.analyse(y, RATE_HZ, taus="log:0")
    with pytest.raises(ValueError, match="unknown estimator"):
        driftless.analyse(y, RATE_HZ, estimator="theo1")
    with pytest.raises(ValueError, match="rate must be a positive"):
        driftless.analyse(y, -1.0)
