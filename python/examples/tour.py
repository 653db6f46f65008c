# %% [markdown]
# # driftless from Python: a tour for navigation engineers
#
# Run it top to bottom (`python tour.py`, well under a minute) or cell by cell in an
# editor that understands `# %%` cells (VS Code, Spyder, Jupytext). Every array is a
# NumPy column in SI units; frames and units are in the names (`gyro_x` rad/s, `acc_x`
# m/s², `lat_rad`, `vel_n_m_s`, `sigma_n_m`). The work runs in Rust with the GIL released.

# %%
import pathlib

import numpy as np

import driftless

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]

# %% [markdown]
# ## 1. Simulate a drive
# `examples/scenarios/city-drive.toml`: a 3.5-min urban drive with a consumer-grade IMU
# at 100 Hz and 1-Hz RTK-grade GNSS (2 cm σ, with velocity). We drop the scenario's own
# GNSS gaps: outages are set below, in the navigation configuration, so that the same
# data serve the full-GNSS and the outage runs. `sim.truth` is the true trajectory of the
# IMU centre.

# %%
scenario = (ROOT / "examples" / "scenarios" / "city-drive.toml").read_text()
scenario = "\n".join(l for l in scenario.splitlines() if not l.startswith("outages"))
sim = driftless.simulate(scenario, name="city-drive.toml")
print(sim)
print("IMU columns:", sorted(sim.imu))
print("GNSS columns:", sorted(sim.gnss))
print("antenna lever arm (body FRD, m):", sim.lever_arm_b_m)

# %% [markdown]
# ## 2. Noise analysis of a static log
# A 20-minute static log of an ADIS16465-class IMU (`examples/scenarios/static-18h.toml`
# cut to 20 min; noise only):
# the overlapping Allan deviation of one gyro with confidence bounds, and the noise model
# fitted to it — the numbers a filter is tuned with. The simulated white noise is known,
# so the fit can be checked.

# %%
static_scenario = (ROOT / "examples" / "scenarios" / "static-18h.toml").read_text()
static = driftless.simulate(static_scenario.replace("duration_s = 64800.0", "duration_s = 1200.0"),
                            name="static-18h.toml, 20 min")
curve = driftless.analyse(static.imu["gyro_x"], 1.0 / static.tau0_s,
                          quantity="angular_rate", name="gyro_x")
print(curve)
print(curve.noise_model.table())
white_true = static.sensor["gyro"]["noise"][0]["white"]
white_fit = curve.noise_model.to_dict()["channels"][0]["fit"]["white"]["value"]
print(f"gyro white noise: simulated {white_true:.3e}, fitted {white_fit:.3e} rad/s/√Hz "
      f"({100 * (white_fit / white_true - 1):+.1f} %)")

# %% [markdown]
# ## 3. Six-position and thermal calibration in a simulated chamber
# A short chamber session of the same ADIS16465-class sensor with its deterministic
# errors switched on: at each of five set temperatures the unit soaks, rests in six
# positions and turns on a rate table (20 Hz, 30-s soaks, so it runs in seconds).
# `simulate_chamber` returns the IMU columns and the segment manifest the protocol
# wrote — what a chamber's own log and protocol file would give.

# %%
chamber = driftless.simulate_chamber("""seed = 7
[imu]
rate_hz = 20.0
preset = "adi-like"
output = "rates"
[trajectory]
type = "chamber"
temperatures_c = [-20.0, 0.0, 25.0, 50.0, 70.0]
soak_s = 30.0
position_dwell_s = 10.0
move_s = 2.0
rate_deg_s = 60.0
rate_revolutions = 1
spin_s = 1.0
lag_tau_s = 1.0
""", name="tour chamber")
print(chamber)

# %% [markdown]
# Six-position calibration at 25 °C: bias, scale factor and misalignment of both
# triads, each with its standard error. The simulated accelerometer bias at 25 °C is the
# constant term of the sensor's bias polynomial plus a turn-on bias the simulator draws
# at power-up (σ 0.049 m/s² here) — the part no datasheet gives and calibration measures.

# %%
cal = driftless.calibrate_six_position(chamber.imu, manifest_toml=chamber.manifest_toml,
                                       temperature_c=25.0)
print(cal)
datasheet = np.array([p[0] for p in chamber.sensor["accel"]["bias_poly_m_s2"]])
print("accel bias (m/s²): estimated", np.round(cal.accel_bias, 4),
      "±", np.round(cal.accel_bias_sigma, 4), "; polynomial's constant term",
      np.round(datasheet, 4))
print("scale factor (1 + s):", np.round(cal.accel_scale_factor, 5), "; simulated",
      np.round([1 + p[0] for p in chamber.sensor["accel"]["scale_factor_poly"]], 5))

# %% [markdown]
# The soak method repeats that calibration at every set temperature and fits a cubic
# in ΔT = T − 25 °C per bias and scale factor. `ThermalModel.compensate` applies it to
# raw samples — the kernel the `no_std` crate runs on a device. Calibrating the
# compensated log again at each temperature shows what is left: the model holds the
# 25 °C calibration and the thermal cubics, so the bias is near zero at every set
# temperature (the gyro's ±25 °/h is the noise of this short protocol's 10-s dwells).

# %%
thermal = driftless.thermal_fit(chamber.imu, manifest_toml=chamber.manifest_toml)
print(thermal)
f = thermal.fit("gyro", "bias", "x")
print("gyro x bias cubic c0…c3:", ", ".join(f"{c:.3e}" for c in f["coefficients"]))
gyro = np.column_stack([chamber.imu[f"gyro_{a}"] for a in "xyz"])
accel = np.column_stack([chamber.imu[f"acc_{a}"] for a in "xyz"])
gyro_c, accel_c = thermal.compensate(gyro, accel, chamber.imu["temp"])
compensated = dict(chamber.imu)
for k, a in enumerate("xyz"):
    compensated[f"gyro_{a}"], compensated[f"acc_{a}"] = gyro_c[:, k], accel_c[:, k]
print("set °C   gyro x bias [°/h] raw → compensated   accel x bias [m/s²] raw → compensated")
for t in (-20.0, 0.0, 25.0, 50.0, 70.0):
    raw = driftless.calibrate_six_position(chamber.imu, manifest_toml=chamber.manifest_toml,
                                           temperature_c=t)
    comp = driftless.calibrate_six_position(compensated, manifest_toml=chamber.manifest_toml,
                                            temperature_c=t)
    print(f"{t:6.0f}   {np.degrees(raw.gyro_bias[0]) * 3600:10.1f} → {np.degrees(comp.gyro_bias[0]) * 3600:8.1f}"
          f"          {raw.accel_bias[0]:10.4f} → {comp.accel_bias[0]:8.4f}")

# %% [markdown]
# ## 4. Navigate with full GNSS
# The loosely coupled filter and the RTS smoother. The configuration is the one
# `driftless nav --config` reads, as a dict of sections (`driftless.default_nav_config()`
# lists every key); here only the lever arm. The horizontal RMS error against the truth
# is taken after 60 s of convergence.

# %%
config = {"gnss": {"lever_arm_m": sim.lever_arm_b_m}}
full = driftless.navigate(sim.imu, sim.gnss, config)
t0 = full.start_time_s + 60.0
print(full)
print(f"full GNSS: horizontal RMS vs truth forward {full.horizontal_rms_m(sim.truth, from_s=t0):.3f} m, "
      f"smoothed {full.horizontal_rms_m(sim.truth, smoothed=True, from_s=t0):.3f} m; "
      f"one-step prediction RMS at the fixes {full.prediction_rms_m:.3f} m")
# Any solution is a dict of columns, e.g. for pandas: pandas.DataFrame(full.forward.columns())
print("solution columns:", ", ".join(list(full.forward.columns())[:12]), "…")

# %% [markdown]
# ## 5. Navigate through a 30-s GNSS outage
# `outages.spec = "100+30"` withholds the fixes from 100 s after the first fix for 30 s
# (the `driftless nav --outages` grammar). The forward filter dead-reckons through it;
# the smoother bridges it from both ends.

# %%
cut = driftless.navigate(sim.imu, sim.gnss, {**config, "outages": {"spec": "100+30"}})
o = cut.outages[0]
inside = (cut.forward.time_s > o["start_s"]) & (cut.forward.time_s <= o["end_s"])


def horizontal_errors_m(sol):
    """Horizontal distance to the truth at the solution epochs (flat-Earth, m)."""
    lat = np.interp(sol.time_s, sim.truth["time_s"], sim.truth["lat_rad"])
    lon = np.interp(sol.time_s, sim.truth["time_s"], sim.truth["lon_rad"])
    r = 6.371e6
    return np.hypot((sol.lat_rad - lat) * r, (sol.lon_rad - lon) * r * np.cos(lat))


fwd_err = horizontal_errors_m(cut.forward)[inside]
smo_err = horizontal_errors_m(cut.smoothed)[inside]
print(f"outage {o['start_s']:.1f}…{o['end_s']:.1f} s: GNSS withheld {cut.gnss_withheld}")
print(f"  forward:  error at the end {fwd_err[-1]:.2f} m, largest {fwd_err.max():.2f} m "
      f"(the filter's own 1σ north at the end {cut.forward.sigma_n_m[inside][-1]:.2f} m)")
print(f"  smoothed: largest {smo_err.max():.2f} m")
print(f"  after the outage: forward error at the first fix {o['end_horizontal_m']:.2f} m")

# %% [markdown]
# ## 6. The experiment, and its Monte Carlo one run at a time
# `driftless.experiment` runs `driftless experiment` on a scenario (here the small one:
# seconds of work). `driftless.montecarlo.run_one(plan, i)` computes run i alone — the
# building block for spreading runs over processes or machines
# (`python/examples/monte_carlo.py` does it with Dask).

# %%
from driftless import montecarlo

small = ROOT / "examples" / "experiment" / "small.toml"
result = driftless.experiment(small, runs=3)
print(result.summary.table())
plan = montecarlo.prepare(small)
row = montecarlo.run_one(plan, 2)
print(f"run 2 alone: raw forward mean end error {row['raw_forward_mean_end_m']:.2f} m "
      f"(serial: {result.rows[2]['raw_forward_mean_end_m']:.2f} m)")
