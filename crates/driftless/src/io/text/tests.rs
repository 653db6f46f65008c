use super::fields::{Delim, detect_delimiter, split_pieces};
use super::header::split_name_unit;
use super::parse::LineMap;
use super::*;

#[test]
fn pieces_cover_data_at_line_ends() {
    let data = b"1\n22\n333\n4444\n55555\n";
    for k in 1..8 {
        let p = split_pieces(data, k);
        assert_eq!(p.concat(), data.to_vec());
        for piece in &p {
            assert_eq!(piece.last(), Some(&b'\n'));
        }
    }
}

/// The outcome must not depend on how much of the input the first chunk holds:
/// inputs whose first lines disagree on the delimiter, and one whose first bytes are
/// partly not UTF-8 (found by fuzzing), give the same log or error at every chunk size
/// as in one piece.
#[test]
fn chunk_size_does_not_change_the_outcome() {
    let inputs: [&[u8]; 4] = [
        b"# rate-only log\ngyro_x [deg/\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\
              \x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\x8d\
              \x8d\x8d\x8d\x8ds];gyro_y [deg/s];gyro_z [deg/s]\n0.5;-0.25;1e-3\n\
              0.52;-0.26;1.1e-3\n0.49;-0.24;0.9e-3\n",
        b"time,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z\n0.00,nan-0.02,0.03,0.1,0.2,-9.8\n\
              0.01,0.011,-0.021,0.031,0.11,0.21,-9.81\n0.02,0.012,-0.022,0.032,0.12,0.22,-9.79\n",
        b"\" rate-only log\ngyro_x [deg/s];gyro_y [deg/s];gyro_z [deg/s]\n0.5;-0.25;1e-3\n\
              0.52;-0.26;1.1e-3\n0.49;-0.24;0.9e-3\n",
        b"t,a,b\n0,1,2\n1 2 3\n2 3 4\n3 4 5\n4 5 6\n",
    ];
    for (k, input) in inputs.into_iter().enumerate() {
        let base = TextOptions::default().with_rate_hz(100.0);
        let whole = read_text_bytes(input, "f", &base).map_err(|e| e.to_string());
        for chunk_bytes in [1, 16, 40, 64, 65, 100] {
            let o = TextOptions {
                chunk_bytes,
                ..base.clone()
            };
            let chunked = read_text(input, "f", &o).map_err(|e| e.to_string());
            assert_eq!(chunked, whole, "input {k}, chunk {chunk_bytes}");
        }
    }
}

#[test]
fn header_units_in_brackets() {
    assert_eq!(
        split_name_unit("gyro_x [deg/s]"),
        ("gyro_x".into(), Some("deg/s".into()))
    );
    assert_eq!(
        split_name_unit("tick(ms)"),
        ("tick".into(), Some("ms".into()))
    );
    assert_eq!(split_name_unit("acc_z"), ("acc_z".into(), None));
}

#[test]
fn delimiter_detection() {
    assert_eq!(detect_delimiter(b"1,2,3"), Delim::Byte(b','));
    assert_eq!(detect_delimiter(b"1;2,5;3"), Delim::Byte(b';'));
    assert_eq!(detect_delimiter(b"a\tb c\td"), Delim::Byte(b'\t'));
    assert_eq!(detect_delimiter(b"  1\t\t2 3"), Delim::Whitespace);
    assert_eq!(detect_delimiter(b"1 2 3 # a, b"), Delim::Whitespace);
}

#[test]
fn line_map_follows_anchors() {
    let m = LineMap {
        anchors: vec![(0, 3), (5, 10)],
    };
    assert_eq!(m.line_of(0), 3);
    assert_eq!(m.line_of(4), 7);
    assert_eq!(m.line_of(5), 10);
    assert_eq!(m.line_of(9), 14);
}
