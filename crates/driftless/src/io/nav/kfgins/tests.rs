use super::line::*;
use super::*;

const IMU: &str = "\
456300.000 1.0e-5 -2.0e-5 3.0e-5 0.001 -0.002 0.049
456300.005, 1.1e-5, -2.1e-5, 3.1e-5, 0.0011, -0.0021, 0.0491
\t456300.010\t1.2e-5\t-2.2e-5\t3.2e-5\t0.0012\t-0.0022\t0.0492\r
";

#[test]
fn imu_blocks_parse_as_one() {
    let mut text = String::new();
    for i in 0..200 {
        if i % 17 == 3 {
            text.push_str("  \n");
        }
        text.push_str(&format!(
            "{:.3} {} -2e-5 3e-5, 0.001 -0.002 0.049\n",
            100.0 + 0.005 * i as f64,
            1e-5 * i as f64
        ));
    }
    let whole = read_imu_in_blocks(text.as_bytes(), "i", 1 << 30).unwrap();
    for block in [1, 7, 64, 333] {
        let parts = read_imu_in_blocks(text.as_bytes(), "i", block).unwrap();
        assert_eq!(parts, whole, "block size {block}");
    }
    assert_eq!(whole.len(), 200);
    // Errors: the first in file order, whatever the block size; a time-order error
    // across a block boundary is found.
    let lines: Vec<&str> = text.lines().collect();
    let mut bad = lines.clone();
    bad[150] = "oops";
    let swapped_a = lines[60].to_string();
    let mut bad2 = lines.clone();
    bad2[60] = lines[61];
    bad2[61] = &swapped_a;
    for (t, want) in [(bad.join("\n"), "i:151:5"), (bad2.join("\n"), "i:62")] {
        let whole = read_imu_in_blocks(t.as_bytes(), "i", 1 << 30)
            .unwrap_err()
            .to_string();
        assert!(whole.contains(want), "{whole}");
        for block in [1, 7, 64, 333] {
            let e = read_imu_in_blocks(t.as_bytes(), "i", block)
                .unwrap_err()
                .to_string();
            assert_eq!(e, whole, "block size {block}");
        }
    }
}

/// The file reader's chunks of whole lines give the in-memory result and errors
/// (line numbers included) whatever the chunk size.
#[test]
fn imu_fast_rows_agree_with_the_field_reader() {
    let rows = [
        "456300.005 1.0e-5 -2.0e-5 3.0e-5 0.001 -0.002 0.049",
        "  456300.005,\t1.1e-5, -2.1e-5 ,3.1e-5,0.0011,-0.0021,+0.0491\r",
        "1 2 3 4 5 6 7",
        "0.1234567890123456789 2 3 4 5 6 7",
        "1e400 2 3 4 5 6 7",
        "1 2 3 4 5 6",
        "1 2 3 4 5 6 7 8",
        "1 2 3 4 5x 6 7",
        "1 2 3 4 5 6 nan",
        "1 2 3 4 5 6 .5",
        "1 2 3 4 5 6 7.",
        "1 2 3 4 5 6 1e-3",
    ];
    let mut fields = Vec::new();
    let mut fast_rows = 0;
    for l in rows {
        let general = parse_imu_row(l, 1, 7, 1, "imu", None, &mut fields).ok();
        match imu_row_fast(l) {
            Some(v) => {
                fast_rows += 1;
                assert_eq!(
                    Some(v.map(f64::to_bits)),
                    general.map(|g| g.map(f64::to_bits)),
                    "{l}"
                );
            }
            // Not taken: the field reader decides (value or error).
            None => assert!(!matches!(l, "1 2 3 4 5 6 7" | "1 2 3 4 5 6 1e-3"), "{l}"),
        }
    }
    assert!(fast_rows >= 6);
}

#[test]
fn imu_reads_all_separators() {
    let imu = read_kfgins_imu(IMU.as_bytes(), "imu.txt").unwrap();
    assert_eq!(imu.len(), 3);
    assert_eq!(imu.time_s, vec![456300.0, 456300.005, 456300.010]);
    assert_eq!(imu.dtheta_rad[1], [1.1e-5, -2.1e-5, 3.1e-5]);
    assert_eq!(imu.dvel_m_s[2], [0.0012, -0.0022, 0.0492]);
}

#[test]
fn imu_eight_columns_ok_but_ragged_rejected() {
    let ok = "1 0 0 0 0 0 0 5.0\n2 0 0 0 0 0 0 5.1\n";
    assert_eq!(read_kfgins_imu(ok.as_bytes(), "i").unwrap().len(), 2);
    let extra = "1 0 0 0 0 0 0\n2 0 0 0 0 0 0 9\n3 0 0 0 0 0 0\n";
    let e = read_kfgins_imu(extra.as_bytes(), "i").unwrap_err();
    assert!(
        matches!(
            e,
            LogError::Ragged {
                found: 8,
                expected: 7,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        "i:2:15: row has 8 fields, expected 7 (as on line 1)"
    );
    let missing = "1 0 0 0 0 0 0\n2 0 0 0 0 0\n3 0 0 0 0 0 0\n";
    let e = read_kfgins_imu(missing.as_bytes(), "i").unwrap_err();
    assert!(matches!(e, LogError::Ragged { found: 6, .. }), "{e}");
    assert_eq!(e.line(), Some(2));
    // Too few columns for the format: the message names what it needs, not a line as
    // its own reference.
    let short = "1 0 0 0 0 0\n2 0 0 0 0 0\n";
    let e = read_kfgins_imu(short.as_bytes(), "i").unwrap_err();
    assert!(matches!(e, LogError::Malformed { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        "i:1:12: malformed KF-GINS IMU: rows have 6 fields; the format needs at least 7 (time, Δθ x y z, Δv x y z)"
    );
}

#[test]
fn imu_cut_edge_records_dropped_with_notes() {
    let whole: Vec<String> = (0..6)
        .map(|i| format!("{}.005 1e-5 -2e-5 3e-5 0.001 0.002 -0.0981", 100 + i))
        .collect();
    let clean = read_kfgins_imu(whole.join("\n").as_bytes(), "i").unwrap();
    assert!(clean.notes.is_empty());
    // Cut at the start (inside the time) and at the end (inside the last field).
    let mut cut = whole.clone();
    cut[0] = "5e-5 3e-5 0.001 0.002 -0.0981".into();
    cut[5] = "105.005 1e-5 -2e-5 3e-5 0.001 0.0".into();
    for block in [1 << 20, 40] {
        let r = read_imu_in_blocks(cut.join("\n").as_bytes(), "i", block).unwrap();
        assert_eq!(r.time_s, clean.time_s[1..5].to_vec());
        assert_eq!(r.dvel_m_s, clean.dvel_m_s[1..5].to_vec());
        assert_eq!(r.notes.len(), 2, "{:?}", r.notes);
        assert!(
            r.notes[0].starts_with("i:1: dropped the first record \"5e-5")
                && r.notes[0].ends_with("it has 5 fields, line 2 has 7"),
            "{}",
            r.notes[0]
        );
        assert!(
            r.notes[1].starts_with("i:6: dropped the last record")
                && r.notes[1].ends_with("it has 6 fields, line 2 has 7"),
            "{}",
            r.notes[1]
        );
    }
    // A last field cut to a non-number ("1.5e") is a cut record too.
    let mut num = whole.clone();
    num[5] = "105.005 1e-5 -2e-5 3e-5 0.001 0.002 -9.8e".into();
    let r = read_kfgins_imu(num.join("\n").as_bytes(), "i").unwrap();
    assert_eq!(r.len(), 5);
    assert!(
        r.notes[0].ends_with("its field 7 is not a number"),
        "{:?}",
        r.notes
    );
    // The same bad row inside the file is an error, and so is a second short row
    // after a dropped first one, citing a good reference line.
    let mut mid = whole.clone();
    mid[3] = "103.005 1e-5 -2e-5".into();
    let e = read_kfgins_imu(mid.join("\n").as_bytes(), "i").unwrap_err();
    assert_eq!(
        e.to_string(),
        "i:4:19: row has 3 fields, expected 7 (as on line 1)"
    );
    let mut two = whole.clone();
    two[0] = "1e-5 0.002 -0.0981".into();
    two[1] = "0.002 -0.0981".into();
    let e = read_kfgins_imu(two.join("\n").as_bytes(), "i").unwrap_err();
    assert_eq!(
        e.to_string(),
        "i:2:14: row has 2 fields, expected 7 (as on line 3)"
    );
    // A first row with more fields than the next ones is no cut record: an error at
    // line 2 citing line 1, as before.
    let mut long = whole;
    long[0].push_str(" 5.0");
    let e = read_kfgins_imu(long.join("\n").as_bytes(), "i").unwrap_err();
    assert!(e.to_string().starts_with("i:2:"), "{e}");
    assert!(e.to_string().ends_with("(as on line 1)"), "{e}");
}

#[test]
fn imu_non_numeric_and_non_finite() {
    let bad = "1 0 0 0 0 0 0\n2 0 abc 0 0 0 0\n";
    let e = read_kfgins_imu(bad.as_bytes(), "imu.txt").unwrap_err();
    assert_eq!(
        e.to_string(),
        "imu.txt:2:5: non-numeric value \"abc\" in column 3 (dtheta_y_rad)"
    );
    let nan = "1 0 0 0 0 0 nan\n";
    assert!(matches!(
        read_kfgins_imu(nan.as_bytes(), "i").unwrap_err(),
        LogError::NonFinite { field: 7, .. }
    ));
    assert!(matches!(
        read_kfgins_imu(b"\n\n", "i").unwrap_err(),
        LogError::Empty { .. }
    ));
}

#[test]
fn imu_time_order() {
    let dup = "1 0 0 0 0 0 0\n1 0 0 0 0 0 0\n";
    let e = read_kfgins_imu(dup.as_bytes(), "i").unwrap_err();
    assert!(
        matches!(e, LogError::DuplicateTime { time_s: 1.0, .. }),
        "{e}"
    );
    assert_eq!(e.line(), Some(2));
    let back = "1 0 0 0 0 0 0\n2 0 0 0 0 0 0\n\n1.5 0 0 0 0 0 0\n";
    let e = read_kfgins_imu(back.as_bytes(), "i").unwrap_err();
    assert!(matches!(e, LogError::NonMonotonicTime { .. }), "{e}");
    assert_eq!(e.line(), Some(4));
}

const GNSS7: &str = "\
456250.000    30.4447858054   114.4718661162     21.095    0.010    0.009    0.019
456251.000    30.4447857891   114.4718661133     21.091    0.011    0.008    0.020
";

#[test]
fn gnss_seven_columns() {
    let g = read_kfgins_gnss(GNSS7.as_bytes(), "g", &GnssReadOptions::default()).unwrap();
    assert_eq!(g.len(), 2);
    assert!((g.lat_rad[0] - 30.4447858054f64.to_radians()).abs() < 1e-15);
    assert!((g.lon_rad[1] - 114.4718661133f64.to_radians()).abs() < 1e-15);
    assert_eq!(g.height_m, vec![21.095, 21.091]);
    assert_eq!(g.sigma_ned_m[1], [0.011, 0.008, 0.020]);
    assert!(g.vel_ned_m_s.is_none() && g.n_sats.is_none() && g.gps_week.is_none());
    assert_eq!(g.quality, vec![0, 0]);
}

#[test]
fn gnss_thirteen_columns() {
    let t = "10 30 114 20 1.0 -2.0 0.5 0.01 0.02 0.03 0.1 0.2 0.3\n\
             11 30 114 20 1.1 -2.1 0.6 0.01 0.02 0.03 0.1 0.2 0.3\n";
    let g = read_kfgins_gnss(t.as_bytes(), "g", &GnssReadOptions::default()).unwrap();
    assert_eq!(g.vel_ned_m_s.as_ref().unwrap()[1], [1.1, -2.1, 0.6]);
    assert_eq!(g.sigma_ned_m[0], [0.01, 0.02, 0.03]);
    assert_eq!(g.sigma_vel_ned_m_s.as_ref().unwrap()[0], [0.1, 0.2, 0.3]);
    // 8 columns: neither format.
    let e =
        read_kfgins_gnss(b"1 30 114 20 1 1 1 1\n", "g", &GnssReadOptions::default()).unwrap_err();
    assert!(matches!(e, LogError::Malformed { .. }), "{e}");
    assert!(e.to_string().contains("rows have 8 fields"), "{e}");
    // A missing column on line 2.
    let t = "1 30 114 20 1 1 1\n2 30 114 20 1 1\n3 30 114 20 1 1 1\n";
    let e = read_kfgins_gnss(t.as_bytes(), "g", &GnssReadOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            LogError::Ragged {
                found: 6,
                expected: 7,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn gnss_cut_edges() {
    let opts = GnssReadOptions::default();
    let rows = [
        "114.4718661162 21.095 0.010 0.009 0.019",
        "456251.000 30.44478 114.47186 21.091 0.011 0.008 0.020",
        "456252.000 30.44478 114.47186 21.091 0.011 0.008 0.020",
        "456253.000 30.44478 114.4",
    ];
    let g = read_kfgins_gnss(rows.join("\n").as_bytes(), "g.txt", &opts).unwrap();
    assert_eq!(g.time_s, vec![456_251.0, 456_252.0]);
    assert_eq!(g.notes.len(), 2);
    assert!(g.notes[0].starts_with("g.txt:1: dropped the first record"));
    assert!(g.notes[1].starts_with("g.txt:4: dropped the last record"));
    // A short first row of a file whose other rows are 13 wide: reference is line 2.
    let t = "1 30 114 20 1 1 1\n2 30 114 20 1 1 1 0.1 0.1 0.1 0.1 0.1 0.1\n3 30 114 20 1 1 1 0.1 0.1 0.1 0.1 0.1 0.1\n";
    let g = read_kfgins_gnss(t.as_bytes(), "g", &opts).unwrap();
    assert_eq!(g.len(), 2);
    assert!(g.vel_ned_m_s.is_some());
    assert!(
        g.notes[0].ends_with("it has 7 fields, line 2 has 13"),
        "{:?}",
        g.notes
    );
}

#[test]
fn gnss_sigma_zero_and_ranges() {
    let t = "1 30 114 20 0.01 0 0.02\n";
    let e = read_kfgins_gnss(t.as_bytes(), "g.txt", &GnssReadOptions::default()).unwrap_err();
    assert!(matches!(e, LogError::InvalidValue { .. }), "{e}");
    assert!(
        e.to_string()
            .starts_with("g.txt:1:18: standard deviation 0"),
        "{e}"
    );
    let floor = GnssReadOptions {
        zero_sigma: ZeroSigma::Floor {
            pos_m: 0.005,
            vel_m_s: 0.01,
        },
    };
    let g = read_kfgins_gnss(t.as_bytes(), "g", &floor).unwrap();
    assert_eq!(g.sigma_ned_m[0], [0.01, 0.005, 0.02]);
    let neg = "1 30 114 20 0.01 -0.1 0.02\n";
    assert!(read_kfgins_gnss(neg.as_bytes(), "g", &floor).is_err());
    let lat = "1 95 114 20 0.01 0.01 0.02\n";
    let e = read_kfgins_gnss(lat.as_bytes(), "g", &floor).unwrap_err();
    assert_eq!(e.to_string(), "g:1:3: latitude 95 deg outside [-90, 90]");
    let dup = "1 30 114 20 1 1 1\n1 30 114 20 1 1 1\n";
    assert!(matches!(
        read_kfgins_gnss(dup.as_bytes(), "g", &floor).unwrap_err(),
        LogError::DuplicateTime { .. }
    ));
}

fn nav_fixture() -> NavSolution {
    NavSolution {
        time_s: vec![456300.005, 456300.010],
        lat_rad: vec![30.5f64.to_radians(), 30.25f64.to_radians()],
        lon_rad: vec![114.5f64.to_radians(), -114.5f64.to_radians()],
        height_m: vec![20.9, -3.5],
        vel_ned_m_s: vec![[0.1, -0.2, 0.3], [0.0, 0.0, -0.0]],
        roll_pitch_yaw_rad: vec![
            [1f64.to_radians(), -2f64.to_radians(), 185f64.to_radians()],
            [0.0, 0.0, -90f64.to_radians()],
        ],
    }
}

#[test]
fn nav_writer_matches_kfgins_layout() {
    let mut out = Vec::new();
    write_kfgins_nav(&mut out, "nav", &nav_fixture(), 0).unwrap();
    let text = String::from_utf8(out).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2);
    // Every field is padded to 15 characters and followed by one space; the time
    // (16 digits) overflows its field as C's printf does: 11 × 16 + 1 characters.
    assert_eq!(lines[0].len(), 11 * 16 + 1);
    assert!(lines[0].starts_with("0.000000000     456300.005000000 30.500000000    "));
    let f: Vec<f64> = lines[1]
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    assert_eq!(f.len(), 11);
    assert_eq!(f[2], 30.25);
    assert_eq!(f[3], -114.5);
    assert_eq!(f[4], -3.5);
    assert!((f[10] + 90.0).abs() < 1e-9);
    // Mismatched lengths and NaN are refused.
    let mut bad = nav_fixture();
    bad.height_m.pop();
    assert!(matches!(
        write_kfgins_nav(Vec::new(), "nav", &bad, 0).unwrap_err(),
        LogError::InvalidLog { .. }
    ));
    let mut bad = nav_fixture();
    bad.height_m[1] = f64::NAN;
    assert!(write_kfgins_nav(Vec::new(), "nav", &bad, 0).is_err());
}

#[test]
fn imu_err_and_std_writers_convert_units() {
    let d2r = 1f64.to_radians();
    let e = ImuErrors {
        time_s: vec![10.0],
        gyro_bias_rad_s: vec![[d2r / 3600.0, 2.0 * d2r / 3600.0, 0.0]],
        accel_bias_m_s2: vec![[1e-5, 0.0, -5e-4]],
        gyro_scale: vec![[1e-6, 0.0, 0.0]],
        accel_scale: vec![[0.0, -3e-4, 0.0]],
    };
    let mut out = Vec::new();
    write_kfgins_imu_err(&mut out, "e", &e).unwrap();
    let f: Vec<f64> = String::from_utf8(out)
        .unwrap()
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    let want = [
        10.0, 1.0, 2.0, 0.0, 1.0, 0.0, -50.0, 1.0, 0.0, 0.0, 0.0, -300.0, 0.0,
    ];
    assert_eq!(f.len(), 13);
    for (a, b) in f.iter().zip(want) {
        assert!((a - b).abs() < 1e-8, "{f:?}");
    }
    let s = NavStd {
        time_s: vec![10.0],
        pos_ned_m: vec![[0.1, 0.2, 0.3]],
        vel_ned_m_s: vec![[0.01, 0.02, 0.03]],
        att_rad: vec![[d2r, 0.0, 2.0 * d2r]],
        gyro_bias_rad_s: vec![[d2r / 3600.0; 3]],
        accel_bias_m_s2: vec![[1e-5; 3]],
        gyro_scale: vec![[1e-6; 3]],
        accel_scale: vec![[2e-6; 3]],
    };
    let mut out = Vec::new();
    write_kfgins_std(&mut out, "s", &s).unwrap();
    let f: Vec<f64> = String::from_utf8(out)
        .unwrap()
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    assert_eq!(f.len(), 22);
    assert!((f[7] - 1.0).abs() < 1e-9 && (f[9] - 2.0).abs() < 1e-9);
    assert!((f[10] - 1.0).abs() < 1e-9 && (f[13] - 1.0).abs() < 1e-9);
    assert!((f[16] - 1.0).abs() < 1e-9 && (f[21] - 2.0).abs() < 1e-9);
}

#[test]
fn outputs_round_trip_through_the_reader_layouts() {
    let dir = std::env::temp_dir().join(format!("driftless-navio-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sol = nav_fixture();
    let e = ImuErrors {
        time_s: sol.time_s.clone(),
        gyro_bias_rad_s: vec![[0.0; 3]; 2],
        accel_bias_m_s2: vec![[0.0; 3]; 2],
        gyro_scale: vec![[0.0; 3]; 2],
        accel_scale: vec![[0.0; 3]; 2],
    };
    let s = NavStd {
        time_s: sol.time_s.clone(),
        pos_ned_m: vec![[1.0; 3]; 2],
        vel_ned_m_s: vec![[1.0; 3]; 2],
        att_rad: vec![[1.0; 3]; 2],
        gyro_bias_rad_s: vec![[1.0; 3]; 2],
        accel_bias_m_s2: vec![[1.0; 3]; 2],
        gyro_scale: vec![[1.0; 3]; 2],
        accel_scale: vec![[1.0; 3]; 2],
    };
    let paths = write_kfgins_outputs(&dir, &sol, &e, &s, 2374).unwrap();
    assert!(paths[0].ends_with("KF_GINS_Navresult.nav"));
    assert!(paths[1].ends_with("KF_GINS_IMU_ERR.txt"));
    assert!(paths[2].ends_with("KF_GINS_STD.txt"));
    let nav = std::fs::read_to_string(&paths[0]).unwrap();
    assert!(nav.starts_with("2374.000000000  456300.005000000"));
    let cols: Vec<usize> = [&paths[1], &paths[2]]
        .iter()
        .map(|p| {
            let t = std::fs::read_to_string(p).unwrap();
            t.lines().next().unwrap().split_whitespace().count()
        })
        .collect();
    assert_eq!(cols, vec![13, 22]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Rows with values on both paths of the formatter: small, negative, ≥ 1e8 (the
/// standard formatter), near ties.
fn mixed_rows(n: usize) -> (NavSolution, ImuErrors, NavStd) {
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut next = |i: usize| {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let u = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        match i % 4 {
            0 => u * 1e-3,
            1 => u * 3e9,
            2 => (u * 2e6).round() * 0.5e-9,
            _ => u * 200.0,
        }
    };
    let mut k = 0;
    let mut tri = || {
        k += 1;
        [next(k), next(k + 1), next(k + 2)]
    };
    let mut sol = NavSolution::default();
    let mut e = ImuErrors::default();
    let mut sd = NavStd::default();
    for i in 0..n {
        let t = 456_300.0 + i as f64 * 0.005;
        let [a, b, c] = tri();
        sol.push_epoch(t, a, b, c, tri(), tri());
        e.time_s.push(t);
        e.gyro_bias_rad_s.push(tri());
        e.accel_bias_m_s2.push(tri());
        e.gyro_scale.push(tri());
        e.accel_scale.push(tri());
        sd.time_s.push(t);
        sd.pos_ned_m.push(tri());
        sd.vel_ned_m_s.push(tri());
        sd.att_rad.push(tri());
        sd.gyro_bias_rad_s.push(tri());
        sd.accel_bias_m_s2.push(tri());
        sd.gyro_scale.push(tri());
        sd.accel_scale.push(tri());
    }
    (sol, e, sd)
}

#[test]
fn line_buffer_matches_the_standard_formatter_and_refuses_non_finite() {
    let (_, _, sd) = mixed_rows(300);
    let mut buf = LineBuf::new();
    let mut want = String::new();
    for i in 0..300 {
        let v = std_row(&sd, i).std_values();
        buf.line(&v).unwrap();
        for x in v {
            want.push_str(&format!("{x:<15.9} "));
        }
        want.push('\n');
    }
    assert_eq!(std::str::from_utf8(&buf.buf[..buf.pos]).unwrap(), want);
    // Both paths of the formatter were taken.
    let big = (0..300).flat_map(|i| std_row(&sd, i).std_values());
    assert!(big.filter(|v| v.abs() >= 1e8).count() > 100);
    let before = buf.pos;
    let mut bad = std_row(&sd, 0).std_values();
    bad[5] = f64::NAN;
    assert_eq!(buf.line(&bad), Err(5));
    bad[2] = f64::NEG_INFINITY;
    assert_eq!(buf.line(&bad), Err(2));
    assert_eq!(buf.pos, before);
}

#[test]
fn row_writer_matches_the_column_writers_and_replaces_old_files() {
    let dir = std::env::temp_dir().join(format!("driftless-rows-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // An earlier, longer run's files: nothing of them may remain.
    for f in output_file_names("") {
        std::fs::write(dir.join(f), vec![b'x'; 3 << 20]).unwrap();
    }
    // More rows than one chunk of the std file holds.
    let n = 13_000;
    let (sol, e, sd) = mixed_rows(n);
    let mut w = KfGinsOutputWriter::create(&dir, 7).unwrap();
    for i in 0..n {
        let row = KfGinsRow {
            lat_rad: sol.lat_rad[i],
            lon_rad: sol.lon_rad[i],
            height_m: sol.height_m[i],
            vel_ned_m_s: sol.vel_ned_m_s[i],
            roll_pitch_yaw_rad: sol.roll_pitch_yaw_rad[i],
            gyro_bias_rad_s: e.gyro_bias_rad_s[i],
            accel_bias_m_s2: e.accel_bias_m_s2[i],
            gyro_scale: e.gyro_scale[i],
            accel_scale: e.accel_scale[i],
            ..std_row(&sd, i)
        };
        w.append_row(&row).unwrap();
    }
    let paths = w.finish().unwrap();
    let mut want = [Vec::new(), Vec::new(), Vec::new()];
    write_kfgins_nav(&mut want[0], "nav", &sol, 7).unwrap();
    write_kfgins_imu_err(&mut want[1], "err", &e).unwrap();
    write_kfgins_std(&mut want[2], "std", &sd).unwrap();
    assert!(want[2].len() > CHUNK);
    for (p, want) in paths.iter().zip(&want) {
        assert!(std::fs::read(p).unwrap() == *want, "{}", p.display());
    }
    // A value that is not finite names the file, row and column.
    let mut w = KfGinsOutputWriter::create(&dir, 0).unwrap();
    let row = nav_row(&sol, 0);
    w.append_row(&row).unwrap();
    let bad = KfGinsRow {
        std_vel_ned_m_s: [0.0, f64::INFINITY, 0.0],
        ..row
    };
    let msg = w.append_row(&bad).unwrap_err().to_string();
    assert!(
        msg.contains("KF_GINS_STD.txt") && msg.contains("row 1, column 6"),
        "{msg}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[ignore = "needs shared data"]
fn wuhan_kfgins_gnss_file() {
    let dir = std::env::var("DRIFTLESS_DATA").map_or_else(
        |_| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
        PathBuf::from,
    );
    let g = read_kfgins_gnss_file(
        dir.join("trajectories/kfgins_wuhan_gnss_rtk_1hz.txt"),
        &GnssReadOptions::default(),
    )
    .unwrap();
    assert_eq!(g.len(), 3413);
    assert_eq!(g.time_s[0], 456_250.0);
    assert_eq!(g.sigma_ned_m[0], [0.010, 0.009, 0.019]);
    assert!((g.lat_rad[0].to_degrees() - 30.4447858054).abs() < 1e-10);
    assert!(g.vel_ned_m_s.is_none());
}
