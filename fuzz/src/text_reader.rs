//! Arbitrary bytes into the text reader, under several option sets and chunk sizes.
//! Invariants: no panic; on success equal-length finite channels; errors name the input.

use driftless::io::{ColumnRef, GapPolicy, TextOptions, read_text, read_text_bytes};

/// One fuzz input; panics on a broken invariant.
pub fn run(data: &[u8]) {
    let (sel, body) = match data.split_first() {
        Some((s, b)) => (*s, b),
        None => (0, data),
    };
    let mut o = match sel % 3 {
        0 => TextOptions::default().with_time(ColumnRef::Index(1), None),
        1 => TextOptions::default().with_rate_hz(100.0),
        _ => TextOptions::default()
            .with_time(ColumnRef::Index(1), None)
            .with_gap_policy(GapPolicy::Split),
    };
    o.chunk_bytes = 64 + usize::from(sel);
    let a = read_text(body, "fuzz", &o);
    let b = read_text_bytes(
        body,
        "fuzz",
        &TextOptions {
            chunk_bytes: 1 << 20,
            ..o
        },
    );
    match (&a, &b) {
        (Ok(x), Ok(y)) => {
            assert_eq!(x, y);
            for c in &x.channels {
                assert_eq!(c.values.len(), x.len());
                assert!(c.values.iter().all(|v| v.is_finite()));
            }
        }
        (Err(x), Err(y)) => {
            assert_eq!(x.to_string(), y.to_string());
            assert!(x.to_string().starts_with("fuzz"));
        }
        _ => panic!("chunk size changed the outcome"),
    }
}
