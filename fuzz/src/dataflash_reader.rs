//! Arbitrary bytes into the ArduPilot DataFlash reader: no panic, no NaN out of the IMU
//! extraction, truncation offsets inside the input, skipped bytes ≤ input length.

use driftless::io::{imu_logs_from_dataflash, parse_dataflash};

/// One fuzz input; panics on a broken invariant.
pub fn run(data: &[u8]) {
    if let Ok(df) = parse_dataflash(data, "fuzz") {
        assert!(df.truncated_at_byte.is_none_or(|t| t < data.len() as u64));
        assert!(df.skipped_bytes <= data.len() as u64);
        for (name, n) in df.message_counts() {
            assert_eq!(df.count(&name), n);
        }
    }
    if let Ok(r) = imu_logs_from_dataflash(data, "fuzz") {
        for imu in &r.imus {
            for c in &imu.log.channels {
                assert_eq!(c.values.len(), imu.log.len());
                assert!(c.values.iter().all(|v| v.is_finite()));
            }
        }
    }
}
