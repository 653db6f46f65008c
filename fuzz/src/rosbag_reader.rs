//! Arbitrary bytes into the ROS 1 bag / MCAP / sqlite3 bag reader (the seeds are short
//! bags written by the Python `rosbags` package, uncompressed and with bz2 / lz4 ROS 1
//! chunks and zstd / lz4 MCAP chunks, and a 512-byte-page `.db3` written by Python's
//! `sqlite3` with rosbag2's tables and rosbags' CDR messages, one row in an overflow page):
//! no panic, no huge allocation, an error's byte offset inside the input, and a log's
//! channels of equal length, finite, in increasing time.
//! The reader takes a file (it reads the bag twice), so each input is written to a
//! temporary file first.

use std::sync::atomic::{AtomicU64, Ordering};

use driftless::io::{LogError, read_rosbag_file};

static NEXT: AtomicU64 = AtomicU64::new(0);

/// One fuzz input; panics on a broken invariant.
pub fn run(data: &[u8]) {
    let path = std::env::temp_dir().join(format!(
        "driftless-fuzz-rosbag-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    if std::fs::write(&path, data).is_err() {
        return;
    }
    for topic in [None, Some("/imu")] {
        match read_rosbag_file(&path, topic) {
            Ok(log) => {
                let t = log.time_s.as_deref().unwrap_or_default();
                assert_eq!(t.len(), log.len());
                assert!(t.windows(2).all(|w| w[1] > w[0]));
                assert!(log.tau0_s > 0.0);
                for c in &log.channels {
                    assert_eq!(c.values.len(), log.len());
                    assert!(c.values.iter().all(|v| v.is_finite()));
                }
            }
            Err(LogError::AtByte { byte_offset, .. }) => {
                assert!(byte_offset <= data.len() as u64)
            }
            Err(_) => {}
        }
    }
    let _ = std::fs::remove_file(&path);
}
