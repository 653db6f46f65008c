//! Logs as users keep them: gzip-compressed, and with the time column named in the header
//! but not given on the command line.

use std::io::Write;

use driftless::io::{
    ImuLog, LogError, TextOptions, read_log_file, read_text_bytes, write_binary_file,
};

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-gz-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).expect("dir");
    d
}

fn csv(rows: usize) -> String {
    let mut s = String::from("t [s],gyro_x [deg/s],accel_z [g]\n");
    for k in 0..rows {
        s.push_str(&format!(
            "{},{},{}\n",
            k as f64 / 100.0,
            0.05 * ((k * 7) % 11) as f64,
            -1.0 + 0.00333 * ((k * 3) % 5) as f64
        ));
    }
    s
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).expect("compress");
    e.finish().expect("finish")
}

fn same(a: &ImuLog, b: &ImuLog) {
    assert_eq!(a.len(), b.len());
    assert_eq!(a.time_s, b.time_s);
    assert_eq!(a.tau0_s, b.tau0_s);
    assert_eq!(a.channels.len(), b.channels.len());
    for (x, y) in a.channels.iter().zip(&b.channels) {
        assert_eq!((x.name.as_str(), x.quantity), (y.name.as_str(), y.quantity));
        assert_eq!(x.values, y.values);
    }
}

#[test]
fn a_time_column_is_found_by_its_header_name() {
    let text = csv(500);
    let log = read_text_bytes(text.as_bytes(), "t.csv", &TextOptions::default()).expect("read");
    assert_eq!(log.channels.len(), 2, "the time is not a data channel");
    assert!((log.tau0_s - 0.01).abs() < 1e-12);
    assert!(
        log.notes.iter().any(|n| n.contains("column 1 (t)")),
        "{:?}",
        log.notes
    );
    // The unit in brackets applies.
    let ns = "timestamp [ns],w_x [rad/s]\n1000000000,0.1\n1005000000,0.2\n1010000000,0.3\n";
    let log = read_text_bytes(ns.as_bytes(), "euroc.csv", &TextOptions::default()).expect("ns");
    assert!((log.tau0_s - 0.005).abs() < 1e-12, "{}", log.tau0_s);
    assert_eq!(log.time_s.as_ref().expect("time")[0], 1.0);
    // Two candidates: which is the time cannot be guessed.
    let two = "time,timestamp,w [rad/s]\n0,0,1\n1,1,2\n";
    let e = read_text_bytes(two.as_bytes(), "two.csv", &TextOptions::default())
        .expect_err("ambiguous")
        .to_string();
    assert!(e.contains("two.csv") && e.contains("--time-column"), "{e}");
    assert!(e.contains("1=time") && e.contains("2=timestamp"), "{e}");
    // Detection off: the field is data, and a rate is needed.
    let off = TextOptions {
        detect_time_column: false,
        rate_hz: Some(100.0),
        ..TextOptions::default()
    };
    let plain_t = text.replacen("t [s]", "t", 1);
    let log = read_text_bytes(plain_t.as_bytes(), "t.csv", &off).expect("off");
    assert_eq!(log.channels.len(), 3);
    assert!(log.time_s.is_none());
    // No time name and no rate: the error says which flags to give.
    let none = "a,b\n1,2\n3,4\n";
    let e = read_text_bytes(none.as_bytes(), "none.csv", &TextOptions::default())
        .expect_err("no time")
        .to_string();
    assert!(e.contains("none.csv:1"), "{e}");
    assert!(e.contains("--rate") && e.contains("--time-column"), "{e}");
    assert!(
        !e.contains("rate_hz"),
        "names a flag, not a config key: {e}"
    );
}

#[test]
fn gzip_logs_read_like_the_plain_file_and_a_cut_stream_is_an_error() {
    let dir = tmp("read");
    let text = csv(20_000);
    let plain = dir.join("log.csv");
    std::fs::write(&plain, &text).expect("write");
    let gz = dir.join("log.csv.gz");
    std::fs::write(&gz, gzip(text.as_bytes())).expect("write gz");
    let opts = TextOptions::default();
    let a = read_log_file(&plain, &opts).expect("plain");
    let b = read_log_file(&gz, &opts).expect("gz");
    same(&a, &b);
    // Two concatenated members (what `cat a.gz b.gz` gives) read as one stream.
    let half = text.len() / 2;
    let cut = text[..half].rfind('\n').expect("line") + 1;
    let mut two = gzip(&text.as_bytes()[..cut]);
    two.extend(gzip(&text.as_bytes()[cut..]));
    let multi = dir.join("multi.csv.gz");
    std::fs::write(&multi, two).expect("write multi");
    same(&a, &read_log_file(&multi, &opts).expect("multi"));
    // A binary log inside gzip.
    let dlog = dir.join("log.dlog");
    write_binary_file(&a, &dlog).expect("dlog");
    let dgz = dir.join("log.dlog.gz");
    std::fs::write(&dgz, gzip(&std::fs::read(&dlog).expect("read dlog"))).expect("dgz");
    same(&a, &read_log_file(&dgz, &opts).expect("dlog.gz"));
    // A truncated download: an error naming the file, never a shorter log.
    let bytes = std::fs::read(&gz).expect("gz bytes");
    let short = dir.join("short.csv.gz");
    std::fs::write(&short, &bytes[..bytes.len() * 2 / 3]).expect("short");
    match read_log_file(&short, &opts) {
        Err(e @ LogError::Io { .. }) => {
            assert!(e.to_string().contains("short.csv.gz"), "{e}")
        }
        other => panic!("truncated gzip: {other:?}"),
    }
    // Corrupt bytes in the middle of the stream.
    let mut bad = bytes.clone();
    let mid = bad.len() / 2;
    for b in &mut bad[mid..mid + 64] {
        *b ^= 0x5a;
    }
    let corrupt = dir.join("corrupt.csv.gz");
    std::fs::write(&corrupt, bad).expect("corrupt");
    let e = read_log_file(&corrupt, &opts).expect_err("corrupt gzip");
    assert!(e.to_string().contains("corrupt.csv.gz"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
