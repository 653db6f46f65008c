"""The Kalibr `imu.yaml` that `driftless allan --export kalibr=…` writes, read by PyYAML
(the YAML 1.1 reader Kalibr itself uses): every value a float equal to the saved noise
model's, the largest axis per sensor (docs/noise-exports.md)."""

import os
import pathlib
import subprocess
import tomllib

import yaml

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("DRIFTLESS_BIN", str(ROOT / "target" / "release" / "driftless"))
DATA = pathlib.Path(os.environ.get("DRIFTLESS_DATA", ROOT.parent / "shared" / "data"))


def test_kalibr_yaml_read_by_pyyaml_equals_the_model(tmp_path):
    log = DATA / "static" / "adis16405_calgary" / "adis16405_run2.csv.gz"
    assert log.is_file(), f"shared data missing: {log}"
    model_path, yaml_path = tmp_path / "noise.toml", tmp_path / "imu.yaml"
    subprocess.run(
        [BIN, "allan", str(log), "--quiet", "--json",
         "--save-model", str(model_path), "--export", f"kalibr={yaml_path}"],
        check=True, stdout=subprocess.DEVNULL,
    )
    imu = yaml.safe_load(yaml_path.read_text())
    model = tomllib.loads(model_path.read_text())

    def largest_white(quantity):
        values = [c["fit"]["white"]["value"] for c in model["channels"]
                  if c["quantity"] == quantity and "white" in c["fit"]]
        assert values, quantity
        return max(values)

    for key, quantity in [("gyroscope_noise_density", "angular_rate"),
                          ("accelerometer_noise_density", "specific_force")]:
        got, want = imu[key], largest_white(quantity)
        assert isinstance(got, float), (key, got)
        assert abs(got - want) <= 1e-12 * want, (key, got, want)
    for key in ["gyroscope_random_walk", "accelerometer_random_walk", "update_rate"]:
        assert isinstance(imu[key], float) and imu[key] > 0.0, (key, imu[key])
    assert abs(imu["update_rate"] - model["sample_rate_hz"]) <= 1e-9 * model["sample_rate_hz"]
    assert isinstance(imu["rostopic"], str)
