"""driftless.navigate on a simulated drive (examples/scenarios/city-drive.toml without its
GNSS outages: a 3.5-min urban drive, consumer-grade IMU at 100 Hz, 1-Hz RTK-grade fixes
with 2 cm horizontal σ and velocity):

* the forward filter follows the truth to within a bound derived from the GNSS σ, and
  the smoother does at least as well;
* a dict configuration round-trips through ``NavResult.config``;
* bad configuration keys, columns of different lengths and non-finite values are
  refused with a ValueError naming them;
* on the same files, ``navigate`` equals ``driftless nav`` (JSON summary to 1e-9, the
  CSV solution to its printed digits), and navigating the arrays read from those files
  equals navigating the files;
* a KF-GINS YAML (written by ``driftless simulate --write kfgins``) runs as
  ``driftless nav --kf-gins`` runs it.
"""

import json
import math
import os
import pathlib
import subprocess

import numpy as np
import pytest

import driftless

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("DRIFTLESS_BIN", str(ROOT / "target" / "release" / "driftless"))
SCENARIO = (ROOT / "examples" / "scenarios" / "city-drive.toml").read_text()
# Full GNSS: the outages are set in the navigation configuration, not in the data.
SCENARIO_FULL_GNSS = "\n".join(l for l in SCENARIO.splitlines() if not l.startswith("outages"))


@pytest.fixture(scope="module")
def sim():
    return driftless.simulate(SCENARIO_FULL_GNSS, name="city-drive.toml")


def config_for(sim):
    return {"gnss": {"lever_arm_m": list(sim.lever_arm_b_m)}}


@pytest.fixture(scope="module")
def result(sim):
    return driftless.navigate(sim.imu, sim.gnss, config_for(sim))


def test_full_gnss_solution_follows_the_truth(sim, result):
    # Bound: after 60 s of convergence the position is observed every Δt = 1 s with
    # σ_h = 2 cm per axis; between fixes the error grows by ½·δf·Δt² for a residual
    # specific-force error δf (a consumer accelerometer's bias is estimated to well under
    # 0.05 m/s² here: 2.5 cm), plus the lever-arm error from a residual attitude error
    # (0.5° × 1.3 m ≈ 1.1 cm). √(2·(2 cm)² + (2.5 cm)² + (1.1 cm)²) ≈ 4 cm; the bound
    # is 2.5 × that, so a lever-arm sign error (2.6 m), a missing velocity update or a
    # time-tag slip of one IMU sample at 15 m/s (15 cm) fails it.
    t0 = result.start_time_s + 60.0
    forward = result.horizontal_rms_m(sim.truth, from_s=t0)
    smoothed = result.horizontal_rms_m(sim.truth, smoothed=True, from_s=t0)
    print(f"horizontal RMS vs truth: forward {forward:.4f} m, smoothed {smoothed:.4f} m")
    assert forward < 0.10, forward
    assert smoothed <= forward * 1.05, (smoothed, forward)
    assert result.gnss_rejected == 0 and result.gnss_accepted > 150
    n = len(result.forward)
    cols = result.forward.columns()
    for key in ("time_s", "lat_rad", "lon_rad", "height_m", "vel_n_m_s", "yaw_rad",
                "sigma_n_m", "sigma_vel_d_m_s", "gyro_bias_z_rad_s", "sigma_accel_scale_x"):
        assert len(cols[key]) == n, key
    assert len(result.smoothed) == n
    assert np.array_equal(result.smoothed.time_s, result.forward.time_s)
    # The reported σ covers the error: the north error is mostly inside 3σ.
    truth_lat = np.interp(result.forward.time_s, sim.truth["time_s"], sim.truth["lat_rad"])
    late = result.forward.time_s >= t0
    north_m = (result.forward.lat_rad - truth_lat)[late] * 6.37e6
    inside = np.mean(np.abs(north_m) <= 3 * result.forward.sigma_n_m[late] + 0.02)
    assert inside > 0.95, inside
    json.dumps(result.to_dict())


def test_dict_config_round_trips(sim, result):
    cfg = result.config
    defaults = driftless.default_nav_config()
    assert set(cfg) == set(defaults)
    assert cfg["gnss"]["lever_arm_m"] == list(sim.lever_arm_b_m)
    assert cfg["filter"] == defaults["filter"]
    again = driftless.navigate(sim.imu, sim.gnss, cfg, smooth=False)
    assert again.config == cfg
    assert again.smoothed is None
    for key, col in result.forward.columns().items():
        assert np.array_equal(again.forward.columns()[key], col), key


def test_bad_configuration_and_columns_are_refused_by_name(sim):
    with pytest.raises(ValueError, match=r"filter\.'smoth'"):
        driftless.navigate(sim.imu, sim.gnss, {"filter": {"smoth": True}})
    with pytest.raises(ValueError, match="unknown section 'filtre'"):
        driftless.navigate(sim.imu, sim.gnss, {"filtre": {}})
    with pytest.raises(ValueError, match="lever_arm_m|sequence|array"):
        driftless.navigate(sim.imu, sim.gnss, {"gnss": {"lever_arm_m": "up"}})
    short = dict(sim.imu, gyro_y=sim.imu["gyro_y"][:-1])
    with pytest.raises(ValueError, match=r"imu\['gyro_y'\] has \d+ values"):
        driftless.navigate(short, sim.gnss)
    bad = dict(sim.imu, acc_z=sim.imu["acc_z"].copy())
    bad["acc_z"][1234] = np.nan
    with pytest.raises(ValueError, match=r"imu\['acc_z'\]\[1234\] is nan"):
        driftless.navigate(bad, sim.gnss)
    no_sigma = {k: v for k, v in sim.gnss.items() if k != "sigma_e_m"}
    with pytest.raises(ValueError, match="no column 'sigma_e_m'"):
        driftless.navigate(sim.imu, no_sigma)
    with pytest.raises(ValueError, match="both as mappings"):
        driftless.navigate(sim.imu, "gnss.txt")
    # The library's own checks come through as ValueError too.
    backwards = dict(sim.gnss, time_s=sim.gnss["time_s"][::-1].copy())
    with pytest.raises(ValueError, match="GNSS fixes: time does not increase at row 1"):
        driftless.navigate(sim.imu, backwards)


def _read_imu_csv(path):
    with open(path) as f:
        lines = [l for l in f if not l.startswith("#")]
    header = [h.split(" [")[0] for h in lines[0].strip().split(",")]
    data = np.loadtxt(lines[1:], delimiter=",")
    cols = {("time_s" if h == "time" else h): data[:, i] for i, h in enumerate(header)}
    return cols


@pytest.fixture(scope="module")
def sim_files(tmp_path_factory):
    out = tmp_path_factory.mktemp("sim")
    scenario = out / "city-drive.toml"
    scenario.write_text(SCENARIO_FULL_GNSS)
    subprocess.run([BIN, "simulate", str(scenario), "--out", str(out / "data"), "--quiet",
                    "--write", "csv,kfgins"], check=True, stdout=subprocess.DEVNULL)
    return out / "data"


def test_equals_the_cli_on_the_same_files(sim_files, sim, tmp_path):
    nav_toml = tmp_path / "nav.toml"
    lever = ", ".join(repr(float(x)) for x in sim.lever_arm_b_m)
    nav_toml.write_text(f'[gnss]\nlever_arm_m = [{lever}]\n[outages]\nspec = "100+30"\n')
    imu, gnss = sim_files / "imu.csv", sim_files / "gnss.txt"
    csv_out = tmp_path / "cli.csv"
    cli = subprocess.run(
        [BIN, "nav", "--imu", str(imu), "--gnss", str(gnss), "--config", str(nav_toml),
         "--json", "--quiet", "--csv", str(csv_out)],
        check=True, capture_output=True, text=True)
    doc = json.loads(cli.stdout)
    py = driftless.navigate(imu, gnss, nav_toml, smooth=False)
    assert py.gnss_accepted == doc["gnss_accepted"]
    assert py.gnss_rejected == doc["gnss_rejected"]
    assert py.gnss_withheld == doc["gnss_withheld"] > 0
    assert py.start_time_s == doc["start_time_s"]
    assert math.isclose(py.prediction_rms_m, doc["horizontal_rms_m"], rel_tol=1e-9, abs_tol=0.0)
    assert len(py.outages) == len(doc["outages"]) == 1
    assert math.isclose(py.outages[0]["end_horizontal_m"], doc["outages"][0]["end_horizontal_m"],
                        rel_tol=1e-9)
    # The CLI's CSV: the forward solution at its printed digits (lat/lon 1e-9 deg, height
    # and velocity 1e-4, angles 1e-5 deg); half a unit of the last digit apart at most.
    table = np.loadtxt(csv_out, delimiter=",", skiprows=1)
    f = py.forward
    assert table.shape[0] == len(f)
    for col, mine, half in [
            (1, np.degrees(f.lat_rad), 0.5e-9), (2, np.degrees(f.lon_rad), 0.5e-9),
            (3, f.height_m, 0.5e-4), (4, f.vel_n_m_s, 0.5e-4), (6, f.vel_d_m_s, 0.5e-4),
            (7, np.degrees(f.roll_rad), 0.5e-5)]:
        assert np.max(np.abs(table[:, col] - mine)) <= half * (1 + 1e-6), col
    # The arrays read from the same files give the same solution.
    cols = _read_imu_csv(imu)
    g = np.loadtxt(gnss)
    fixes = {"time_s": g[:, 0], "lat_rad": np.radians(g[:, 1]), "lon_rad": np.radians(g[:, 2]),
             "height_m": g[:, 3], "sigma_n_m": g[:, 4], "sigma_e_m": g[:, 5], "sigma_d_m": g[:, 6]}
    arrays = driftless.navigate(cols, fixes, nav_toml, smooth=False)
    assert arrays.gnss_accepted == py.gnss_accepted
    assert math.isclose(arrays.prediction_rms_m, py.prediction_rms_m, rel_tol=1e-9)
    for key in ("lat_rad", "lon_rad"):
        assert np.max(np.abs(arrays.forward.columns()[key] - f.columns()[key])) < 1e-9 / 6.4e6
    assert np.max(np.abs(arrays.forward.height_m - f.height_m)) < 1e-9


def test_kf_gins_yaml_runs_as_the_cli(sim_files, sim, tmp_path, monkeypatch):
    # KF-GINS resolves its paths against the working directory.
    monkeypatch.chdir(sim_files)
    py = driftless.navigate(config="kf-gins.yaml", smooth=True)
    assert len(py.files) == 6 and all(os.path.isfile(p) for p in py.files)
    assert py.config is None and py.smoothed is not None
    t0 = py.start_time_s + 60.0
    forward = py.horizontal_rms_m(sim.truth, from_s=t0)
    assert forward < 0.10, forward
    cli_csv = tmp_path / "kf.csv"
    subprocess.run([BIN, "nav", "--kf-gins", "kf-gins.yaml", "--quiet", "--force",
                    "--csv", str(cli_csv)], check=True, stdout=subprocess.DEVNULL)
    table = np.loadtxt(cli_csv, delimiter=",", skiprows=1)
    # The CLI writes KF-GINS's rows (every epoch after the initial one).
    f = py.forward
    k = np.searchsorted(f.time_s, table[:, 0] - 1e-6)
    assert np.max(np.abs(f.time_s[k] - table[:, 0])) <= 0.5e-4
    assert np.max(np.abs(np.degrees(f.lat_rad[k]) - table[:, 1])) <= 0.5e-9 * (1 + 1e-6)
    assert np.max(np.abs(f.height_m[k] - table[:, 3])) <= 0.5e-4 * (1 + 1e-6)
    with pytest.raises(ValueError, match="names its own"):
        driftless.navigate(sim.imu, sim.gnss, "kf-gins.yaml")
