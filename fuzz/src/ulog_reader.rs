//! Arbitrary bytes into the PX4 ULog reader (prefixed with a valid header half the time so
//! the fuzzer reaches the message parser): no panic, no huge allocation, no NaN out of the
//! IMU extraction, truncation offsets inside the input.

use driftless::io::{imu_logs_from_ulog, parse_ulog, ulog::MAGIC};

/// One fuzz input; panics on a broken invariant.
pub fn run(data: &[u8]) {
    let mut with_header = MAGIC.to_vec();
    with_header.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0, 0]);
    with_header.extend_from_slice(data);
    for bytes in [data, with_header.as_slice()] {
        if let Ok(u) = parse_ulog(bytes, "fuzz") {
            assert!(u.truncated_at_byte.is_none_or(|t| t < bytes.len() as u64));
            for t in &u.topics {
                for f in &t.fields {
                    assert_eq!(t.column(&f.name).map(|c| c.len()), Some(t.len()));
                }
            }
        }
        if let Ok(r) = imu_logs_from_ulog(bytes, "fuzz") {
            for imu in &r.imus {
                for c in &imu.log.channels {
                    assert_eq!(c.values.len(), imu.log.len());
                    assert!(c.values.iter().all(|v| v.is_finite()));
                }
            }
        }
    }
}
