//! Deterministic mutation fuzzing of the text and binary readers: bit flips, truncation,
//! inserted and deleted bytes on valid inputs. Asserts no panic, and that every text-reader
//! error that concerns a line names a line that exists.

use driftless::io::{
    ColumnRef, GapPolicy, LogError, TextOptions, read_binary, read_text, read_text_bytes,
    write_binary,
};

struct XorShift(u64);
impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const SEEDS: [&str; 4] = [
    "# comment\ntime [s],gx [deg/s],az [g]\n0,0.1,1\n0.01,-0.2,0.99 # c\n0.02,3e-3,1.01\n\n0.03,1,1\n",
    "0.0 1 2 3\n0.01 4 5 6\n0.02 7 8 9\n0.03 1 1 1\n",
    "t;a;b\n0;1;2\n1;3;4\r\n2;5;6\n",
    "1.5\n2.5\n# x\n3.5\n",
];

fn mutate(rng: &mut XorShift, seed: &[u8]) -> Vec<u8> {
    let mut v = seed.to_vec();
    for _ in 0..1 + rng.below(3) {
        match rng.below(5) {
            0 if !v.is_empty() => {
                let i = rng.below(v.len());
                v[i] ^= 1 << rng.below(8);
            }
            1 => v.truncate(rng.below(v.len() + 1)),
            2 => {
                let i = rng.below(v.len() + 1);
                let pick = b",;\t #\n\r.-+e0123456789naif\xff";
                v.insert(i, pick[rng.below(pick.len())]);
            }
            3 if !v.is_empty() => {
                let i = rng.below(v.len());
                v.remove(i);
            }
            _ => {
                let i = rng.below(v.len() + 1);
                v.insert(i, rng.next() as u8);
            }
        }
    }
    v
}

#[test]
fn mutated_text_never_panics_and_errors_name_lines() {
    let mut rng = XorShift(0x1234_5678_9ABC_DEF1);
    let opts = [
        TextOptions::default()
            .with_time(ColumnRef::Index(1), None)
            .with_gap_policy(GapPolicy::Bridge),
        TextOptions::default().with_time(ColumnRef::Index(1), None),
        TextOptions::default().with_rate_hz(100.0),
    ];
    let (mut ok, mut errs) = (0, 0);
    for case in 0..6000 {
        let seed = SEEDS[case % SEEDS.len()].as_bytes();
        let input = mutate(&mut rng, seed);
        let nlines = input.split(|&b| b == b'\n').count();
        for (k, o) in opts.iter().enumerate() {
            let mut o = o.clone();
            o.chunk_bytes = 64 + rng.below(64);
            let whole = read_text_bytes(&input, "fuzz.csv", &o);
            let streamed = read_text(&input[..], "fuzz.csv", &o);
            match (&whole, &streamed) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(a, b);
                    assert!(
                        a.channels
                            .iter()
                            .all(|c| c.values.iter().all(|v| v.is_finite()))
                    );
                    assert!(a.channels.iter().all(|c| c.values.len() == a.len()));
                    ok += 1;
                }
                (Err(a), Err(b)) => {
                    assert_eq!(a.to_string(), b.to_string());
                    let s = a.to_string();
                    assert!(s.starts_with("fuzz.csv"), "{s}");
                    match a {
                        LogError::NonNumeric { .. }
                        | LogError::EmptyField { .. }
                        | LogError::NonFinite { .. }
                        | LogError::Ragged { .. } => {
                            let loc = a.location().unwrap();
                            let line = loc.line.unwrap_or(0);
                            assert!(line >= 1 && line <= nlines, "case {case}/{k}: {s}");
                            assert!(loc.column.is_some(), "{s}");
                        }
                        LogError::NonMonotonicTime { .. }
                        | LogError::DuplicateTime { .. }
                        | LogError::TimeGap { .. }
                        | LogError::RateChange { .. }
                        | LogError::LineTooLong { .. }
                        | LogError::HeaderOnly { .. } => {
                            let line = a.line().unwrap_or(0);
                            assert!(line >= 1 && line <= nlines, "case {case}/{k}: {s}");
                        }
                        LogError::BinaryData { byte_offset, .. } => {
                            let at = usize::try_from(*byte_offset).unwrap_or(usize::MAX);
                            assert!(at < input.len(), "case {case}/{k}: {s}");
                            let b = input[at];
                            assert!(!(0x20..0x80).contains(&b), "case {case}/{k}: {s}");
                        }
                        _ => {}
                    }
                    errs += 1;
                }
                _ => panic!(
                    "case {case}: chunked and whole reads disagree: {whole:?} vs {streamed:?}"
                ),
            }
        }
    }
    assert!(
        ok > 1000 && errs > 1000,
        "ok {ok}, errors {errs}: mutations too weak or too strong"
    );
}

#[test]
fn mutated_binary_never_panics() {
    let log = read_text_bytes(
        SEEDS[0].as_bytes(),
        "s",
        &TextOptions::default().with_time(ColumnRef::Index(1), None),
    )
    .unwrap();
    let mut bin = Vec::new();
    write_binary(&log, &mut bin).unwrap();
    let mut rng = XorShift(42);
    let mut errs = 0;
    for _ in 0..5000 {
        let input = mutate(&mut rng, &bin);
        match read_binary(&input[..], "fuzz.dlog") {
            Ok(back) => {
                assert!(
                    back.channels
                        .iter()
                        .all(|c| c.values.len() == back.len()
                            && c.values.iter().all(|v| v.is_finite()))
                )
            }
            Err(e) => {
                assert!(e.to_string().starts_with("fuzz.dlog"));
                errs += 1;
            }
        }
    }
    assert!(errs > 2500, "{errs}");
}

/// The real PX4 ULog and truncated ArduPilot DataFlash logs (`../shared/data/logs`) with
/// bit flips, overwritten bytes and cuts: no panic, IMU logs finite when they come out.
#[cfg(feature = "autopilot-logs")]
#[test]
#[ignore = "needs shared data"]
fn mutated_autopilot_logs_never_panic() {
    use driftless::io::imu_logs_from_autopilot;
    let dir = match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => std::path::PathBuf::from(p),
        None => std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    };
    let ulog = std::fs::read(dir.join("logs/px4_ulog/sample_log_small.ulg")).unwrap();
    let df = std::fs::read(dir.join("logs/ardupilot_dataflash/backend_log_80k.bin")).unwrap();
    // The ULog is cut to its first 64 KiB (definitions, parameters and the first data) to
    // keep 300 parses cheap; the DataFlash log is used whole.
    let seeds = [ulog[..ulog.len().min(65_536)].to_vec(), df];
    let mut rng = XorShift(0xD1F7_1E55_0000_0001);
    for round in 0..600 {
        let mut v = seeds[round % 2].clone();
        for _ in 0..1 + rng.below(8) {
            let i = rng.below(v.len());
            match rng.below(3) {
                0 => v[i] ^= 1 << rng.below(8),
                1 => v[i] = rng.next() as u8,
                _ => v.truncate(i.max(1)),
            }
        }
        if let Ok(Some(r)) = imu_logs_from_autopilot(&v, "mut") {
            for imu in &r.imus {
                for c in &imu.log.channels {
                    assert_eq!(c.values.len(), imu.log.len());
                    assert!(c.values.iter().all(|x| x.is_finite()));
                }
            }
        }
    }
}
