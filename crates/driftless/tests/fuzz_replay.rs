//! The fuzz targets' invariants under stable `cargo test`: every seed of
//! `fuzz/corpus/<target>/`, and a fixed set of deterministic mutations of the seeds (bit
//! flips, interesting bytes, runs of one byte, truncations, deletions, duplications,
//! splices of two seeds, extreme numbers), through the same harness bodies libFuzzer runs
//! (`fuzz/src`, included here). A failure names the seed and the mutation and prints the
//! input.

#[path = "../../../fuzz/src/lib.rs"]
mod harness;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// Mutations per seed; with ~60 seeds a few thousand inputs in all.
const MUTATIONS_PER_SEED: usize = 80;

/// The library's deterministic generator, with a uniform integer draw.
struct Rng(driftless::sim::rng::Rng);

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(driftless::sim::rng::Rng::seed_from_u64(seed))
    }
    /// Uniform in `0..n` (`n` > 0).
    fn below(&mut self, n: usize) -> usize {
        (self.0.next_u64() % n as u64) as usize
    }
}

/// Bytes that often reach a parser's corners.
const INTERESTING: &[u8] = b"\0\xff\x7f\x80\n\r,;. -+eE09[]=\"#:x";

/// One mutation of `seed` (`other`: a second seed to splice with), and what it did.
fn mutate(rng: &mut Rng, seed: &[u8], other: &[u8]) -> (Vec<u8>, String) {
    let mut b = seed.to_vec();
    if b.is_empty() {
        b.push(0);
    }
    let at = rng.below(b.len());
    let what = match rng.below(8) {
        0 => {
            let bit = rng.below(8);
            b[at] ^= 1 << bit;
            format!("flip bit {bit} of byte {at}")
        }
        1 => {
            let v = INTERESTING[rng.below(INTERESTING.len())];
            b[at] = v;
            format!("byte {at} := 0x{v:02x}")
        }
        2 => {
            b.truncate(at);
            format!("truncate at {at}")
        }
        3 => {
            let end = (at + 1 + rng.below(16)).min(b.len());
            b.drain(at..end);
            format!("delete {at}..{end}")
        }
        4 => {
            let end = (at + 1 + rng.below(64)).min(b.len());
            let piece = b[at..end].to_vec();
            let to = rng.below(b.len() + 1);
            b.splice(to..to, piece);
            format!("copy {at}..{end} to {to}")
        }
        5 => {
            let from = rng.below(other.len() + 1);
            b.truncate(at);
            b.extend_from_slice(&other[from..]);
            format!("splice at {at} with another seed from {from}")
        }
        6 => {
            // A run of one byte (a stretch of binary data in a text, say).
            let v = rng.below(256) as u8;
            let end = (at + 1 + rng.below(64)).min(b.len());
            b[at..end].fill(v);
            format!("bytes {at}..{end} := 0x{v:02x}")
        }
        _ => {
            // A number replaced by an extreme one, where the seed is text.
            let v: &[u8] = [
                &b"1e308"[..],
                b"-0",
                b"nan",
                b"inf",
                b"99999999999999999999",
                b"1e-320",
            ][rng.below(6)];
            let end = (at + 1 + rng.below(8)).min(b.len());
            b.splice(at..end, v.iter().copied());
            format!("bytes {at}..{end} := {:?}", String::from_utf8_lossy(v))
        }
    };
    (b, what)
}

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus")
}

/// The seeds of one target, by file name.
fn seeds(target: &str) -> Vec<(String, Vec<u8>)> {
    let dir = corpus_dir().join(target);
    let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let mut out: Vec<(String, Vec<u8>)> = entries
        .map(|e| {
            let p = e.expect("corpus entry").path();
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (
                p.file_name().expect("name").to_string_lossy().into_owned(),
                bytes,
            )
        })
        .collect();
    out.sort();
    out
}

/// Runs `run` on one input; on a panic, the description of the input.
fn run_one(run: fn(&[u8]), input: &[u8], what: impl Fn() -> String) -> Option<String> {
    catch_unwind(AssertUnwindSafe(|| run(input)))
        .err()
        .map(|e| {
            let message = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| (*s).to_owned()))
                .unwrap_or_default();
            let shown = input.len().min(512);
            format!(
                "{}: {message}\n  input ({} bytes): {:?}",
                what(),
                input.len(),
                String::from_utf8_lossy(&input[..shown])
            )
        })
}

/// Seeds and their mutations through one target; panics listing every failing input.
fn replay(target: &str) {
    let run = harness::TARGETS
        .iter()
        .find(|(n, _)| *n == target)
        .map(|(_, r)| *r)
        .unwrap_or_else(|| panic!("no harness {target}"));
    let seeds = seeds(target);
    assert!(!seeds.is_empty(), "fuzz/corpus/{target} has no seed");
    let mut failures = Vec::new();
    let mut rng = Rng::new(0x5eed ^ target.len() as u64);
    let mut runs = 0usize;
    for (i, (name, seed)) in seeds.iter().enumerate() {
        assert!(seed.len() < 4096, "{target}/{name}: a seed stays small");
        failures.extend(run_one(run, seed, || format!("{target}/{name}")));
        for k in 0..MUTATIONS_PER_SEED {
            let other = &seeds[(i + 1 + k) % seeds.len()].1;
            let (input, what) = mutate(&mut rng, seed, other);
            failures.extend(run_one(run, &input, || format!("{target}/{name}, {what}")));
            runs += 1;
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {runs} inputs broke an invariant:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn every_corpus_folder_has_a_harness_and_back() {
    let mut folders: Vec<String> = std::fs::read_dir(corpus_dir())
        .expect("fuzz/corpus")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    folders.sort();
    let targets: Vec<&str> = harness::TARGETS.iter().map(|(n, _)| *n).collect();
    assert_eq!(folders, targets);
}

#[test]
fn mutations_are_deterministic_and_change_the_input() {
    let seed = b"t,gx\n0,1\n1,2\n";
    let (mut a, mut b) = (Rng::new(7), Rng::new(7));
    let mut changed = 0;
    for _ in 0..100 {
        let x = mutate(&mut a, seed, b"other");
        assert_eq!(x, mutate(&mut b, seed, b"other"));
        changed += usize::from(x.0 != seed);
    }
    assert!(changed > 90, "{changed}");
}

#[test]
fn binary_reader() {
    replay("binary_reader");
}

#[test]
fn config_formats() {
    replay("config_formats");
}

#[test]
fn dataflash_reader() {
    replay("dataflash_reader");
}

#[test]
fn log_input() {
    replay("log_input");
}

#[test]
fn nav_formats() {
    replay("nav_formats");
}

#[test]
fn text_reader() {
    replay("text_reader");
}

#[test]
fn ulog_reader() {
    replay("ulog_reader");
}

#[test]
fn rosbag_reader() {
    replay("rosbag_reader");
}
