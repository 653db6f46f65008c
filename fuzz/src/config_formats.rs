//! Arbitrary text into every configuration, model and specification format the library
//! reads, the first byte choosing the format (the rest is taken as UTF-8, invalid bytes
//! replaced): noise model, simulation scenario, experiment scenario, motion profile,
//! chamber manifest, navigation configuration (file text, or one command-line flag),
//! KF-GINS YAML, calibration file, thermal model file, outage specification, tau grid,
//! column / unit / time specifications, navigation quantities, and the fit, GMWM, gate,
//! preset and axis specifications.
//!
//! Invariants: no panic; an error's message is non-empty and, where the parser is given a
//! name, starts with it; a value the parser validates holds only finite numbers (parsers
//! that check syntax only are followed by the checks their callers run before use).

use std::fmt::{Debug, Display};
use std::path::PathBuf;
use std::str::FromStr;

use driftless::allan::Estimator;
use driftless::allan::noise_model::NoiseModel;
use driftless::allan::taus::{TauSpec, averaging_factors};
use driftless::calib::model_file::CalibrationFile;
use driftless::calib::protocol::{BodyAxis, ChamberManifest, SignedAxis};
use driftless::experiment::scenario::ExperimentScenario;
use driftless::io::nav::{KfGinsConfig, TimeBase};
use driftless::io::{ColumnRef, ColumnSpec, Delimiter, GapPolicy, TimeUnit, Unit};
use driftless::nav::config::quantity::{Kind, parse_quantity};
use driftless::nav::config::{KEYS, LoadedConfig, NavConfig, Override};
use driftless::nav::outage::{OutageSpec, TimeSpan};
use driftless::sim::profile::MotionProfile;
use driftless::sim::scenario::Scenario;
use driftless::thermal::model_file::ThermalModelFile;

use super::check;

/// Name given to the parsers that take one; their errors start with it.
const NAME: &str = "fuzz.toml";

/// One fuzz input; panics on a broken invariant.
pub fn run(data: &[u8]) {
    let (sel, body) = data.split_first().map_or((0, data), |(s, b)| (*s, b));
    let text = String::from_utf8_lossy(body);
    let text = text.as_ref();
    match sel % 16 {
        0 => noise_model(text),
        1 => sim_scenario(text),
        2 => experiment_scenario(text),
        3 => motion_profile(text),
        4 => chamber_manifest(text),
        5 => nav_config(text),
        6 => nav_flag(body),
        7 => match KfGinsConfig::from_yaml_str(text, NAME) {
            Ok(c) => check::finite_debug("KF-GINS config", &c),
            Err(e) => check::names_input(NAME, &e),
        },
        8 => match CalibrationFile::from_toml_str(text, NAME) {
            Ok(f) => check::finite_debug("calibration file", &f),
            Err(e) => check::names_input(NAME, &e),
        },
        9 => match ThermalModelFile::from_toml_str(text, NAME) {
            Ok((f, m)) => {
                check::finite_debug("thermal model file", &f);
                check::finite_debug("thermal model", &m);
            }
            Err(e) => check::names_input(NAME, &e),
        },
        10 => outage(text),
        11 => taus(text),
        12 => columns(text),
        13 => quantities(text),
        _ => small_specs(text),
    }
}

fn noise_model(text: &str) {
    match NoiseModel::from_toml_str(text) {
        Ok(m) => {
            assert!(m.sample_rate_hz.is_finite() && m.sample_rate_hz > 0.0);
            use driftless::allan::fit::TermKind;
            let kinds = TermKind::LINEAR.into_iter().chain([TermKind::GaussMarkov]);
            for fit in m.fits() {
                for t in kinds.clone().filter_map(|k| fit.term(k)) {
                    assert!(t.value.is_finite() && t.value >= 0.0, "{t:?}");
                }
            }
        }
        Err(e) => {
            check::message("noise model", &e);
        }
    }
}

fn sim_scenario(text: &str) {
    match Scenario::from_toml_str(text, NAME) {
        Ok(mut s) => {
            // A noise-model path would be read from the file system: not here.
            s.imu.noise_model = None;
            if let Err(e) = s.sensor_config() {
                check::names_input(NAME, &e);
            }
        }
        Err(e) => check::names_input(NAME, &e),
    }
}

fn experiment_scenario(text: &str) {
    match ExperimentScenario::from_toml_str(text, NAME, PathBuf::new()) {
        Ok(s) => {
            check::finite_debug("experiment scenario", &s);
            if let Err(e) = s.vehicle_source() {
                check::names_input(NAME, &e);
            }
            if let Err(e) = s.sensor_config() {
                check::names_input(NAME, &e);
            }
            if let Err(e) = s.outage_spec() {
                check::names_input(NAME, &e);
            }
        }
        Err(e) => check::names_input(NAME, &e),
    }
}

fn motion_profile(text: &str) {
    match MotionProfile::from_toml_str(text, NAME) {
        Ok(p) => {
            match p.drive_segments() {
                Ok(d) => check::finite_debug("drive segments", &d),
                Err(e) => {
                    check::message("drive segments", &e);
                }
            }
            match p.gait() {
                Ok(g) => check::finite_debug("gait", &g),
                Err(e) => {
                    check::message("gait", &e);
                }
            }
        }
        Err(e) => {
            let m = check::message("motion profile", &e);
            assert!(m.contains(NAME), "{m}");
        }
    }
}

fn chamber_manifest(text: &str) {
    match ChamberManifest::from_toml_str(text) {
        Ok(m) => {
            // Syntax only: the queries must still not panic on whatever numbers it holds.
            let temps = m.set_temperatures_c();
            let _ = m.steps();
            for &t in temps.iter().take(4) {
                for axis in [BodyAxis::X, BodyAxis::Y, BodyAxis::Z] {
                    let _ = m.rate(t, axis, true);
                    let _ = m.position(
                        t,
                        SignedAxis {
                            axis,
                            positive: false,
                        },
                    );
                }
            }
            for s in m.segments.iter().take(8) {
                let _ = s.duration_s();
                let _ = s.sample_range(100.0);
            }
        }
        Err(e) => {
            check::message("chamber manifest", &e);
        }
    }
}

fn nav_config(text: &str) {
    let source = Some((text.to_owned(), PathBuf::from(NAME), PathBuf::new()));
    match NavConfig::load_text(source, &[]) {
        Ok(c) => nav_config_ok(&c),
        Err(e) => check::names_input(NAME, &e),
    }
}

/// `body`: a key index byte, then the flag's text.
fn nav_flag(body: &[u8]) {
    let (k, value) = body.split_first().map_or((0, body), |(s, b)| (*s, b));
    let key = &KEYS[usize::from(k) % KEYS.len()];
    let value = String::from_utf8_lossy(value).into_owned();
    let overrides = [Override { key, value }];
    match NavConfig::load_text(None, &overrides) {
        Ok(c) => nav_config_ok(&c),
        Err(e) => {
            let m = check::message("flag", &e);
            assert!(m.contains(key.flag) || m.contains(key.path), "{m}");
        }
    }
}

/// What the navigation command derives from a validated configuration.
fn nav_config_ok(loaded: &LoadedConfig) {
    let c = &loaded.config;
    check::finite_debug("nav config", c);
    if let Ok(g) = c.gate() {
        check::finite_debug("gate", &g);
    }
    let _ = c.time_base();
    check::finite_debug("stream options", &c.stream_options());
    check::finite_debug("sigma floor", &c.sigma_floor_m());
    match c.noise_settings(None) {
        Ok(n) => check::finite_debug("noise settings", &n),
        Err(e) => {
            check::message("noise settings", &loaded.error(e));
        }
    }
}

fn outage(text: &str) {
    let Some(spec) = parsed::<OutageSpec>(text, "outage") else {
        return;
    };
    let span = TimeSpan {
        start_s: 1000.0,
        end_s: 5000.0,
    };
    match spec.resolve(span) {
        Ok(w) => {
            check::finite_debug("outage windows", &w);
            for x in &w {
                assert!(x.start_s >= span.start_s && x.end_s <= span.end_s, "{w:?}");
                assert!(x.end_s > x.start_s, "{w:?}");
            }
            assert!(w.windows(2).all(|p| p[1].start_s >= p[0].end_s), "{w:?}");
        }
        Err(e) => {
            check::message("outage resolve", &e);
        }
    }
}

fn taus(text: &str) {
    let Some(spec) = parsed::<TauSpec>(text, "tau spec") else {
        return;
    };
    let n_phase = 10_001;
    for est in [Estimator::Oadev, Estimator::Totdev] {
        if let Ok(m) = averaging_factors(&spec, 0.01, n_phase, est) {
            assert!(!m.is_empty());
            assert!(
                m.iter().all(|&m| m >= 1 && m <= est.max_m(n_phase)),
                "{m:?}"
            );
        }
    }
}

fn columns(text: &str) {
    parsed::<ColumnSpec>(text, "column spec");
    parsed::<ColumnRef>(text, "column");
    parsed::<Unit>(text, "unit");
    if let Some(u) = parsed::<TimeUnit>(text, "time unit") {
        assert!(u.to_s() > 0.0, "{u:?}");
    }
    parsed::<GapPolicy>(text, "gap policy");
    parsed::<Delimiter>(text, "delimiter");
    parsed::<TimeBase>(text, "time base");
}

/// `text` parsed as a `T`: a value holding only finite numbers, or an error with a message.
fn parsed<T>(text: &str, what: &str) -> Option<T>
where
    T: FromStr + Debug,
    T::Err: Display,
{
    match text.parse::<T>() {
        Ok(v) => {
            check::finite_debug(what, &v);
            Some(v)
        }
        Err(e) => {
            check::message(what, &e);
            None
        }
    }
}

fn quantities(text: &str) {
    for kind in [
        Kind::AngleRandomWalk,
        Kind::VelocityRandomWalk,
        Kind::AngularRate,
        Kind::SpecificForce,
        Kind::RateRandomWalk,
        Kind::AccelRandomWalk,
        Kind::Scale,
    ] {
        match parse_quantity(text, kind) {
            Ok(v) => assert!(v.is_finite() && v >= 0.0, "{text:?} as {kind:?}: {v}"),
            Err(e) => {
                check::message("quantity", &e);
            }
        }
    }
}

fn small_specs(text: &str) {
    use driftless::allan::fit::{FitConfig, FitRangeSpec};
    use driftless::allan::gmwm::GmwmConfig;
    use driftless::nav::filter::model::Gate;
    use driftless::sim::presets::Preset;
    parsed::<FitConfig>(text, "fit config");
    parsed::<FitRangeSpec>(text, "fit range");
    parsed::<GmwmConfig>(text, "GMWM config");
    parsed::<Gate>(text, "gate");
    if let Some(p) = parsed::<Preset>(text, "preset") {
        check::finite_debug("preset", &p.config());
    }
    parsed::<SignedAxis>(text, "axis");
}
