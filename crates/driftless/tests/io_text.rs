//! Text reader: real reference files, format variants, and one test per error case.

use std::path::PathBuf;

use driftless::io::{
    ColumnRef, ColumnSpec, Delimiter, GapPolicy, HeaderMode, LogError, Quantity, TextOptions,
    TimeUnit, Unit, read_text, read_text_bytes, read_text_file, write_csv,
};

/// Shared reference data: `$DRIFTLESS_DATA`, else `../shared/data` beside the project.
fn data(rel: &str) -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
    .join(rel)
}

fn rate(hz: f64) -> TextOptions {
    TextOptions::default().with_rate_hz(hz)
}

fn timed() -> TextOptions {
    TextOptions::default().with_time(ColumnRef::Index(1), None)
}

fn err(text: &str, opts: &TextOptions) -> LogError {
    match read_text_bytes(text.as_bytes(), "mem.csv", opts) {
        Ok(log) => panic!("expected an error, got {} rows", log.len()),
        Err(e) => e,
    }
}

// ---- real files ------------------------------------------------------------------------

/// allantools/Stable32 test vector (allan/ocxo): single column with `#` comments.
#[test]
#[ignore = "needs shared data"]
fn allantools_ocxo_single_column_with_comments() {
    let path = data("allan/ocxo/ocxo_frequency.txt");
    let text = std::fs::read_to_string(&path).unwrap();
    let expected: Vec<f64> = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|l| l.trim().parse().unwrap())
        .collect();
    let log = read_text_file(&path, &rate(1.0)).unwrap();
    assert_eq!(log.channels.len(), 1);
    assert_eq!(log.channels[0].name, "col1");
    assert_eq!(log.channels[0].quantity, Quantity::Other);
    assert_eq!(log.channels[0].values, expected);
    assert_eq!(log.len(), 19_982);
    assert_eq!(log.tau0_s, 1.0);
    assert_eq!(log.segments, vec![0..19_982]);
    assert!(log.time_s.is_none());
}

/// NBS14 PHASE.DAT: CRLF line ends and comment lines.
#[test]
#[ignore = "needs shared data"]
fn phase_dat_crlf() {
    let log = read_text_file(data("allan/phasedat/PHASE.DAT"), &rate(1.0)).unwrap();
    assert_eq!(log.len(), 1001);
    assert_eq!(log.channels[0].values[0], 0.0);
    assert!(log.channels[0].values.iter().all(|v| v.is_finite()));
}

/// imu_tk Xsens recording: whitespace `t x y z` in raw counts, 100 Hz.
#[test]
#[ignore = "needs shared data"]
fn imu_tk_xsens_whitespace_with_time_and_counts() {
    let path = data("calib/imu_tk_xsens/xsens_gyro.txt");
    let unit: Unit = "counts-32768/6258rad/s".parse().unwrap();
    let opts = timed()
        .with_names(["t", "x", "y", "z"])
        .with_column(ColumnRef::Name("x".into()), Some(unit.clone()))
        .with_column(ColumnRef::Index(3), Some(unit.clone()))
        .with_column(ColumnRef::Name("Z".into()), Some(unit.clone()));
    let log = read_text_file(&path, &opts).unwrap();
    assert_eq!(log.len(), 51_175);
    let t = log.time_s.as_ref().unwrap();
    assert_eq!(t.len(), 51_175);
    assert!((log.tau0_s - 0.01).abs() < 1e-4, "tau0 {}", log.tau0_s);
    assert_eq!(log.channels[0].quantity, Quantity::AngularRate);
    assert_eq!(log.channels[2].name, "z");
    // first row in the file, converted by hand
    let first = std::fs::read_to_string(&path).unwrap();
    let f: Vec<f64> = first
        .lines()
        .next()
        .unwrap()
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    assert_eq!(t[0], f[0]);
    assert!((log.channels[0].values[0] - (f[1] - 32768.0) / 6258.0).abs() < 1e-12);
    assert!((log.channels[1].values[0] - (f[2] - 32768.0) / 6258.0).abs() < 1e-12);
}

/// rtklibexplorer GNSS_IMU drive: headerless CSV `acc[g] x3, gyr[deg/s] x3, tick[ms]`.
#[test]
#[ignore = "needs shared data"]
fn rtklib_drive_csv_ms_ticks() {
    let path = data("drive/drive_0708/imu_1934.csv");
    let mut opts = TextOptions::default()
        .with_time(ColumnRef::Name("tick".into()), Some(TimeUnit::Milliseconds))
        .with_names(["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z", "tick"])
        .with_rate_hz(100.0);
    opts.rate_tolerance = 0.05;
    for n in ["acc_x", "acc_y", "acc_z"] {
        opts.columns.push(ColumnSpec {
            column: ColumnRef::Name(n.into()),
            unit: Some("g".parse().unwrap()),
            rename: None,
        });
    }
    for n in ["gyr_x", "gyr_y", "gyr_z"] {
        opts.columns.push(ColumnSpec {
            column: ColumnRef::Name(n.into()),
            unit: Some("deg/s".parse().unwrap()),
            rename: None,
        });
    }
    let log = read_text_file(&path, &opts).unwrap();
    assert_eq!(log.len(), 54_860);
    assert_eq!(log.channels.len(), 6);
    let az = &log.channel("acc_z").unwrap().values;
    let mean = az.iter().sum::<f64>() / az.len() as f64;
    assert!((mean - 9.8).abs() < 0.5, "mean acc_z {mean}");
    assert_eq!(
        log.channel("gyr_x").unwrap().quantity,
        Quantity::AngularRate
    );
    let t = log.time_s.as_ref().unwrap();
    assert!((t[0] - 261.906).abs() < 1e-9);
    assert!((log.tau0_s - 0.010).abs() < 0.0015);
    let span = t[t.len() - 1] - t[0];
    assert!((span - 548.6).abs() < 1.0, "span {span}");
}

// ---- formats ---------------------------------------------------------------------------

#[test]
fn delimiters_are_detected_and_overridable() {
    let want = vec![1.5, -2.0];
    for text in [
        "t,a\n0,1.5\n0.1,-2\n",
        "t;a\n0;1.5\n0.1;-2\n",
        "t\ta\n0\t1.5\n0.1\t-2\n",
        "t a\n  0   1.5  \n0.1 -2\n",
        "t , a\n0 , 1.5 \r\n0.1,-2,\r\n",
        "# c1\n\n# c2\nt,a # names\n0,1.5 # first\n\n   # indented comment\n0.1,-2\n",
    ] {
        let log = read_text_bytes(text.as_bytes(), "x", &timed())
            .unwrap_or_else(|e| panic!("{text:?}: {e}"));
        assert_eq!(log.channels[0].values, want, "{text:?}");
        assert_eq!(log.channels[0].name, "a");
        assert!((log.tau0_s - 0.1).abs() < 1e-15);
    }
    let mut o = timed();
    o.delimiter = Delimiter::Semicolon;
    let e = err("0,1;5\n1,2;6\n", &o);
    assert!(matches!(e, LogError::NonNumeric { .. }), "{e}");
}

#[test]
fn header_modes_and_units_from_header() {
    let text = "time [ms],gyro [deg/s],acc(mg),temp\n0,180,1000,25\n10,90,0,26\n";
    let o = TextOptions::default().with_time(ColumnRef::Name("time".into()), None);
    let log = read_text_bytes(text.as_bytes(), "x", &o).unwrap();
    assert_eq!(log.time_s.as_deref(), Some(&[0.0, 0.01][..]));
    assert!((log.channels[0].values[0] - std::f64::consts::PI).abs() < 1e-12);
    assert_eq!(log.channels[0].quantity, Quantity::AngularRate);
    assert!((log.channels[1].values[0] - 9.80665).abs() < 1e-12);
    assert_eq!(log.channels[2].quantity, Quantity::Other);
    assert_eq!(log.channels[2].name, "temp");

    // header forced absent: the first row is data (and here fails to parse)
    let mut o2 = rate(1.0);
    o2.header = HeaderMode::Absent;
    assert!(matches!(
        err("a,b\n1,2\n", &o2),
        LogError::NonNumeric { .. }
    ));
    // header forced present on an all-numeric first row: names "1","2"
    let mut o3 = rate(1.0);
    o3.header = HeaderMode::Present;
    let log = read_text_bytes(b"1,2\n3,4\n", "x", &o3).unwrap();
    assert_eq!(log.len(), 1);
    assert_eq!(log.channels[1].name, "2");
    // caller names override header names
    let log = read_text_bytes(b"a,b\n3,4\n", "x", &rate(1.0).with_names(["p", "q"])).unwrap();
    assert_eq!(log.channels[0].name, "p");
}

#[test]
fn column_selection_rename_and_default_unit() {
    let text = "t a b c\n0 1 2 3\n1 4 5 6\n";
    let mut o = timed();
    o.columns = vec!["c:deg/s=gz".parse().unwrap(), "2".parse().unwrap()];
    o.default_unit = Some("mg".parse().unwrap());
    let log = read_text_bytes(text.as_bytes(), "x", &o).unwrap();
    assert_eq!(log.channels.len(), 2);
    assert_eq!(log.channels[0].name, "gz");
    assert!((log.channels[0].values[1] - 6.0f64.to_radians()).abs() < 1e-15);
    assert_eq!(log.channels[1].name, "a");
    assert_eq!(log.channels[1].source_unit, "mg");
    assert!((log.channels[1].values[1] - 4.0 * 9.80665e-3).abs() < 1e-15);
    // unselected columns are not parsed
    let log = read_text_bytes(
        b"t x s\n0 1 junk\n1 2 junk\n",
        "x",
        &timed().with_column(ColumnRef::Index(2), None),
    )
    .unwrap();
    assert_eq!(log.channels[0].values, vec![1.0, 2.0]);
}

#[test]
fn single_column_and_rate_only() {
    let log = read_text_bytes(b"1\n2\n3", "x", &rate(200.0)).unwrap();
    assert_eq!(log.channels[0].values, vec![1.0, 2.0, 3.0]);
    assert_eq!(log.tau0_s, 1.0 / 200.0);
}

#[test]
fn small_chunks_give_identical_results_and_line_numbers() {
    // Many chunks and pieces: the result and error lines must not depend on chunking.
    let mut text = String::from("# header comment\nt,x,y\n");
    for i in 0..5000 {
        if i % 97 == 0 {
            text.push_str("# interleaved comment\n\n");
        }
        text.push_str(&format!(
            "{},{},{}\n",
            i as f64 * 0.01,
            (i * 7 % 13) as f64 - 6.5,
            i
        ));
    }
    let big = read_text_bytes(text.as_bytes(), "x", &timed()).unwrap();
    for chunk in [64, 100, 1000, 4096] {
        let mut o = timed();
        o.chunk_bytes = chunk;
        let small = read_text(text.as_bytes(), "x", &o).unwrap();
        assert_eq!(small, big, "chunk {chunk}");
    }
    // an error deep in the file reports the same line whatever the chunking
    let bad = text.replacen(",4321\n", ",4321x\n", 1);
    let want_line = bad.lines().position(|l| l.contains("4321x")).unwrap() + 1;
    for chunk in [64, 1000, 1 << 20] {
        let mut o = timed();
        o.chunk_bytes = chunk;
        let e = read_text(bad.as_bytes(), "x", &o).unwrap_err();
        assert_eq!(e.line(), Some(want_line), "chunk {chunk}: {e}");
    }
}

#[test]
fn csv_writer_round_trips_bit_exact() {
    let text = "time,gyro [deg/s],acc [g],temp [degC],aux\n0,0.1,1,25.5,7\n0.01,-1e-7,0.999,25.6,1e300\n0.02,3.3,1.001,25.7,-0\n";
    let o = TextOptions::default().with_time(ColumnRef::Name("time".into()), None);
    let log = read_text_bytes(text.as_bytes(), "orig", &o).unwrap();
    let mut out = Vec::new();
    write_csv(&log, &mut out).unwrap();
    let back = read_text_bytes(&out, "orig", &o).unwrap();
    assert_eq!(back.time_s, log.time_s);
    for (a, b) in log.channels.iter().zip(&back.channels) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.quantity, b.quantity);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.values), bits(&b.values), "{}", a.name);
    }
}

// ---- errors: one test per case ---------------------------------------------------------

#[test]
fn error_non_numeric_names_line_byte_column_and_field() {
    let e = err("t,gyro_x,gyro_y\n0,1,2\n1,2,abc\n", &timed());
    assert_eq!(
        e.to_string(),
        r#"mem.csv:3:5: non-numeric value "abc" in column 3 (gyro_y)"#
    );
}

#[test]
fn error_ragged_rows() {
    let e = err("t,a,b\n0,1,2\n1,2\n", &timed());
    assert!(
        matches!(
            e,
            LogError::Ragged {
                found: 2,
                expected: 3,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(e.line(), Some(3));
    let e = err("0 1 2\n1 2 3 4\n2 3 4\n", &timed());
    assert!(matches!(e, LogError::Ragged { found: 4, .. }), "{e}");
    assert!(e.to_string().starts_with("mem.csv:2:7:"), "{e}");
}

/// The reference row of "expected N fields (as on line K)" is itself good: a short first
/// row is reported at its own line against the rows after it.
#[test]
fn ragged_first_row_cites_a_good_reference() {
    let e = err("0 1\n1 2 3\n2 3 4\n3 4 5\n", &timed());
    assert_eq!(
        e.to_string(),
        "mem.csv:1:4: row has 2 fields, expected 3 (as on line 2)"
    );
    // Two rows: the longer second row is the reference.
    let e = err("# c\n0 1 2\n1 2 3 4\n", &timed());
    assert_eq!(
        e.to_string(),
        "mem.csv:2:6: row has 3 fields, expected 4 (as on line 3)"
    );
    // Many short rows: after a dropped cut first record the next short row is an error
    // with file, line and byte column, citing a good row.
    let many = "1,2\n1,2\n3,4\n2,5,6\n3,7,8\n4,9,9\n";
    let opts = timed().dropping_truncated_edges();
    let e = err(many, &opts);
    assert_eq!(
        e.to_string(),
        "mem.csv:2:4: row has 2 fields, expected 3 (as on line 4)"
    );
    // Strict (default): the first short row is the error, with the same reference.
    let e = err(many, &timed());
    assert_eq!(
        e.to_string(),
        "mem.csv:1:4: row has 2 fields, expected 3 (as on line 4)"
    );
}

/// Opt-in dropping of records cut by the start or end of a recording.
#[test]
fn truncated_edge_records_dropped_only_when_asked() {
    let rows: Vec<String> = (0..20)
        .map(|i| {
            format!(
                "{i},{:.1},{:.1}",
                1.5 + 0.1 * i as f64,
                2.5 + 0.1 * i as f64
            )
        })
        .collect();
    let clean = rows.join("\n") + "\n";
    // Cut inside the first row's first number and inside the last row's second field.
    let mut cut_rows = rows.clone();
    cut_rows[0] = "5,2.5".into();
    cut_rows[19] = "19,3.".into();
    let cut = cut_rows.join("\n");
    let strict = err(&cut, &timed());
    assert_eq!(
        strict.to_string(),
        "mem.csv:1:6: row has 2 fields, expected 3 (as on line 2)"
    );
    let opts = timed().dropping_truncated_edges();
    let all = read_text_bytes(clean.as_bytes(), "mem.csv", &opts).unwrap();
    assert!(all.notes.is_empty());
    for chunk in [64, 100, 1 << 20] {
        let mut o = opts.clone();
        o.chunk_bytes = chunk;
        let log = read_text_bytes(cut.as_bytes(), "mem.csv", &o).unwrap();
        let t: Vec<f64> = (1..19).map(f64::from).collect();
        assert_eq!(log.time_s, Some(t), "chunk {chunk}");
        for (c, whole) in log.channels.iter().zip(&all.channels) {
            assert_eq!(c.values, whole.values[1..19].to_vec());
        }
        assert_eq!(
            log.notes,
            vec![
                "mem.csv:1: dropped the first record \"5,2.5\", cut by the start of the recording: it has 2 fields, line 2 has 3".to_string(),
                "mem.csv:20: dropped the last record \"19,3.\", cut by the end of the recording: it has 2 fields, line 2 has 3".to_string(),
            ]
        );
    }
    // A cut first number that is no number, after a header, and a cut last number.
    let t = "t,a,b\n.5e,1.5,2.5\n1,1.6,2.6\n2,1.7,2.7\n3,1.8,2.8e";
    let log = read_text_bytes(t.as_bytes(), "mem.csv", &opts).unwrap();
    assert_eq!(log.len(), 2);
    assert!(
        log.notes[0].ends_with("its field 1 is not a number"),
        "{:?}",
        log.notes
    );
    assert!(
        log.notes[1].starts_with("mem.csv:5: dropped the last"),
        "{:?}",
        log.notes
    );
    // Headerless, a cut first number is not mistaken for a header.
    let t = "e-3,1.5,2.5\n1,1.6,2.6\n2,1.7,2.7\n";
    let log = read_text_bytes(t.as_bytes(), "mem.csv", &opts).unwrap();
    assert_eq!(log.time_s.as_deref(), Some(&[1.0, 2.0][..]));
    assert_eq!(log.channels[0].name, "col2");
    // The time is the last field and the file ends inside it: 2 fields whole, but the
    // time goes back → dropped; with a line end it is a real error.
    let opts_t = TextOptions::default()
        .with_time(ColumnRef::Index(3), None)
        .dropping_truncated_edges();
    let t = "1.5,2.5,100\n1.6,2.6,101\n1.7,2.7,102\n1.8,2.8,10";
    let log = read_text_bytes(t.as_bytes(), "mem.csv", &opts_t).unwrap();
    assert_eq!(log.len(), 3);
    assert!(
        log.notes[0].ends_with(
            "it has no line end and its time stamp 10 s does not follow the previous 102 s"
        ),
        "{:?}",
        log.notes
    );
    let e = err(&format!("{t}\n"), &opts_t);
    assert!(matches!(e, LogError::NonMonotonicTime { .. }), "{e}");
    // A bad row in the middle stays an error with dropping on.
    let e = err("0,1,2\n1,2\n2,3,4\n3,4,5\n", &opts);
    assert!(e.to_string().starts_with("mem.csv:2:4:"), "{e}");
    let e = err("0,1,2\n1,x,2\n2,3,4\n", &opts);
    assert!(matches!(e, LogError::NonNumeric { .. }), "{e}");
}

/// Week + seconds of week in two columns, across a week boundary.
#[test]
fn week_and_seconds_of_week_columns() {
    let t = "week,sow,g\n2399,604799.5,1\n2399,604799.75,2\n2400,0.0,3\n2400,0.25,4\n";
    for week in [ColumnRef::Name("week".into()), ColumnRef::Index(1)] {
        let o = TextOptions::default()
            .with_time(ColumnRef::Name("sow".into()), None)
            .with_week_column(week);
        let log = read_text_bytes(t.as_bytes(), "w.csv", &o).unwrap();
        assert_eq!(log.week, Some(2399));
        // Seconds from the start of week 2399 keep increasing past 604 800 s.
        assert_eq!(
            log.time_s.as_deref(),
            Some(&[604_799.5, 604_799.75, 604_800.0, 604_800.25][..])
        );
        assert_eq!(log.channels.len(), 1);
        assert_eq!(log.channels[0].values, vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(log.tau0_s, 0.25);
    }
    // Without the week column the restart at 0 is time going backwards.
    let o = TextOptions::default().with_time(ColumnRef::Name("sow".into()), None);
    let e = err(t, &o);
    assert!(matches!(e, LogError::NonMonotonicTime { .. }), "{e}");
    // Weeks must be whole numbers; the week column needs a time column.
    let bad = "week,sow,g\n2399.5,1,1\n2399.5,2,1\n";
    let o = TextOptions::default()
        .with_time(ColumnRef::Name("sow".into()), None)
        .with_week_column(ColumnRef::Name("week".into()));
    let e = err(bad, &o);
    assert_eq!(
        e.to_string(),
        "mem.csv:2: week 2399.5 in column 1 (week) is not a whole number in 0–65535"
    );
    let o = rate(1.0).with_week_column(ColumnRef::Index(1));
    let e = err(t, &o);
    assert!(e.to_string().contains("needs a time column"), "{e}");
    let o = TextOptions::default()
        .with_time(ColumnRef::Index(2), None)
        .with_week_column(ColumnRef::Index(2));
    let e = err(t, &o);
    assert!(e.to_string().contains("selected twice"), "{e}");
}

#[test]
fn error_nan_and_inf() {
    for bad in ["nan", "NaN", "inf", "-Infinity", "1e400"] {
        let e = err(&format!("0,1\n1,{bad}\n"), &timed());
        assert!(
            matches!(e, LogError::NonFinite { field: 2, .. }),
            "{bad}: {e}"
        );
        assert_eq!(e.line(), Some(2));
    }
    // non-finite after unit conversion
    let o = timed().with_column(ColumnRef::Index(2), Some("counts*1e300".parse().unwrap()));
    assert!(matches!(
        err("0,1\n1,1e10\n", &o),
        LogError::NonFinite { .. }
    ));
}

#[test]
fn error_empty_field() {
    let e = err("0,1,2\n1,,3\n", &timed());
    assert!(matches!(e, LogError::EmptyField { field: 2, .. }), "{e}");
    assert!(e.to_string().starts_with("mem.csv:2:3:"), "{e}");
}

#[test]
fn error_non_monotonic_time() {
    let e = err("# c\nt,a\n0,1\n0.02,1\n0.01,1\n0.03,1\n", &timed());
    assert!(matches!(e, LogError::NonMonotonicTime { .. }), "{e}");
    assert_eq!(e.line(), Some(5));
    assert!(e.to_string().contains("column 1 (t)"), "{e}");
}

#[test]
fn error_duplicated_time() {
    let e = err("0,1\n0.01,1\n\n0.01,2\n", &timed());
    assert!(matches!(e, LogError::DuplicateTime { .. }), "{e}");
    assert_eq!(e.line(), Some(4));
}

#[test]
fn gaps_error_split_bridge() {
    let text = "0,1\n1,2\n2,3\n5,4\n6,5\n7,6\n";
    let e = err(text, &timed());
    assert!(matches!(e, LogError::TimeGap { .. }), "{e}");
    assert_eq!(e.line(), Some(4));
    let split = read_text_bytes(
        text.as_bytes(),
        "x",
        &timed().with_gap_policy(GapPolicy::Split),
    )
    .unwrap();
    assert_eq!(split.segments, vec![0..3, 3..6]);
    assert_eq!(split.gaps.len(), 1);
    assert_eq!(split.gaps[0].index, 3);
    assert_eq!(split.gaps[0].duration_s, 3.0);
    let bridge = read_text_bytes(
        text.as_bytes(),
        "x",
        &timed().with_gap_policy(GapPolicy::Bridge),
    )
    .unwrap();
    assert_eq!(bridge.segments, vec![0..6]);
    assert_eq!(bridge.gaps, split.gaps);
    assert_eq!(bridge.len(), 6);
    // configurable factor: 3 s is within 4 × τ0
    let mut o = timed();
    o.gap_factor = 4.0;
    assert_eq!(
        read_text_bytes(text.as_bytes(), "x", &o)
            .unwrap()
            .gaps
            .len(),
        0
    );
}

#[test]
fn error_rate_disagrees_with_time_column() {
    let e = err("0,1\n0.01,1\n0.02,1\n", &timed().with_rate_hz(50.0));
    assert!(matches!(e, LogError::RateMismatch { .. }), "{e}");
    assert!(read_text_bytes(b"0,1\n0.01,1\n0.02,1\n", "x", &timed().with_rate_hz(100.5)).is_ok());
}

#[test]
fn error_empty_input() {
    for text in ["", "\n\n", "# only\n# comments\n", "   \r\n"] {
        let e = err(text, &rate(1.0));
        assert!(matches!(e, LogError::Empty { .. }), "{text:?}: {e}");
        assert!(e.to_string().starts_with("mem.csv:"), "{e}");
    }
}

#[test]
fn error_header_only() {
    let e = err("# c\ntime,gx,gy\n\n# end\n", &timed());
    assert!(matches!(e, LogError::HeaderOnly { .. }), "{e}");
    assert_eq!(e.line(), Some(2));
}

#[test]
fn error_unknown_unit() {
    assert!("xyz".parse::<Unit>().is_err());
    let e = err("t,a [furlong/s]\n0,1\n1,2\n", &timed());
    assert!(matches!(e, LogError::UnknownUnit { .. }), "{e}");
    assert!(e.to_string().contains("furlong"), "{e}");
    assert_eq!(e.line(), Some(1));
    let e = err("t [fortnight],a\n0,1\n1,2\n", &timed());
    assert!(matches!(e, LogError::UnknownUnit { .. }), "{e}");
    assert!("gx:bogus".parse::<ColumnSpec>().is_err());
}

#[test]
fn error_unknown_column() {
    let e = err(
        "t,a\n0,1\n1,2\n",
        &timed().with_column(ColumnRef::Name("gyro_q".into()), None),
    );
    assert!(matches!(e, LogError::UnknownColumn { .. }), "{e}");
    assert!(
        e.to_string().contains("gyro_q") && e.to_string().contains("2=a"),
        "{e}"
    );
    let e = err(
        "0,1\n1,2\n",
        &timed().with_column(ColumnRef::Index(3), None),
    );
    assert!(matches!(e, LogError::UnknownColumn { .. }), "{e}");
    let e = err(
        "0,1\n1,2\n",
        &TextOptions::default().with_time(ColumnRef::Index(9), None),
    );
    assert!(matches!(e, LogError::UnknownColumn { .. }), "{e}");
}

#[test]
fn error_options() {
    // neither a time column nor a rate
    assert!(matches!(
        err("1\n2\n", &TextOptions::default()),
        LogError::InvalidOptions { .. }
    ));
    assert!(matches!(
        err("1\n2\n", &rate(-1.0)),
        LogError::InvalidOptions { .. }
    ));
    // time column selected as data too
    let e = err(
        "0,1\n1,2\n",
        &timed().with_column(ColumnRef::Index(1), None),
    );
    assert!(matches!(e, LogError::InvalidOptions { .. }), "{e}");
    // wrong number of names
    assert!(matches!(
        err("0,1\n1,2\n", &timed().with_names(["a"])),
        LogError::InvalidOptions { .. }
    ));
}

#[test]
fn error_io_and_missing_file() {
    let e = read_text_file("/nonexistent/imu.csv", &rate(1.0)).unwrap_err();
    assert!(matches!(e, LogError::Io { .. }));
    assert!(e.to_string().starts_with("/nonexistent/imu.csv: "), "{e}");
}

#[test]
fn invalid_utf8_is_a_clean_error() {
    let e = read_text_bytes(b"0,1\n1,\xff\xfe\n", "x", &timed()).unwrap_err();
    assert!(matches!(e, LogError::NonNumeric { .. }), "{e}");
    assert_eq!(e.line(), Some(2));
}
