//! Binary `DRIFTLOG` format: round trip and header validation errors.

use driftless::io::{
    Channel, ColumnRef, GapPolicy, ImuLog, LogError, Quantity, TextOptions, read_binary,
    read_binary_file, read_log_file, read_text_bytes, write_binary, write_binary_file,
};

fn sample_log() -> ImuLog {
    let n = 3000;
    let t: Vec<f64> = (0..n)
        .map(|i| {
            if i < 1500 {
                i as f64 * 0.01
            } else {
                20.0 + i as f64 * 0.01
            }
        })
        .collect();
    let text: String = t
        .iter()
        .enumerate()
        .map(|(i, t)| {
            format!(
                "{t},{},{}\n",
                (i as f64 * 0.37).sin(),
                9.8 + 1e-7 * i as f64
            )
        })
        .collect();
    let text = format!("time,gyro [deg/s],acc [m/s^2]\n{text}");
    let o = TextOptions::default()
        .with_time(ColumnRef::Name("time".into()), None)
        .with_gap_policy(GapPolicy::Split);
    read_text_bytes(text.as_bytes(), "sample.csv", &o).unwrap()
}

fn encode(log: &ImuLog) -> Vec<u8> {
    let mut v = Vec::new();
    write_binary(log, &mut v).unwrap();
    v
}

#[test]
fn round_trip_is_exact_including_segments_and_gaps() {
    let log = sample_log();
    assert_eq!(log.segments.len(), 2);
    let bytes = encode(&log);
    assert_eq!(&bytes[..8], b"DRIFTLOG");
    let back = read_binary(&bytes[..], "mem.bin").unwrap();
    assert_eq!(back, log);
    // through a file, and auto-detected by read_log_file
    let path = std::env::temp_dir().join(format!("driftless_io_rt_{}.dlog", std::process::id()));
    write_binary_file(&log, &path).unwrap();
    assert_eq!(read_binary_file(&path).unwrap(), log);
    assert_eq!(read_log_file(&path, &TextOptions::default()).unwrap(), log);
    std::fs::remove_file(&path).ok();
}

#[test]
fn log_without_time_round_trips() {
    let log = ImuLog::new(
        "sim",
        None,
        0.005,
        vec![Channel {
            name: "t".into(),
            quantity: Quantity::Temperature,
            source_unit: "degC".into(),
            values: vec![25.0, 25.5],
        }],
    );
    assert_eq!(read_binary(&encode(&log)[..], "m").unwrap(), log);
}

#[test]
fn bad_magic() {
    let mut b = encode(&sample_log());
    b[0] = b'X';
    let e = read_binary(&b[..], "f.bin").unwrap_err();
    assert!(matches!(e, LogError::BadMagic { .. }), "{e}");
    assert!(
        e.to_string()
            .starts_with("f.bin: not a driftless binary log"),
        "{e}"
    );
    assert!(matches!(
        read_binary(&b"DRIFT"[..], "f").unwrap_err(),
        LogError::BadMagic { .. }
    ));
}

#[test]
fn unsupported_version() {
    let mut b = encode(&sample_log());
    b[8] = 9;
    assert!(matches!(
        read_binary(&b[..], "f").unwrap_err(),
        LogError::UnsupportedVersion { version: 9, .. }
    ));
}

#[test]
fn truncated_anywhere_is_an_error() {
    let b = encode(&sample_log());
    for cut in [10, 20, 100, b.len() / 2, b.len() - 8, b.len() - 1] {
        let e = read_binary(&b[..cut], "f").unwrap_err();
        assert!(
            matches!(e, LogError::Truncated { .. } | LogError::BadHeader { .. }),
            "cut {cut}: {e}"
        );
    }
    // with a file, the size check catches it before reading data
    let path = std::env::temp_dir().join(format!("driftless_io_trunc_{}.dlog", std::process::id()));
    std::fs::write(&path, &b[..b.len() - 16]).unwrap();
    let e = read_binary_file(&path).unwrap_err();
    assert!(matches!(e, LogError::CountMismatch { .. }), "{e}");
    assert!(e.to_string().contains("3000 rows × 3 columns"), "{e}");
    std::fs::remove_file(&path).ok();
}

#[test]
fn trailing_bytes_are_a_count_mismatch() {
    let mut b = encode(&sample_log());
    b.extend_from_slice(&[0; 8]);
    let e = read_binary(&b[..], "f").unwrap_err();
    assert!(
        matches!(e, LogError::CountMismatch { found_bytes, expected_bytes, .. } if found_bytes == expected_bytes + 8),
        "{e}"
    );
}

/// Rewrites the header text (keeping the layout valid) to test header validation.
fn with_header(log: &ImuLog, edit: impl Fn(&str) -> String) -> Vec<u8> {
    let b = encode(log);
    let hlen = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
    let data_start = (16 + hlen).next_multiple_of(8);
    let text = edit(std::str::from_utf8(&b[16..16 + hlen]).unwrap());
    let mut out = b"DRIFTLOG".to_vec();
    out.extend_from_slice(&1u32.to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(text.as_bytes());
    out.resize(out.len().next_multiple_of(8), 0);
    out.extend_from_slice(&b[data_start..]);
    out
}

#[test]
fn header_count_mismatch_and_garbage() {
    let log = sample_log();
    let b = with_header(&log, |h| {
        h.replace("rows = 3000", "rows = 2999")
            .replace("[[0, 1500], [1500, 3000]]", "[]")
    });
    assert!(matches!(
        read_binary(&b[..], "f").unwrap_err(),
        LogError::CountMismatch { .. }
    ));
    let b = with_header(&log, |h| h.replace("rows = 3000", "rows = 3001"));
    assert!(matches!(
        read_binary(&b[..], "f").unwrap_err(),
        LogError::Truncated { .. }
    ));
    let b = with_header(&log, |h| h.replace("rows = 3000", "rows = 99999999999999"));
    assert!(read_binary(&b[..], "f").is_err());
    let b = with_header(&log, |h| {
        h.replace("encoding = \"f64le\"", "encoding = \"f32le\"")
    });
    assert!(matches!(
        read_binary(&b[..], "f").unwrap_err(),
        LogError::BadHeader { .. }
    ));
    let b = with_header(&log, |h| h.replace("tau0_s", "tau_zero"));
    let e = read_binary(&b[..], "f").unwrap_err();
    assert!(matches!(e, LogError::BadHeader { .. }), "{e}");
    assert!(e.to_string().contains("tau0_s"), "{e}");
    let b = with_header(&log, |h| {
        h.replace("[[0, 1500], [1500, 3000]]", "[[0, 1500], [1000, 3000]]")
    });
    assert!(matches!(
        read_binary(&b[..], "f").unwrap_err(),
        LogError::BadHeader { .. }
    ));
}

#[test]
fn stored_nan_and_time_order_are_rejected() {
    let mut log = sample_log();
    let b = encode(&log);
    let n = b.len();
    let mut nan = b.clone();
    nan[n - 8..].copy_from_slice(&f64::NAN.to_le_bytes());
    assert!(matches!(
        read_binary(&nan[..], "f").unwrap_err(),
        LogError::NonFiniteStored { row: 2999, .. }
    ));
    // writer refuses NaN too
    log.channels[0].values[5] = f64::NAN;
    assert!(matches!(
        write_binary(&log, Vec::new()).unwrap_err(),
        LogError::InvalidLog { .. }
    ));
    let mut log = sample_log();
    log.time_s.as_mut().unwrap()[10] = 0.0;
    let e = read_binary(&encode(&log)[..], "f").unwrap_err();
    assert!(matches!(e, LogError::Corrupt { .. }), "{e}");
}
