//! Inputs as they arrive in practice: through pipes and FIFOs, as binary data given by
//! mistake, without line ends, at two sample rates, with timing jitter; configuration files
//! that are not configuration files.

use std::io::Write;
use std::path::{Path, PathBuf};

use driftless::io::{
    ImuLog, LogError, MAX_CONFIG_BYTES, TextOptions, read_config_text, read_log_file,
    read_text_bytes, write_binary_file,
};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-input-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("dir");
    d
}

/// Rows `time,gx,gy` at the given time stamps, with values that differ row to row.
fn csv_at(times: &[f64]) -> String {
    let mut s = String::from("time,gx,gy\n");
    for (k, t) in times.iter().enumerate() {
        s.push_str(&format!(
            "{t:.6},{},{}\n",
            0.01 * ((k * 7) % 13) as f64 - 0.06,
            1000.123456789 + 0.001 * ((k * 3) % 5) as f64
        ));
    }
    s
}

fn uniform(n: usize, dt: f64) -> Vec<f64> {
    (0..n).map(|k| k as f64 * dt).collect()
}

fn same(a: &ImuLog, b: &ImuLog) {
    assert_eq!(a.len(), b.len());
    assert_eq!(a.time_s, b.time_s);
    assert_eq!(a.tau0_s, b.tau0_s);
    assert_eq!(a.channels.len(), b.channels.len());
    for (x, y) in a.channels.iter().zip(&b.channels) {
        assert_eq!(x.name, y.name);
        assert_eq!(x.values, y.values);
    }
}

/// Makes a FIFO with the `mkfifo` program; `None` (and a note) where there is none.
fn mkfifo(path: &Path) -> Option<()> {
    match std::process::Command::new("mkfifo").arg(path).status() {
        Ok(s) if s.success() => Some(()),
        _ => {
            println!("note: no `mkfifo` here; the FIFO part of this test is skipped");
            None
        }
    }
}

/// Reads `bytes` through a FIFO at `path` (a thread writes them).
fn read_through_fifo(path: &Path, bytes: Vec<u8>, opts: &TextOptions) -> Option<ImuLog> {
    mkfifo(path)?;
    let p = path.to_path_buf();
    let writer = std::thread::spawn(move || {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .open(&p)
            .expect("open fifo");
        // The reader may stop early on an error; a broken pipe is then expected.
        let _ = f.write_all(&bytes);
    });
    let log = read_log_file(path, opts).expect("read through the FIFO");
    writer.join().expect("writer");
    Some(log)
}

#[test]
fn a_fifo_gives_the_same_log_as_the_file_for_text_binary_and_gzip() {
    let d = tmp("fifo");
    let text = csv_at(&uniform(5000, 0.01));
    let file = d.join("log.csv");
    std::fs::write(&file, &text).unwrap();
    let opts = TextOptions::default();
    let from_file = read_log_file(&file, &opts).unwrap();
    assert_eq!(from_file.len(), 5000);
    assert_eq!(from_file.channels[1].values[0], 1000.123456789);

    let bin = d.join("log.dlog");
    write_binary_file(&from_file, &bin).unwrap();
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(text.as_bytes()).unwrap();
    let gz = gz.finish().unwrap();

    for (k, bytes) in [
        text.as_bytes().to_vec(),
        std::fs::read(&bin).unwrap(),
        gz.clone(),
    ]
    .into_iter()
    .enumerate()
    {
        let Some(log) = read_through_fifo(&d.join(format!("fifo{k}")), bytes, &opts) else {
            return;
        };
        same(&log, &from_file);
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn nul_bytes_are_binary_data_naming_the_byte_offset() {
    let e = read_text_bytes(
        b"time,gx\n0,1\n\x000.01,2\n",
        "z.bin",
        &TextOptions::default(),
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(
            e,
            LogError::BinaryData {
                byte_offset: 12,
                ..
            }
        ),
        "{msg}"
    );
    assert!(
        msg.starts_with("z.bin: binary data, not a text log (byte offset 12"),
        "{msg}"
    );
    assert!(msg.contains("lacks the magic bytes"), "{msg}");

    // An executable: control bytes in its first bytes, not a "row has N fields" error.
    let elf = b"\x7fELF\x02\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x02\x00>\x00";
    let e = read_text_bytes(elf, "ls", &TextOptions::default().with_rate_hz(100.0)).unwrap_err();
    assert!(
        matches!(e, LogError::BinaryData { byte_offset: 4, .. }),
        "{e}"
    );

    // A NUL far past the checked start, inside a data row: still binary data, at its offset.
    let mut text = csv_at(&uniform(5000, 0.01));
    let at = text.len() - 40;
    text.replace_range(at..at + 1, "\0");
    let opts = TextOptions {
        chunk_bytes: 4096,
        ..TextOptions::default()
    };
    let e = read_text_bytes(text.as_bytes(), "late.csv", &opts).unwrap_err();
    assert!(
        matches!(e, LogError::BinaryData { byte_offset, .. } if byte_offset == at as u64),
        "{e}"
    );
}

#[test]
fn a_latin1_header_is_still_text() {
    let text =
        b"# Temperatur in \xb0C, Drehrate in \xb0/s\ntime,temp,gx\n0,1,2\n0.01,2,3\n0.02,3,4\n";
    let log = read_text_bytes(text, "l1.csv", &TextOptions::default()).unwrap();
    assert_eq!(log.len(), 3);
}

#[test]
fn a_line_longer_than_the_cap_is_an_error_before_it_is_buffered() {
    // Text without line ends, a few MiB: refused at the cap, naming line 1.
    let d = tmp("long");
    let path = d.join("noline.txt");
    let chunk = "0.1,0.2,0.3,".repeat(1 << 16);
    let mut f = std::fs::File::create(&path).unwrap();
    for _ in 0..4 {
        f.write_all(chunk.as_bytes()).unwrap();
    }
    drop(f);
    let t0 = std::time::Instant::now();
    let e = read_log_file(&path, &TextOptions::default().with_rate_hz(1.0)).unwrap_err();
    assert!(t0.elapsed().as_secs_f64() < 1.0);
    let msg = e.to_string();
    assert!(matches!(e, LogError::LineTooLong { .. }), "{msg}");
    assert!(msg.contains(":1: line 1 is longer than 1 MiB"), "{msg}");
    assert!(msg.contains("binary data, or not a text log?"), "{msg}");
    let _ = std::fs::remove_dir_all(&d);

    // A long line in the middle, with a small cap and small chunks: its own line number.
    let mut text = csv_at(&uniform(200, 0.01));
    let pos = text.match_indices('\n').nth(50).unwrap().0;
    text.insert_str(pos, &" ".repeat(3000));
    for chunk_bytes in [64, 1 << 10, 16 << 20] {
        let opts = TextOptions {
            max_line_bytes: 1024,
            chunk_bytes,
            ..TextOptions::default()
        };
        let e = read_text_bytes(text.as_bytes(), "mid.csv", &opts).unwrap_err();
        assert!(
            matches!(&e, LogError::LineTooLong { at, limit: 1024 } if at.line == Some(51)),
            "chunk {chunk_bytes}: {e}"
        );
    }
}

#[test]
fn a_log_at_two_rates_is_refused_naming_both_rates_and_where() {
    // 30 % at 100 Hz, then 70 % at 50 Hz: the median alone would say 50 Hz throughout.
    let mut t: Vec<f64> = uniform(3000, 0.01);
    let t_switch = 3000.0 * 0.01;
    t.extend((0..7000).map(|k| t_switch + k as f64 * 0.02));
    let e = read_text_bytes(csv_at(&t).as_bytes(), "two.csv", &TextOptions::default()).unwrap_err();
    let msg = e.to_string();
    match &e {
        LogError::RateChange {
            at,
            interval_s,
            other_interval_s,
            last,
            ..
        } => {
            assert!((interval_s - 0.02).abs() < 1e-9, "{msg}");
            assert!((other_interval_s - 0.01).abs() < 1e-9, "{msg}");
            assert_eq!((at.line, *last), (Some(2), 3002), "{msg}");
        }
        _ => panic!("{msg}"),
    }
    assert!(msg.contains("50 Hz") && msg.contains("100 Hz"), "{msg}");

    // The other way round (a slower stretch), with gaps accepted: a rate change still,
    // not thousands of gaps.
    let mut t: Vec<f64> = uniform(7000, 0.01);
    t.extend((1..=3000).map(|k| 70.0 + k as f64 * 0.02 - 0.01));
    let opts = TextOptions::default().with_gap_policy(driftless::io::GapPolicy::Split);
    let e = read_text_bytes(csv_at(&t).as_bytes(), "slow.csv", &opts).unwrap_err();
    match &e {
        LogError::RateChange {
            at,
            interval_s,
            other_interval_s,
            ..
        } => {
            assert!((interval_s - 0.01).abs() < 1e-9, "{e}");
            assert!((other_interval_s - 0.02).abs() < 1e-9, "{e}");
            assert_eq!(at.line, Some(7001), "{e}");
        }
        _ => panic!("{e}"),
    }

    // A short faster burst inside a long log (shorter intervals only).
    let mut t: Vec<f64> = uniform(4000, 0.01);
    let t0 = t[3999];
    t.extend((1..=400).map(|k| t0 + k as f64 * 0.008));
    let t1 = t[t.len() - 1];
    t.extend((1..=4000).map(|k| t1 + k as f64 * 0.01));
    let e =
        read_text_bytes(csv_at(&t).as_bytes(), "burst.csv", &TextOptions::default()).unwrap_err();
    assert!(
        matches!(&e, LogError::RateChange { other_interval_s, .. }
            if (other_interval_s - 0.008).abs() < 1e-6),
        "{e}"
    );
}

#[test]
fn a_jittered_constant_rate_log_is_read() {
    // Isolated late or early samples, up to ±25 % of an interval, on every 7th to 23rd
    // sample, plus a few isolated gaps with the bridge policy: one rate, read as such.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut rnd = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut t = Vec::new();
    let mut k = 0usize;
    let mut next_jitter = 5;
    while t.len() < 20_000 {
        let mut s = k as f64 * 0.01;
        if t.len() == next_jitter {
            s += (rnd() - 0.5) * 0.5 * 0.01;
            next_jitter += 7 + (rnd() * 16.0) as usize;
        }
        t.push(s);
        k += if t.len() % 5000 == 0 { 4 } else { 1 };
    }
    let opts = TextOptions::default().with_gap_policy(driftless::io::GapPolicy::Bridge);
    let log = read_text_bytes(csv_at(&t).as_bytes(), "jitter.csv", &opts).unwrap();
    assert_eq!(log.len(), 20_000);
    assert!((log.tau0_s - 0.01).abs() < 1e-9, "{}", log.tau0_s);
    assert_eq!(log.gaps.len(), 3);

    // Time stamps rounded to 1 ms at 400 Hz (intervals of 2 and 3 ms): one rate too.
    let t: Vec<f64> = (0..8000)
        .map(|k| (k as f64 * 2.5).floor() / 1000.0)
        .collect();
    let opts = TextOptions::default().with_gap_policy(driftless::io::GapPolicy::Bridge);
    read_text_bytes(csv_at(&t).as_bytes(), "ms.csv", &opts).unwrap();
}

#[test]
fn configuration_files_are_read_under_a_size_cap() {
    let d = tmp("config");
    let big = d.join("big.toml");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(MAX_CONFIG_BYTES + 1).unwrap();
    drop(f);
    let e = read_config_text(&big, MAX_CONFIG_BYTES).unwrap_err();
    assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
    assert!(e.to_string().contains("larger than 16 MiB"), "{e}");

    // Every loader of a configuration or model file names the file and the cap.
    let msgs = [
        driftless::allan::noise_model::NoiseModel::load(&big)
            .map(|_| ())
            .unwrap_err()
            .to_string(),
        driftless::calib::model_file::CalibrationFile::load(&big)
            .map(|_| ())
            .unwrap_err()
            .to_string(),
        driftless::thermal::model_file::ThermalModelFile::load(&big)
            .map(|_| ())
            .unwrap_err()
            .to_string(),
        driftless::sim::scenario::Scenario::from_file(&big)
            .map(|_| ())
            .unwrap_err()
            .to_string(),
        driftless::sim::profile::MotionProfile::from_file(&big)
            .map(|_| ())
            .unwrap_err()
            .to_string(),
        driftless::experiment::ExperimentScenario::from_file(&big)
            .map(|_| ())
            .unwrap_err()
            .to_string(),
        driftless::io::nav::KfGinsConfig::from_file(&big)
            .map(|_| ())
            .unwrap_err()
            .to_string(),
    ];
    for m in msgs {
        assert!(m.contains("big.toml") && m.contains("16 MiB"), "{m}");
    }

    // A device without end: refused at the cap, quickly.
    if Path::new("/dev/zero").exists() {
        let t0 = std::time::Instant::now();
        let e = read_config_text("/dev/zero", MAX_CONFIG_BYTES).unwrap_err();
        assert!(e.to_string().contains("larger than"), "{e}");
        assert!(t0.elapsed().as_secs_f64() < 1.0);
    }
    // Binary data and non-UTF-8 text are refused with the offset.
    let nul = d.join("nul.toml");
    std::fs::write(&nul, b"a = 1\n\0").unwrap();
    assert!(
        read_config_text(&nul, 100)
            .unwrap_err()
            .to_string()
            .contains("byte offset 6")
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A `DRIFTLOG` binary log holds its time column as written: a log at two rates (made
/// in memory, as a converter of another format might) is refused when read back, naming
/// the samples, not analysed at one τ0.
#[test]
fn a_binary_log_at_two_rates_is_refused_naming_the_samples() {
    let mut t: Vec<f64> = uniform(3000, 0.01);
    t.extend((1..=7000).map(|k| 29.99 + k as f64 * 0.02));
    let n = t.len();
    let log = ImuLog::new(
        "two",
        Some(t),
        0.02,
        vec![driftless::io::Channel {
            name: "gx".into(),
            quantity: driftless::io::Quantity::AngularRate,
            source_unit: "rad/s".into(),
            values: (0..n).map(|k| (k % 7) as f64 * 1e-3).collect(),
        }],
    );
    let d = tmp("binrate");
    let path = d.join("two.dlog");
    write_binary_file(&log, &path).unwrap();
    let e = read_log_file(&path, &TextOptions::default()).unwrap_err();
    let msg = e.to_string();
    match &e {
        LogError::RateChange {
            at, first, last, ..
        } => {
            assert_eq!((at.line, *first, *last), (None, 0, 2999), "{msg}");
        }
        _ => panic!("{msg}"),
    }
    assert!(
        msg.contains("two.dlog")
            && msg.contains("100 Hz")
            && msg.contains("50 Hz")
            && msg.contains("from sample 0 "),
        "{msg}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// The whole-file text readers (KF-GINS IMU and GNSS, RTKLIB `.pos` and `.tag`) end in an
/// error within their first MiB on `/dev/zero` and on a file without line ends, and read a
/// pipe through the one handle, giving what the file gives.
#[cfg(unix)]
#[test]
fn whole_file_text_readers_are_bounded_and_read_pipes_once() {
    use driftless::io::nav::{
        FposSize, GnssReadOptions, read_kfgins_gnss_file, read_kfgins_imu_file,
        read_rtklib_pos_file, read_rtklib_tag_file,
    };
    let d = tmp("whole");
    let clock = std::time::Instant::now();
    let zero = Path::new("/dev/zero");
    let msgs = [
        read_kfgins_imu_file(zero).unwrap_err().to_string(),
        read_kfgins_gnss_file(zero, &GnssReadOptions::default())
            .unwrap_err()
            .to_string(),
        read_rtklib_pos_file(zero, &GnssReadOptions::default())
            .unwrap_err()
            .to_string(),
        read_rtklib_tag_file(zero, FposSize::Auto)
            .unwrap_err()
            .to_string(),
    ];
    for m in &msgs[..3] {
        assert!(m.contains("/dev/zero: binary data"), "{m}");
    }
    assert!(msgs[3].contains("TIMETAG RTKLIB"), "{}", msgs[3]);
    let long = d.join("long.txt");
    std::fs::write(&long, vec![b'1'; 3 << 20]).unwrap();
    let m = read_kfgins_gnss_file(&long, &GnssReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        m.contains("long.txt:1") && m.contains("longer than 1 MiB"),
        "{m}"
    );
    assert!(clock.elapsed().as_secs_f64() < 5.0);

    // A KF-GINS GNSS file through a FIFO: the same fixes as the file.
    let text: String = (0..500)
        .map(|k| {
            format!(
                "{:.3} 30.{:08} 114.3 20.0 0.02 0.02 0.04\n",
                356400.0 + k as f64,
                k * 7
            )
        })
        .collect();
    let file = d.join("gnss.txt");
    std::fs::write(&file, &text).unwrap();
    let fifo = d.join("gnss.fifo");
    if mkfifo(&fifo).is_none() {
        return;
    }
    let writer = {
        let fifo = fifo.clone();
        let bytes = text.clone().into_bytes();
        std::thread::spawn(move || {
            let mut f = std::fs::OpenOptions::new().write(true).open(fifo).unwrap();
            f.write_all(&bytes).unwrap();
        })
    };
    let through = read_kfgins_gnss_file(&fifo, &GnssReadOptions::default()).unwrap();
    writer.join().unwrap();
    let direct = read_kfgins_gnss_file(&file, &GnssReadOptions::default()).unwrap();
    assert_eq!(through.time_s, direct.time_s);
    assert_eq!(through.lat_rad, direct.lat_rad);
    assert_eq!(through.len(), 500);
    let _ = std::fs::remove_dir_all(&d);
}
