use super::*;

fn opts() -> TextOptions {
    TextOptions {
        time_column: Some(ColumnRef::Name("time".into())),
        ..TextOptions::default()
    }
}

#[test]
fn a_driftless_csv_cut_at_a_line_end_is_an_error() {
    let rows: String = (0..50)
        .map(|i| format!("{},{}\n", i as f64 * 0.01, i))
        .collect();
    let whole = format!(
        "# driftless log; source: test\n# tau0_s: 0.01; rows: 50; last line: # end of driftless log\n\
             time [s],gyro_x [rad/s]\n{rows}# end of driftless log\n"
    );
    assert_eq!(
        read_text_bytes(whole.as_bytes(), "w.csv", &opts())
            .unwrap()
            .len(),
        50
    );
    let cut: String = whole.lines().take(40).map(|l| format!("{l}\n")).collect();
    let e = read_text_bytes(cut.as_bytes(), "w.csv", &opts()).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(
            e,
            LogError::RowCountMismatch {
                expected: 50,
                found: 37,
                ..
            }
        ) && msg.contains("w.csv"),
        "{msg}"
    );
    // All rows there, the end mark cut off.
    let unmarked = whole.strip_suffix("# end of driftless log\n").unwrap();
    let msg = read_text_bytes(unmarked.as_bytes(), "w.csv", &opts())
        .unwrap_err()
        .to_string();
    assert!(msg.contains("50 found, its last line is missing"), "{msg}");
    // A file of an earlier writer: rows counted, no end mark expected.
    let older = unmarked.replace("; last line: # end of driftless log", "");
    assert_eq!(
        read_text_bytes(older.as_bytes(), "w.csv", &opts())
            .unwrap()
            .len(),
        50
    );
    // Without the driftless header the rows present are read.
    let other = cut.replacen("# driftless log", "# some log", 1);
    assert_eq!(
        read_text_bytes(other.as_bytes(), "o.csv", &opts())
            .unwrap()
            .len(),
        37
    );
}
