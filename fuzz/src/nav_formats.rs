//! Arbitrary bytes into the navigation and simulation readers: KF-GINS IMU and GNSS text,
//! RTKLIB `.pos`, KF-GINS YAML, scenario and calibration TOML (parsed, not run), the text
//! reader with truncated-edge dropping and a week column, the tagged-CSV path, and the IMU
//! time bases on arbitrary stamps.
//! Invariants: no panic; errors name the input; parsed numbers are finite; at most two
//! notes (first and last record), each naming the input; times strictly increasing.

use driftless::io::nav::{
    FposSize, GnssReadOptions, KfGinsConfig, TimeBase, read_kfgins_gnss, read_kfgins_imu,
    read_rtklib_pos, read_rtklib_tag,
};
use driftless::io::{ColumnRef, GapPolicy, TextOptions, read_text_bytes};
use driftless::nav::pipeline::{
    ImuStreamOptions, TaggedCsvOptions, imu_from_tagged_csv, rates_to_stream,
};

fn notes_ok(notes: &[String]) {
    assert!(notes.len() <= 2, "{notes:?}");
    assert!(notes.iter().all(|n| n.starts_with("fuzz:")), "{notes:?}");
}

fn increasing(t: &[f64]) {
    assert!(t.iter().all(|v| v.is_finite()));
    assert!(t.windows(2).all(|w| w[1] > w[0]));
}

/// A `.tag` file: header, start 2025-07-08 19:34:21 GPST, records (0, 0) and (1000, 100).
fn tag() -> Vec<u8> {
    let mut b = b"TIMETAG RTKLIB demo5".to_vec();
    b.resize(60, 0);
    b.extend_from_slice(&0u32.to_le_bytes());
    b.extend_from_slice(&1_752_003_261u32.to_le_bytes());
    b.extend_from_slice(&0.5f64.to_le_bytes());
    for (t, p) in [(0u32, 0u32), (1000, 100)] {
        b.extend_from_slice(&t.to_le_bytes());
        b.extend_from_slice(&p.to_le_bytes());
    }
    b
}

/// One fuzz input; panics on a broken invariant.
pub fn run(data: &[u8]) {
    let (sel, body) = match data.split_first() {
        Some((s, b)) => (*s, b),
        None => (0, data),
    };
    match sel % 10 {
        0 => match read_kfgins_imu(body, "fuzz") {
            Ok(imu) => {
                increasing(&imu.time_s);
                notes_ok(&imu.notes);
            }
            Err(e) => assert!(e.to_string().starts_with("fuzz")),
        },
        1 => match read_kfgins_gnss(body, "fuzz", &GnssReadOptions::default()) {
            Ok(g) => {
                assert!(g.sigma_ned_m.iter().flatten().all(|s| *s > 0.0));
                notes_ok(&g.notes);
            }
            Err(e) => assert!(e.to_string().starts_with("fuzz")),
        },
        2 => match read_rtklib_pos(body, "fuzz", &GnssReadOptions::default()) {
            Ok(g) => {
                assert!(g.lat_rad.iter().all(|v| v.is_finite()));
                notes_ok(&g.notes);
            }
            Err(e) => assert!(e.to_string().starts_with("fuzz")),
        },
        6 | 7 => {
            // Text reader, edge dropping on; 7 adds a week column (field 1, seconds in 2).
            let mut o = TextOptions {
                drop_truncated_edges: true,
                gap_policy: GapPolicy::Bridge,
                chunk_bytes: 64 + usize::from(sel) * 7,
                ..TextOptions::default()
            };
            if sel % 10 == 7 {
                o = o
                    .with_time(ColumnRef::Index(2), None)
                    .with_week_column(ColumnRef::Index(1));
            } else {
                o = o.with_time(ColumnRef::Index(1), None);
            }
            match read_text_bytes(body, "fuzz", &o) {
                Ok(log) => {
                    notes_ok(&log.notes);
                    increasing(log.time_s.as_deref().unwrap_or(&[]));
                    assert_eq!(log.week.is_some(), sel % 10 == 7);
                }
                Err(e) => assert!(e.to_string().starts_with("fuzz")),
            }
        }
        8 => {
            let Ok(t) = read_rtklib_tag(&tag(), "t.tag", FposSize::Auto) else {
                panic!("fixture tag")
            };
            match imu_from_tagged_csv(body, "fuzz", &t, &TaggedCsvOptions::default()) {
                Ok(s) => {
                    notes_ok(&s.notes);
                    let t: Vec<f64> = s.epochs.iter().map(|e| e.time_s).collect();
                    increasing(&t);
                    assert_eq!(s.gps_week, Some(2374));
                }
                Err(e) => assert!(e.to_string().starts_with("fuzz"), "{e}"),
            }
        }
        9 => {
            // Arbitrary stamps in each time base, as 8-byte floats.
            let t: Vec<f64> = body
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
                .collect();
            let zeros = vec![0.0; t.len()];
            let z = zeros.as_slice();
            for base in [
                TimeBase::GpsSecondsOfWeek,
                TimeBase::GpsWeekAndSeconds,
                TimeBase::GpstUnix,
                TimeBase::UtcUnix,
            ] {
                if let Ok((_, g)) = base.to_gps_week_seconds(&t, Some(2000)) {
                    assert_eq!(g.len(), t.len());
                }
                let week = (!base.is_absolute()).then_some(2000);
                let opts = ImuStreamOptions {
                    time_base: base,
                    ..ImuStreamOptions::default()
                };
                match rates_to_stream("fuzz", week, &t, [z, z, z], [z, z, z], &opts) {
                    Ok(s) => {
                        let ts: Vec<f64> = s.epochs.iter().map(|e| e.time_s).collect();
                        increasing(&ts);
                        if base.is_absolute() {
                            assert!(s.gps_week.is_some());
                            assert!(ts.first().is_some_and(|&v| (0.0..604_800.0).contains(&v)));
                        }
                    }
                    Err(e) => assert!(
                        e.to_string().contains("fuzz")
                            || e.to_string().starts_with("invalid option"),
                        "{e}"
                    ),
                }
            }
        }
        3 => {
            if let Ok(text) = std::str::from_utf8(body)
                && let Err(e) = KfGinsConfig::from_yaml_str(text, "fuzz")
            {
                assert!(e.to_string().starts_with("fuzz"));
            }
        }
        4 => {
            if let Ok(text) = std::str::from_utf8(body)
                && let Err(e) = driftless::sim::scenario::Scenario::from_toml_str(text, "fuzz")
            {
                assert!(e.to_string().starts_with("fuzz"));
            }
        }
        _ => {
            if let Ok(text) = std::str::from_utf8(body)
                && let Err(e) =
                    driftless::calib::model_file::CalibrationFile::from_toml_str(text, "fuzz")
            {
                assert!(e.to_string().starts_with("fuzz"));
            }
        }
    }
}
