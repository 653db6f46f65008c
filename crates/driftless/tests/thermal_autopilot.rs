//! PX4 `TC_*` / ArduPilot `INS_TCAL*` export → re-import → each autopilot's documented
//! correction formula, against the model's own bias b + Δb(T)
//! (the same correction to 1e-6 at 10 temperatures), clamping outside the range,
//! the worked example of `docs/autopilot-thermal.md`, and the import's error messages.

use driftless::thermal::autopilot::{
    AutopilotError, BiasModel, ExportOptions, check_temperatures, compare_ardupilot, compare_px4,
    export_ardupilot, export_px4, parse_ardupilot, parse_px4,
};
use driftless::thermal::model_file::{FORMAT_VERSION, ThermalModelFile, TriadSection};
use driftless_model::compensation::CompensationModel;

const G: f64 = 9.80665;

/// A model with the adi-like preset's magnitudes: cubic bias deltas on every axis (up to
/// ~1 m/s² and ~6 °/s over −25…70 °C), scale-factor deltas and misalignment (which the
/// export must drop), room biases 0.1–0.2 m/s² and 0.2–0.5 °/s.
fn adi_like_file(t_ref_c: f64, range_c: [f64; 2]) -> ThermalModelFile {
    let cfg = driftless::sim::presets::Preset::AdiLike.config();
    let section = |polys: &[Vec<f64>; 3], sf: &[Vec<f64>; 3], unit: &str, mis: f64| {
        let strip = |p: &Vec<f64>| {
            let mut c = p.clone();
            c[0] = 0.0;
            c
        };
        TriadSection {
            raw_unit: unit.into(),
            bias: std::array::from_fn(|k| polys[k][0]),
            matrix: [
                [1.0, mis, -mis],
                [0.5 * mis, 1.0, mis],
                [-mis, 0.3 * mis, 1.0],
            ],
            bias_delta: std::array::from_fn(|k| strip(&polys[k])),
            scale_delta: std::array::from_fn(|k| strip(&sf[k])),
        }
    };
    let gyro_polys: [Vec<f64>; 3] = std::array::from_fn(|k| cfg.gyro.bias_poly_rad_s[k].to_vec());
    ThermalModelFile {
        format_version: FORMAT_VERSION,
        model_id: 0x1234,
        t_ref_c,
        range_c,
        out_of_range: "clamp".into(),
        gyro_g_sensitivity: None,
        accel: section(
            &cfg.accel.bias_poly_m_s2,
            &cfg.accel.scale_factor_poly,
            "m/s^2",
            2e-3,
        ),
        gyro: section(&gyro_polys, &cfg.gyro.scale_factor_poly, "rad/s", 3e-3),
    }
}

fn model_of(f: &ThermalModelFile) -> CompensationModel {
    f.model("test").unwrap()
}

#[test]
fn round_trip_matches_the_model_at_ten_temperatures() {
    for (t_ref, range, offsets) in [
        (25.0, [-25.0, 70.0], true),
        (25.0, [-25.0, 70.0], false),
        (40.0, [-10.0, 85.0], true),
    ] {
        let f = adi_like_file(t_ref, range);
        let m = model_of(&f);
        let bm = BiasModel::from_model_file(&f, "test").unwrap();
        let opts = ExportOptions {
            include_offsets: offsets,
            px4_accel_id: 1_310_988,
            px4_gyro_id: 1_310_996,
            ..ExportOptions::default()
        };
        let temps = check_temperatures(range, 10);
        assert_eq!(temps.len(), 10);

        let px4_text = export_px4(&bm, &opts).unwrap();
        assert!(px4_text.contains("BIAS ONLY. Scale-factor and misalignment terms have no place"));
        let px4 = parse_px4(&px4_text, "t.params", 0).unwrap();
        let e = compare_px4(&f, &m, &px4, &temps, !offsets).unwrap();
        eprintln!("PX4 t_ref {t_ref} offsets {offsets}: {e:?}");
        // f64 evaluation of the float32 parameters: parameter rounding only.
        assert!(e.accel <= 1e-6 && e.gyro <= 1e-6, "{e:?}");
        assert!(e.accel <= 1e-7 && e.gyro <= 1e-8, "{e:?}");
        // PX4's own float arithmetic.
        assert!(e.accel_f32 <= 1e-6 && e.gyro_f32 <= 1e-6, "{e:?}");

        let ap_text = export_ardupilot(&bm, &opts).unwrap();
        // No exponent notation (ArduPilot scales by 1e6 for editors that cannot read it).
        for t in [&ap_text, &px4_text] {
            for l in t.lines().filter(|l| !l.starts_with('#')) {
                let v = l
                    .split([',', '\t'])
                    .nth_back(if l.contains(',') { 0 } else { 1 });
                assert!(!v.unwrap().contains(['e', 'E']), "{l}");
            }
        }
        let ap = parse_ardupilot(&ap_text, "t.param", 0).unwrap();
        if offsets {
            assert_eq!(ap.acc_caltemp as f64, t_ref);
        } else {
            assert!(ap.acc_offs.is_none());
        }
        let mut ap_eval = ap.clone();
        if !offsets {
            // The vehicle's own calibration temperature (not in the file): any will do.
            ap_eval.acc_caltemp = 31.5;
            ap_eval.gyr_caltemp = 18.0;
        }
        let e = compare_ardupilot(&f, &m, &ap_eval, &temps, !offsets).unwrap();
        eprintln!("ArduPilot t_ref {t_ref} offsets {offsets}: {e:?}");
        assert!(e.accel <= 1e-6 && e.gyro <= 1e-6, "{e:?}");
        assert!(e.accel <= 1e-7 && e.gyro <= 1e-8, "{e:?}");
        assert!(e.accel_f32 <= 1e-6 && e.gyro_f32 <= 1e-6, "{e:?}");
    }
}

/// The exported values must not be usable in the wrong instance, and PX4's file must
/// carry the device ids.
#[test]
fn instances_and_ids() {
    let f = adi_like_file(25.0, [-25.0, 70.0]);
    let bm = BiasModel::from_model_file(&f, "t").unwrap();
    let o = ExportOptions {
        instance: 2,
        px4_accel_id: 7,
        px4_gyro_id: 9,
        ..ExportOptions::default()
    };
    let px4 = export_px4(&bm, &o).unwrap();
    assert!(px4.contains("1\t1\tTC_A2_ID\t7\t6\n") && px4.contains("1\t1\tTC_G2_ID\t9\t6\n"));
    assert!(px4.contains("1\t1\tCAL_GYRO2_ZOFF\t0\t9\n"));
    let p = parse_px4(&px4, "t", 2).unwrap();
    assert_eq!(p.accel.as_ref().unwrap().device_id, 7);
    assert!(matches!(
        parse_px4(&px4, "t", 0),
        Err(AutopilotError::Params { .. })
    ));
    let ap = export_ardupilot(&bm, &o).unwrap();
    assert!(ap.contains("INS_TCAL3_ENABLE,1\n") && ap.contains("INS_ACC3OFFS_X,"));
    assert!(ap.contains("INS_GYR3OFFS_Z,") && ap.contains("INS_GYR3_CALTEMP,25\n"));
    assert_eq!(parse_ardupilot(&ap, "t", 2).unwrap().instance, 2);
    for (r, what) in [
        (
            export_px4(
                &bm,
                &ExportOptions {
                    instance: 4,
                    ..o.clone()
                },
            )
            .map(|_| ()),
            "PX4 has instances 0..=3",
        ),
        (
            export_ardupilot(
                &bm,
                &ExportOptions {
                    instance: 3,
                    ..o.clone()
                },
            )
            .map(|_| ()),
            "ArduPilot has instances 0..=2",
        ),
    ] {
        let e = r.unwrap_err().to_string();
        assert!(e.contains(what), "{e}");
    }
}

/// Outside [TMIN, TMAX] both autopilots hold the end values, as the model's clamp policy
/// does; ArduPilot clamps CALTEMP too, which the export absorbs into the offsets when
/// T_ref lies outside the range.
#[test]
fn clamping_outside_the_range_matches_each_autopilot() {
    for t_ref in [25.0, 5.0] {
        let range = [10.0, 60.0];
        let f = adi_like_file(t_ref, range);
        let m = model_of(&f);
        let bm = BiasModel::from_model_file(&f, "t").unwrap();
        let o = ExportOptions::default();
        let px4 = parse_px4(&export_px4(&bm, &o).unwrap(), "t", 0).unwrap();
        let ap = parse_ardupilot(&export_ardupilot(&bm, &o).unwrap(), "t", 0).unwrap();
        let outside = [-40.0, 0.0, 9.99, 60.01, 85.0, 200.0];
        let e = compare_px4(&f, &m, &px4, &outside, false).unwrap();
        assert!(
            e.accel_f32 <= 1e-6 && e.gyro_f32 <= 1e-6,
            "PX4 {t_ref}: {e:?}"
        );
        let e = compare_ardupilot(&f, &m, &ap, &outside, false).unwrap();
        assert!(
            e.accel_f32 <= 1e-6 && e.gyro_f32 <= 1e-6,
            "AP {t_ref}: {e:?}"
        );
        // And the held value really is the end value (the evaluators clamp).
        let a = px4.accel.as_ref().unwrap();
        assert_eq!(a.offset(-40.0), a.offset(10.0));
        assert_eq!(a.offset(200.0), a.offset(60.0));
        assert_eq!(ap.correction(true, 200.0), ap.correction(true, 60.0));
        assert_ne!(ap.correction(true, 60.0), ap.correction(true, 59.0));
    }
    // A disabled triad corrects nothing (PX4 TC_A_ENABLE = 0, ArduPilot ENABLE = 2: learning).
    let f = adi_like_file(25.0, [-25.0, 70.0]);
    let bm = BiasModel::from_model_file(&f, "t").unwrap();
    let o = ExportOptions {
        include_offsets: false,
        ..ExportOptions::default()
    };
    let t = export_px4(&bm, &o)
        .unwrap()
        .replace("TC_A_ENABLE\t1\t6", "TC_A_ENABLE\t0\t6");
    let p = parse_px4(&t, "t", 0).unwrap();
    assert_eq!(p.accel.unwrap().offset(60.0), [0.0; 3]);
    assert_ne!(p.gyro.unwrap().offset(60.0), [0.0; 3]);
    let t = export_ardupilot(&bm, &o)
        .unwrap()
        .replace("INS_TCAL1_ENABLE,1", "INS_TCAL1_ENABLE,2");
    assert_eq!(
        parse_ardupilot(&t, "t", 0).unwrap().correction(true, 60.0),
        [0.0; 3]
    );
}

#[test]
fn orders_above_three_and_non_si_units_are_refused() {
    let mut f = adi_like_file(25.0, [-25.0, 70.0]);
    f.gyro.bias_delta[1] = vec![0.0, 1e-4, 0.0, 0.0, 1e-12];
    let e = BiasModel::from_model_file(&f, "t").unwrap_err().to_string();
    assert!(
        e.contains("[gyro] bias_delta[1] has order 4") && e.contains("refit with order 3"),
        "{e}"
    );
    // Trailing zeros are not an order.
    f.gyro.bias_delta[1] = vec![0.0, 1e-4, 0.0, 0.0, 0.0];
    assert!(BiasModel::from_model_file(&f, "t").is_ok());
    // Units: g and deg/s convert; a gyro model in m/s^2 is refused.
    let mut g = adi_like_file(25.0, [-25.0, 70.0]);
    g.accel.raw_unit = "g".into();
    let b = BiasModel::from_model_file(&g, "t").unwrap();
    assert!((b.accel.bias_si[0] - 0.15 * G).abs() < 1e-15);
    g.gyro.raw_unit = "m/s^2".into();
    let e = BiasModel::from_model_file(&g, "t").unwrap_err().to_string();
    assert!(e.contains("[gyro] raw_unit \"m/s^2\""), "{e}");
}

fn err_of(r: Result<impl std::fmt::Debug, AutopilotError>) -> String {
    r.unwrap_err().to_string()
}

#[test]
fn malformed_files_are_refused_with_file_line_and_column() {
    let f = adi_like_file(25.0, [-25.0, 70.0]);
    let bm = BiasModel::from_model_file(&f, "t").unwrap();
    let o = ExportOptions::default();
    let px4 = export_px4(&bm, &o).unwrap();
    let line_of = |text: &str, name: &str| {
        text.lines()
            .position(|l| l.contains(name))
            .map(|i| i + 1)
            .unwrap()
    };
    // A value that is not a number: file:line:column of the value.
    let l = line_of(&px4, "TC_A0_X1_1");
    let bad = px4.replacen(
        &format!(
            "TC_A0_X1_1\t{}",
            px4.lines().nth(l - 1).unwrap().split('\t').nth(3).unwrap()
        ),
        "TC_A0_X1_1\tabc",
        1,
    );
    assert_eq!(
        err_of(parse_px4(&bad, "v.params", 0)),
        format!("v.params:{l}:16: value \"abc\" is not a number")
    );
    // A missing field.
    let bad = px4.replace("TC_A0_TMIN\t-25\t9", "TC_A0_TMIN\t-25");
    let e = err_of(parse_px4(&bad, "v.params", 0));
    assert!(
        e.starts_with(&format!("v.params:{}:", line_of(&px4, "TC_A0_TMIN")))
            && e.contains("expected 5 fields"),
        "{e}"
    );
    // A wrong type code.
    let bad = px4.replace("TC_G0_TREF\t25\t9", "TC_G0_TREF\t25\t6");
    assert!(err_of(parse_px4(&bad, "v", 0)).contains("type must be 9 (REAL32), not 6"));
    // A removed scale parameter.
    let bad = format!("{px4}1\t1\tTC_A0_SCL_0\t1.0\t9\n");
    let e = err_of(parse_px4(&bad, "v", 0));
    assert!(
        e.contains("unknown parameter TC_A0_SCL_0")
            && e.contains("scale-factor terms have no place"),
        "{e}"
    );
    // A missing coefficient.
    let bad: String = px4
        .lines()
        .filter(|l| !l.contains("TC_G0_X3_2"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(
        err_of(parse_px4(&bad, "v", 0)),
        "v: missing required parameter TC_G0_X3_2"
    );
    // A duplicate.
    let bad = format!("{px4}1\t1\tTC_A0_X0_0\t0.5\t9\n");
    assert!(err_of(parse_px4(&bad, "v", 0)).contains("TC_A0_X0_0 given again"));
    // Foreign parameters are skipped and counted.
    let ok = format!("{px4}1\t1\tMPC_XY_VEL_MAX\t12.0\t9\n1\t1\tTC_A1_X0_0\t3\t9\n");
    assert_eq!(parse_px4(&ok, "v", 0).unwrap().ignored, 2);

    let ap = export_ardupilot(&bm, &o).unwrap();
    let l = line_of(&ap, "INS_TCAL1_GYR2_Y");
    let bad: String = ap
        .lines()
        .map(|x| {
            if x.starts_with("INS_TCAL1_GYR2_Y,") {
                "INS_TCAL1_GYR2_Y,1.5x # typo".to_string()
            } else {
                x.to_string()
            }
        })
        .map(|x| format!("{x}\n"))
        .collect();
    assert_eq!(
        err_of(parse_ardupilot(&bad, "a.param", 0)),
        format!("a.param:{l}:18: value \"1.5x\" is not a number")
    );
    let bad = ap.replace("INS_TCAL1_TMAX,70", "INS_TCAL1_TMAX,70,1");
    assert!(
        err_of(parse_ardupilot(&bad, "a", 0)).contains("expected `NAME,VALUE`, found 3 fields")
    );
    let bad: String = ap
        .lines()
        .filter(|l| !l.starts_with("INS_TCAL1_GYR3_Z"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(
        err_of(parse_ardupilot(&bad, "a", 0)),
        "a: missing required parameter INS_TCAL1_GYR3_Z"
    );
    let bad = format!("{ap}INS_TCAL1_ACC4_X,3\n");
    assert!(err_of(parse_ardupilot(&bad, "a", 0)).contains("unknown parameter INS_TCAL1_ACC4_X"));
    let bad = format!("{ap}INS_TCAL1_TMIN,nan\n");
    assert!(err_of(parse_ardupilot(&bad, "a", 0)).contains("is not finite"));
    let bad: String = ap
        .lines()
        .filter(|l| !l.starts_with("INS_ACCOFFS_Y"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(err_of(parse_ardupilot(&bad, "a", 0)).contains("give all three axes or none"));
    assert!(err_of(parse_ardupilot("FOO,1\n", "a", 0)).contains("no INS_TCAL1_* parameters"));
    // Mission Planner's other separators and trailing comments are read.
    let spaced = ap
        .replace(',', "\t")
        .replace("INS_TCAL1_TMIN\t-25", "INS_TCAL1_TMIN -25 # cold");
    assert_eq!(
        parse_ardupilot(&spaced, "a", 0).unwrap(),
        parse_ardupilot(&ap, "a", 0).unwrap()
    );
}

/// `docs/autopilot-thermal.md`'s worked example: its model, the parameter lines it shows
/// and the corrections it computes by hand at 45 °C, so the page cannot drift.
#[test]
fn worked_example_of_the_docs() {
    let doc = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/autopilot-thermal.md"),
    )
    .unwrap();
    let block = |marker: &str| -> String {
        let i = doc
            .find(marker)
            .unwrap_or_else(|| panic!("{marker} missing"));
        let rest = &doc[i..];
        let s = rest.find("```").unwrap();
        let body = &rest[s..];
        let nl = body.find('\n').unwrap();
        let e = body[nl..].find("```").unwrap();
        body[nl + 1..nl + e].to_string()
    };
    let f: ThermalModelFile = toml::from_str(&block("<!-- worked-example:model -->")).unwrap();
    let m = model_of(&f);
    let bm = BiasModel::from_model_file(&f, "doc").unwrap();
    let o = ExportOptions {
        px4_accel_id: 1_310_988,
        px4_gyro_id: 1_310_996,
        ..ExportOptions::default()
    };
    let px4 = export_px4(&bm, &o).unwrap();
    let ap = export_ardupilot(&bm, &o).unwrap();
    for (marker, text) in [
        ("<!-- worked-example:px4 -->", &px4),
        ("<!-- worked-example:ardupilot -->", &ap),
    ] {
        let shown = block(marker);
        assert!(shown.lines().count() >= 8);
        for line in shown.lines() {
            // The page shows PX4 lines with spaces for readability.
            let want = line.split_whitespace().collect::<Vec<_>>().join("\t");
            assert!(
                text.lines()
                    .any(|l| l == line
                        || l.split_whitespace().collect::<Vec<_>>().join("\t") == want),
                "{marker}: {line:?} not in the export:\n{text}"
            );
        }
    }
    // Hand computation at 45 °C: accel x 0.2 + 0.0728 m/s², gyro x 0.002 + 0.00076 rad/s.
    let p = parse_px4(&px4, "doc", 0).unwrap();
    let a = parse_ardupilot(&ap, "doc", 0).unwrap();
    let model = driftless::thermal::autopilot::model_bias_si(&f, &m, 45.0).unwrap();
    for (got, want) in [
        (model[0][0], 0.2728),
        (model[1][0], 0.00276),
        (p.accel.as_ref().unwrap().correction(45.0)[0], 0.2728),
        (p.gyro.as_ref().unwrap().correction(45.0)[0], 0.00276),
        (a.correction(true, 45.0)[0], 0.2728),
        (a.correction(false, 45.0)[0], 0.00276),
        (
            a.correction(true, 45.0)[0] - a.acc_offs.unwrap()[0] as f64,
            0.0728,
        ),
    ] {
        assert!((got - want).abs() < 1e-8, "{got} vs {want}");
    }
    for s in [
        "0.2728 m/s²",
        "0.00276 rad/s",
        "3630",
        "-17",
        "0.0347",
        "-0.0381",
    ] {
        assert!(doc.contains(s), "doc lost {s:?}");
    }
}
