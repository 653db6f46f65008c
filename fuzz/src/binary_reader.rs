//! Arbitrary bytes into the binary reader: no panic, no huge allocation, no NaN out.

use driftless::io::read_binary;

/// One fuzz input; panics on a broken invariant.
pub fn run(data: &[u8]) {
    if let Ok(log) = read_binary(data, "fuzz") {
        for c in &log.channels {
            assert_eq!(c.values.len(), log.len());
            assert!(c.values.iter().all(|v| v.is_finite()));
        }
    }
}
