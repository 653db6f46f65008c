use super::*;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-navcfg-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn flag(path: &str, value: &str) -> Override {
    Override {
        key: key_by_path(path).unwrap(),
        value: value.into(),
    }
}

#[test]
fn printed_default_reads_back_as_the_default() {
    let d = tmp("print");
    let p = write(&d, "nav.toml", &NavConfig::default_toml());
    let c = NavConfig::load(Some(&p), &[]).unwrap();
    assert_eq!(c.config, NavConfig::default());
    // Every key appears in the printed file, as a value or a commented example.
    let text = NavConfig::default_toml();
    for k in KEYS {
        let name = k.path.split_once('.').unwrap().1;
        assert!(text.contains(&format!("{name} = ")), "{}", k.path);
        assert!(text.contains(&format!("(--{})", k.flag)), "{}", k.flag);
    }
}

#[test]
fn flags_override_the_file_and_errors_name_their_origin() {
    let d = tmp("override");
    let p = write(
        &d,
        "nav.toml",
        "[imu]\ntime_offset_s = -0.125\nmounting_rpy_deg = [180.0, 0.0, 180.0]\n\n[gnss]\nsigma_floor_m = 0.05\n",
    );
    let c = NavConfig::load(
        Some(&p),
        &[flag("gnss.sigma_floor_m", "0.1"), flag("aids.zupt", "true")],
    )
    .unwrap();
    assert_eq!(c.config.imu.time_offset_s, -0.125);
    assert_eq!(c.config.imu.mounting_rpy_deg, [180.0, 0.0, 180.0]);
    assert_eq!(c.config.gnss.sigma_floor_m, FloorSetting::Metres(0.1));
    assert_eq!(c.config.sigma_floor_m(), Some((0.1, 0.2)));
    assert!(!c.config.auto_sigma_floor());
    assert!(c.config.aids.zupt);

    // The σ floor: estimated by default, `auto` or a number in the file and as a flag,
    // anything else named with its position.
    assert!(NavConfig::default().auto_sigma_floor());
    assert_eq!(NavConfig::default().sigma_floor_m(), None);
    let p = write(&d, "auto.toml", "[gnss]\nsigma_floor_m = 0.3\n");
    let c = NavConfig::load(Some(&p), &[flag("gnss.sigma_floor_m", "auto")]).unwrap();
    assert!(c.config.auto_sigma_floor());
    let p = write(
        &d,
        "auto2.toml",
        "[gnss]\nsigma_floor_m = \"auto\"\nsigma_floor_vertical_m = 0.5\n",
    );
    let c = NavConfig::load(Some(&p), &[]).unwrap();
    assert!(c.config.auto_sigma_floor());
    assert_eq!(c.config.sigma_floor_m(), Some((0.0, 0.5)));
    let c = NavConfig::load(None, &[flag("gnss.sigma_floor_m", "0")]).unwrap();
    assert!(!c.config.auto_sigma_floor() && c.config.sigma_floor_m().is_none());
    let p = write(&d, "autox.toml", "[gnss]\nsigma_floor_m = \"automatic\"\n");
    let e = NavConfig::load(Some(&p), &[]).unwrap_err();
    assert!(e.location.ends_with("autox.toml:2:17"), "{e}");
    assert!(e.message.contains("\"auto\" or a number of metres"), "{e}");
    let e = NavConfig::load(None, &[flag("gnss.sigma_floor_m", "big")]).unwrap_err();
    assert!(
        e.location.starts_with("flag --gnss-sigma-floor") && e.message.contains("or `auto`"),
        "{e}"
    );

    // A bad value in the file: FILE:LINE:COL and the key.
    let p = write(&d, "bad.toml", "[gnss]\n# comment\nsigma_floor_m = -1.0\n");
    let e = NavConfig::load(Some(&p), &[]).unwrap_err();
    assert!(
        e.location
            .ends_with("bad.toml:3:17 (key `gnss.sigma_floor_m`)"),
        "{e}"
    );
    assert!(e.message.contains("≥ 0"), "{e}");
    // The same through a flag names the flag.
    let e = NavConfig::load(None, &[flag("gnss.sigma_floor_m", "-1")]).unwrap_err();
    assert_eq!(e.location, "flag --gnss-sigma-floor");
    // A flag that is not a number.
    let e = NavConfig::load(None, &[flag("imu.time_offset_s", "abc")]).unwrap_err();
    assert!(
        e.location.starts_with("flag --imu-time-offset") && e.message.contains("not a number"),
        "{e}"
    );
    // A wrong type and an unknown key in the file, with their positions.
    let p = write(&d, "type.toml", "[imu]\ntime_offset_s = \"soon\"\n");
    let e = NavConfig::load(Some(&p), &[]).unwrap_err();
    assert!(e.location.ends_with("type.toml:2:17"), "{e}");
    let p = write(&d, "unknown.toml", "[imu]\ntime_ofset_s = 1.0\n");
    let e = NavConfig::load(Some(&p), &[]).unwrap_err();
    assert!(
        e.location.ends_with("unknown.toml:2:1") && e.message.contains("time_ofset_s"),
        "{e}"
    );
}

#[test]
fn every_new_key_is_validated() {
    let bad: &[(&str, &str, &str)] = &[
        ("imu.mounting_rpy_deg", "1000,0,0", "±360"),
        ("imu.format", "xml", "not a format"),
        ("imu.rate_hz", "0", "> 0"),
        ("imu.max_gyro_deg_s", "0", "> 0"),
        ("imu.max_accel_g", "-1", "> 0"),
        ("gnss.lever_arm_m", "0,0,500", "±100"),
        ("gnss.sigma_scale", "float=-3", "> 0"),
        ("gnss.accept", "fix,fixed", "not a solution quality"),
        ("noise.gyro_white", "0.2 deg/h", "does not fit"),
        ("noise.gyro_white", "300 deg/s/sqrt(Hz)", "implausible"),
        ("noise.gyro_bias_initial", "30 deg/s", "implausible"),
        ("noise.accel_scale_sigma", "-5 ppm", "≥ 0"),
        ("noise.multiplier", "white=0", "> 0"),
        ("align.min_speed_m_s", "-1", "≥ 0"),
        ("align.initial_yaw_deg", "720", "±360"),
        ("aids.zupt_sigma_m_s", "0", "> 0"),
        ("filter.gate", "chi2:2", "not a gate"),
        ("filter.gate", "strict", "robust"),
        ("imu.time_base", "unix", "gpst-unix"),
        ("imu.time_base", "gps-week-sow", "week column"),
        ("outages.spec", "3x", ""),
    ];
    for (path, value, needle) in bad {
        let e = NavConfig::load(None, &[flag(path, value)]).unwrap_err();
        let k = key_by_path(path).unwrap();
        assert!(
            e.location.starts_with(&format!("flag --{}", k.flag)),
            "{path}: {e}"
        );
        assert!(e.message.contains(needle), "{path} {value}: {e}");
    }
    let e = NavConfig::load(
        None,
        &[
            flag("align.initial_yaw_deg", "10"),
            flag("align.initial_attitude_deg", "0,0,10"),
        ],
    )
    .unwrap_err();
    assert!(e.message.contains("not both"), "{e}");
}

#[test]
fn data_sheet_noise_becomes_the_filter_model() {
    let c = NavConfig::load(
        None,
        &[
            flag("noise.gyro_white", "3.8 mdps/sqrt(Hz)"),
            flag("noise.accel_white", "70 ug/sqrt(Hz)"),
            flag("noise.gyro_bias_instability", "8 deg/h"),
            flag("noise.gyro_bias_random_walk", "40 deg/h/sqrt(h)"),
            flag("noise.multiplier", "white=2"),
        ],
    )
    .unwrap();
    let (n, s0) = c.config.noise_settings(None).unwrap();
    let deg = std::f64::consts::PI / 180.0;
    assert!((n.gyro_arw_rad_sqrt_s - 2.0 * 3.8e-3 * deg).abs() < 1e-15);
    assert!((n.accel_vrw_m_s_sqrt_s - 2.0 * 70e-6 * 9.80665).abs() < 1e-15);
    // σ² = B² + K²T/2 with T = 3600 s.
    let b = 8.0 * deg / 3600.0;
    let k = 40.0 * deg / 3600.0 / 60.0;
    let want = (b * b + k * k * 3600.0 / 2.0).sqrt();
    assert!((n.gyro_bias.sigma - want).abs() < 1e-15 * want.max(1.0));
    // The turn-on σ (0.3 deg/s default) is the initial uncertainty.
    assert!((s0[0] - 0.3 * deg).abs() < 1e-15);
    assert_eq!(n.gyro_scale.sigma, 5e-3);
}
