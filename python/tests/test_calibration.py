"""driftless.calibrate_six_position / calibrate_multi_position / thermal_fit /
ThermalModel: the bindings recover a simulated sensor's true errors, give the files and
numbers of the `driftless calibrate|thermal|compensate` commands bit for bit, round-trip
their dicts and files, and refuse bad input with ValueError naming the argument."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import driftless
from calib_helpers import assert_round_trips, chamber_trajectory

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("DRIFTLESS_BIN", str(ROOT / "target" / "release" / "driftless"))
DATA = pathlib.Path(os.environ.get("DRIFTLESS_DATA", ROOT.parent / "shared" / "data"))

# A noise-free sensor with known bias b, scale-factor errors S and misalignment M
# (raw = (I + S)(I + M)·x + b), no g-sensitivity.
GYRO_B = [1e-3, -2e-3, 5e-4]
GYRO_S = [2e-3, -1e-3, 3e-3]
GYRO_M = [[0.0, 1e-3, -2e-3], [5e-4, 0.0, 1e-3], [-1e-3, 2e-3, 0.0]]
ACC_B = [0.05, -0.03, 0.08]
ACC_S = [1e-3, -2e-3, 4e-3]
ACC_M = [[0.0, -2e-3, 3e-3], [1e-3, 0.0, -4e-3], [5e-3, 2e-3, 0.0]]

def known_sensor_scenario(out_dir=None):
    col = lambda v: "[" + ", ".join(f"[{x!r}]" for x in v) + "]"  # noqa: E731
    text = f"""seed = 5
[imu]
rate_hz = 20.0
output = "rates"
[imu.sensor]
name = "known"
[imu.sensor.gyro]
bias_poly_rad_s = {col(GYRO_B)}
scale_factor_poly = {col(GYRO_S)}
misalignment_rad = {GYRO_M!r}
[imu.sensor.accel]
bias_poly_m_s2 = {col(ACC_B)}
scale_factor_poly = {col(ACC_S)}
misalignment_rad = {ACC_M!r}
""" + chamber_trajectory([25.0], 10.0)
    if out_dir is not None:
        text += f'[output]\ndir = "{out_dir}"\n'
    return text


def read_log(path):
    """The numbers of a driftless CSV log (comment lines and the header skipped):
    time, gyro x y z, acc x y z, temp per row."""
    rows = [ln for ln in pathlib.Path(path).read_text().splitlines() if not ln.startswith("#")]
    return np.array([[float(v) for v in ln.split(",")] for ln in rows[1:]])


def forward(s, m):
    return (np.eye(3) + np.diag(s)) @ (np.eye(3) + np.array(m))


@pytest.fixture(scope="module")
def known():
    return driftless.simulate_chamber(known_sensor_scenario(), "known")


def test_six_position_recovers_the_known_sensor(known):
    r = driftless.calibrate_six_position(known.imu, manifest_toml=known.manifest_toml)
    assert r.method == "six-position"
    # Noise-free data and exact (Gauss-Legendre) increments: the least squares recover
    # the forward model to rounding (measured: 1.4e-15 on A, 4e-17 on b).
    np.testing.assert_allclose(r.accel_bias, ACC_B, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r.accel_forward, forward(ACC_S, ACC_M), rtol=0, atol=1e-12)
    np.testing.assert_allclose(r.gyro_bias, GYRO_B, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r.gyro_forward, forward(GYRO_S, GYRO_M), rtol=0, atol=1e-12)
    np.testing.assert_allclose(r.accel_scale_factor, np.diag(forward(ACC_S, ACC_M)), atol=1e-12)
    np.testing.assert_allclose(np.diag(r.accel_misalignment), 0.0, atol=0)
    np.testing.assert_allclose(r.accel_matrix @ r.accel_forward, np.eye(3), atol=1e-12)
    assert r.details["positions"] == ["-z", "+z", "+x", "-x", "+y", "-y"]
    assert r.details["a_minus_g_m_s2"].shape == (6, 3)
    assert np.max(np.abs(r.residuals_m_s2)) < 1e-11
    assert set(r.quality) == {"accel", "gyro"}
    # the calibration applied to the raw position means gives g along the up axis
    a, _ = r.apply(accel=np.array([[0.0, 0.0, 0.0]]) + r.accel_bias)
    np.testing.assert_allclose(a, 0.0, atol=1e-15)


def test_arrays_and_columns_give_the_same_result(known):
    by_map = driftless.calibrate_six_position(known.imu, manifest_toml=known.manifest_toml)
    g = np.column_stack([known.imu[c] for c in ("gyro_x", "gyro_y", "gyro_z")])
    a = np.column_stack([known.imu[c] for c in ("acc_x", "acc_y", "acc_z")])
    by_arrays = driftless.calibrate_six_position(
        gyro=g, accel=a, rate_hz=1.0 / known.tau0_s, manifest_toml=known.manifest_toml)
    assert by_arrays.to_dict()["accel"] == by_map.to_dict()["accel"]
    assert by_arrays.to_dict()["gyro"] == by_map.to_dict()["gyro"]


def test_calibration_dict_file_and_pickle_round_trip(known, tmp_path):
    r = driftless.calibrate_six_position(known.imu, manifest_toml=known.manifest_toml,
                                         g_sensitivity=True)
    assert r.to_dict()["gyro_g_sensitivity"] is not None
    loaded, again = assert_round_trips(r, tmp_path / "cal.toml")
    np.testing.assert_array_equal(loaded.gyro_g_sensitivity, r.gyro_g_sensitivity)
    np.testing.assert_array_equal(again.accel_matrix, r.accel_matrix)


def test_calibrate_and_thermal_match_the_cli(tmp_path):
    """The same log file through the CLI and the binding: the same model files, text for
    text (the source line names the inputs the same way), and the same compensation."""
    out = tmp_path / "sim"
    scen = tmp_path / "scenario.toml"
    text = known_sensor_scenario(out).replace(
        "temperatures_c = [25.0]", "temperatures_c = [-5.0, 10.0, 25.0, 40.0, 55.0]")
    text = text.replace("bias_poly_rad_s = [[0.001]", "bias_poly_rad_s = [[0.001, 2e-5, -3e-7]")
    scen.write_text(text)
    subprocess.run([BIN, "simulate", str(scen)], check=True, stdout=subprocess.DEVNULL)
    log, manifest = out / "imu.csv", out / "manifest.toml"
    cal_cli = tmp_path / "cal.toml"
    subprocess.run([BIN, "calibrate", "six-position", str(log), "--manifest", str(manifest),
                    "--temperature-c", "25", "--out", str(cal_cli)],
                   check=True, stdout=subprocess.DEVNULL)
    r = driftless.calibrate_six_position(str(log), manifest=str(manifest), temperature_c=25.0)
    assert r.to_toml() == cal_cli.read_text()

    model_cli = tmp_path / "model.toml"
    subprocess.run([BIN, "thermal", "soak", str(log), "--manifest", str(manifest),
                    "--min-rise", "10", "--out", str(model_cli)],
                   check=True, stdout=subprocess.DEVNULL)
    m = driftless.thermal_fit(str(log), manifest=str(manifest))
    assert m.to_toml() == model_cli.read_text()

    comp_cli = tmp_path / "comp.csv"
    subprocess.run([BIN, "compensate", str(log), "--model", str(model_cli), "--out",
                    str(comp_cli)], check=True, stdout=subprocess.DEVNULL)
    raw, cli = read_log(log), read_log(comp_cli)
    g, a, temp = raw[:, 1:4], raw[:, 4:7], raw[:, 7]
    gc, ac = m.compensate(g, a, temp)
    np.testing.assert_array_equal(gc, cli[:, 1:4])
    np.testing.assert_array_equal(ac, cli[:, 4:7])
    gc2, ac2 = driftless.thermal_compensate(str(model_cli), g, a, temp)
    np.testing.assert_array_equal(gc2, gc)
    np.testing.assert_array_equal(ac2, ac)


def test_multi_position_on_the_imu_tk_recording_matches_the_cli():
    d = DATA / "calib" / "imu_tk_xsens"
    acc_f, gyr_f = d / "xsens_acc.txt", d / "xsens_gyro.txt"
    assert acc_f.is_file(), f"shared data missing: {acc_f}"
    acc, gyr = np.loadtxt(acc_f), np.loadtxt(gyr_f)
    r = driftless.calibrate_multi_position(
        accel=acc[:, 1:4], gyro=gyr[:, 1:4], time_s=acc[:, 0], units="raw",
        gravity_m_s2=9.81744, gyro_scale_guess=1.598e-4)
    out = subprocess.run([BIN, "calibrate", "multi-position", "--json", "--gravity", "9.81744",
                          "--gyro-scale-guess", "1.598e-4", str(acc_f), str(gyr_f)],
                         check=True, capture_output=True, text=True).stdout
    cli = json.loads(out)
    assert r.to_dict()["accel"]["matrix"] == cli["accel"]["matrix"]
    assert r.to_dict()["gyro"]["bias"] == cli["gyro"]["bias"]
    assert r.accel_raw_unit == "raw"
    assert len(r.static_intervals) == len(cli["static_intervals"])
    # imu_tk's figures (match or beat): RMS |a| − g 0.00112 m/s², gravity angle 0.52°
    assert r.accel_residual_rms <= 0.00112
    assert np.degrees(r.gyro_residual_rms) <= 0.52
    assert r.details["gyro_scale_estimate"] is None
    with pytest.raises(ValueError, match=r"(?s)implausible.*off by \d+\.\d+° RMS \(limit 3\.0°\).*accept_poor_fit=True"):
        driftless.calibrate_multi_position(
            accel=acc[:, 1:4], gyro=gyr[:, 1:4], time_s=acc[:, 0], units="raw",
            gravity_m_s2=9.81744, gyro_scale_guess=1.0)


def test_bad_input_is_a_value_error_naming_it(known):
    m = known.manifest_toml
    g = np.zeros((100, 3))
    with pytest.raises(ValueError, match=r"gyro must have shape \(N, 3\)"):
        driftless.calibrate_six_position(gyro=np.zeros((100, 2)), accel=g, rate_hz=20.0,
                                         manifest_toml=m)
    bad = dict(known.imu)
    bad["acc_y"] = bad["acc_y"].copy()
    bad["acc_y"][7] = np.nan
    with pytest.raises(ValueError, match="acc_y: sample 7 is nan"):
        driftless.calibrate_six_position(bad, manifest_toml=m)
    short = dict(known.imu)
    short["gyro_z"] = short["gyro_z"][:-1]
    with pytest.raises(ValueError, match="gyro_z has"):
        driftless.calibrate_six_position(short, manifest_toml=m)
    with pytest.raises(ValueError, match="manifest"):
        driftless.calibrate_six_position(known.imu)
    with pytest.raises(ValueError, match="lacks the columns"):
        driftless.calibrate_six_position({"gyro_x": [1.0]}, manifest_toml=m)
    # the library's own message: the log's rate is not the manifest's
    with pytest.raises(ValueError, match="sampled at 40"):
        driftless.calibrate_six_position(known.imu, manifest_toml=m, rate_hz=40.0)
    with pytest.raises(ValueError, match="temperature_c = 30"):
        driftless.calibrate_six_position(known.imu, manifest_toml=m, temperature_c=30.0)
    with pytest.raises(ValueError, match="gravity_m_s2 = 3"):
        driftless.calibrate_six_position(known.imu, manifest_toml=m, gravity_m_s2=3.0)
    with pytest.raises(ValueError, match="no such file|No such file"):
        driftless.calibrate_six_position("/nonexistent/imu.csv", manifest_toml=m)
    with pytest.raises(ValueError, match="out_of_range"):
        driftless.thermal_fit(known.imu, manifest_toml=m, out_of_range="hold")
    with pytest.raises(ValueError, match="order must be"):
        driftless.thermal_fit(known.imu, manifest_toml=m, order=9)
    with pytest.raises(ValueError, match="needs temperature_c"):
        driftless.thermal_fit(gyro=g, accel=g, time_s=np.arange(100.0))
    with pytest.raises(ValueError, match="time_s must increase"):
        driftless.calibrate_multi_position(gyro=g, accel=g, time_s=np.zeros(100))
