//! Arbitrary bytes through the file-opening path: written to a regular file and, on Unix,
//! fed through a FIFO (a non-regular input: no size, no seeking, read once), then opened
//! with `LogInput::open` and read by the reader the first byte selects (`read_log` with a
//! sample rate or a time column, `read_all`, `read_autopilot`); both kinds of input also
//! go through `read_config_text` with a small cap.
//!
//! Invariants: no panic; the sniffed format matches the magic bytes; `read_all` gives back
//! the bytes; on success equal-length finite channels and finite times; errors start with
//! the input's name; a FIFO gives the same log or error as a regular file holding the same
//! bytes (a binary log's error may be worded differently: a regular file's size is checked
//! first; a ROS bag from a pipe is always refused, as it is read twice); `read_config_text` is `Ok` exactly for UTF-8 without NUL within the cap, and
//! then returns the bytes unchanged. Memory stays bounded by the small caps below.

use std::io::{ErrorKind, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use driftless::io::{ColumnRef, ImuLog, InputFormat, LogError, LogInput, TextOptions};

use super::check;

/// Longest text line accepted (the library's default is 1 MiB).
const MAX_LINE_BYTES: usize = 512;
/// Largest configuration text accepted.
const MAX_CONFIG_BYTES: u64 = 1024;
/// Longest input fed through the FIFO: `PIPE_BUF`, so the writer's one `write` is atomic
/// and done before the reader sees a byte (the reader may stop early without the writer
/// meeting a closed pipe).
const MAX_PIPE_BYTES: usize = 4096;

/// How one input read: the outcome of each call with the input's name replaced by
/// `<input>`, so a regular file and a FIFO can be compared.
#[derive(Debug, PartialEq)]
struct Outcome {
    opened: Result<(InputFormat, bool), String>,
    read: Result<String, String>,
    config: Result<String, String>,
}

/// One fuzz input; panics on a broken invariant.
pub fn run(data: &[u8]) {
    // One FIFO and one scratch file per process: serialise callers (parallel tests).
    static LOCK: Mutex<()> = Mutex::new(());
    let _guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let (sel, body) = data.split_first().map_or((0, data), |(s, b)| (*s, b));
    let dir = scratch_dir();
    let file = dir.join("input.log");
    if let Err(e) = std::fs::write(&file, body) {
        panic!("cannot write the scratch file {}: {e}", file.display());
    }
    let from_file = read(&file, sel, body, true);
    assert_eq!(
        from_file.opened,
        Ok((expected_format(body), true)),
        "sniffed format of a regular file"
    );
    if body.len() <= MAX_PIPE_BYTES
        && let Some(fifo) = fifo(dir)
    {
        let from_pipe = read(fifo, sel, body, false);
        assert_eq!(
            from_pipe.opened,
            Ok((expected_format(body), false)),
            "sniffed format of a FIFO"
        );
        if matches!(expected_format(body), InputFormat::RosBag(_)) && sel % 4 < 2 {
            // A ROS bag is read twice (topics, then messages): a FIFO is refused whatever
            // the regular file gives.
            assert!(
                from_pipe
                    .read
                    .as_ref()
                    .is_err_and(|m| m.contains("give a regular file")),
                "FIFO read of a ROS bag {:?}",
                from_pipe.read
            );
        } else if expected_format(body) == InputFormat::Binary && from_file.read.is_err() {
            // A regular file's size is checked against the header before reading; a pipe
            // finds the same truncation or excess at the column where it shows.
            assert!(from_pipe.read.is_err(), "FIFO read {:?}", from_pipe.read);
        } else if matches!(expected_format(body), InputFormat::RosBag(_))
            && from_pipe.read != from_file.read
        {
            // The bag reader reads twice (topics, then messages), so it refuses a pipe
            // whatever the bytes hold; a regular file reaches the reader's own errors.
            assert!(
                from_pipe
                    .read
                    .as_ref()
                    .is_err_and(|e| e.contains("read twice")),
                "FIFO read {:?}, regular file {:?}",
                from_pipe.read,
                from_file.read
            );
        } else {
            assert_eq!(
                from_pipe.read, from_file.read,
                "FIFO and regular file differ"
            );
        }
        assert_eq!(
            from_pipe.config, from_file.config,
            "FIFO and regular file differ"
        );
    }
}

/// The format the magic bytes at the start of `body` name.
fn expected_format(body: &[u8]) -> InputFormat {
    use driftless::io::{dataflash, ulog};
    if body.starts_with(&driftless::io::GZIP_MAGIC) {
        InputFormat::Gzip
    } else if body.starts_with(driftless::io::binary::MAGIC) {
        InputFormat::Binary
    } else if let Some(f) = driftless::io::rosbag::detect_format(&body[..body.len().min(8)]) {
        InputFormat::RosBag(f)
    } else if body.starts_with(&ulog::MAGIC) {
        InputFormat::ULog
    } else if body.starts_with(&[dataflash::HEAD1, dataflash::HEAD2, 128]) {
        InputFormat::DataFlash
    } else {
        InputFormat::Text
    }
}

/// Opens `path` (a FIFO is fed `body` by a writer thread for each open) and reads it as
/// `sel` asks; the invariants that hold for one input alone are checked here.
fn read(path: &Path, sel: u8, body: &[u8], regular: bool) -> Outcome {
    let name = path.display().to_string();
    let strip = |s: String| s.replace(&name, "<input>");
    let err = |e: &LogError| {
        check::names_input(&name, e);
        strip(e.to_string())
    };
    let (opened, read) = feed(path, body, regular, || match LogInput::open(path) {
        Err(e) => ((Err(err(&e)), Err(String::new())), false),
        Ok(input) => {
            assert_eq!(input.name(), name);
            assert_eq!(
                input.is_autopilot(),
                matches!(input.format(), InputFormat::ULog | InputFormat::DataFlash)
            );
            let opened = Ok((input.format(), input.is_regular_file()));
            let read = match sel % 4 {
                0 | 1 => {
                    let opts = TextOptions {
                        max_line_bytes: MAX_LINE_BYTES,
                        chunk_bytes: 64 + usize::from(sel),
                        ..if sel.is_multiple_of(4) {
                            TextOptions::default().with_rate_hz(100.0)
                        } else {
                            TextOptions::default().with_time(ColumnRef::Index(1), None)
                        }
                    };
                    input
                        .read_log(&opts)
                        .map(|log| log_summary(&log))
                        .map_err(|e| err(&e))
                }
                2 => match input.read_all() {
                    Ok(bytes) => {
                        assert_eq!(bytes, body, "read_all changed the bytes");
                        Ok(format!("{} bytes", bytes.len()))
                    }
                    Err(e) => Err(err(&e)),
                },
                _ => match input.read_autopilot() {
                    Ok(logs) => Ok(logs
                        .imus
                        .iter()
                        .map(|imu| log_summary(&imu.log))
                        .collect::<Vec<_>>()
                        .join("\n")),
                    Err(e) => Err(err(&e)),
                },
            };
            ((opened, read.map(&strip)), true)
        }
    });
    let config = feed(
        path,
        body,
        regular,
        || match driftless::io::read_config_text(path, MAX_CONFIG_BYTES) {
            Ok(text) => {
                assert_eq!(text.as_bytes(), body, "read_config_text changed the text");
                (Ok(format!("{} bytes", text.len())), true)
            }
            Err(e) => {
                let opened = e.kind() == ErrorKind::InvalidData;
                (Err(strip(check::message(&name, &e))), opened)
            }
        },
    );
    let valid = body.len() as u64 <= MAX_CONFIG_BYTES
        && !body.contains(&0)
        && std::str::from_utf8(body).is_ok();
    assert_eq!(config.is_ok(), valid, "read_config_text: {config:?}");
    if let Err(m) = &config {
        let too_big = body.len() as u64 > MAX_CONFIG_BYTES;
        assert!(!too_big || m.contains(&MAX_CONFIG_BYTES.to_string()), "{m}");
    }
    Outcome {
        opened,
        read,
        config,
    }
}

/// The log's invariants, and a text that compares two reads of it.
fn log_summary(log: &ImuLog) -> String {
    for c in &log.channels {
        assert_eq!(c.values.len(), log.len());
        assert!(c.values.iter().all(|v| v.is_finite()), "channel {}", c.name);
    }
    if let Some(t) = &log.time_s {
        assert_eq!(t.len(), log.len());
        assert!(t.iter().all(|v| v.is_finite()), "time");
    }
    assert!(log.tau0_s.is_finite(), "tau0_s {}", log.tau0_s);
    format!("{log:?}")
}

/// Runs `open_and_read` on `path`. For a FIFO a writer thread feeds `body` (one atomic
/// write) to the open; `open_and_read` returns its result and whether it opened the path,
/// and when it did not the FIFO is opened here so that the writer is released.
fn feed<T>(
    path: &Path,
    body: &[u8],
    regular: bool,
    open_and_read: impl FnOnce() -> (T, bool),
) -> T {
    if regular {
        return open_and_read().0;
    }
    std::thread::scope(|s| {
        let writer = s.spawn(|| -> std::io::Result<()> {
            let mut w = std::fs::OpenOptions::new().write(true).open(path)?;
            w.write_all(body)
        });
        let (out, opened) = open_and_read();
        if !opened {
            let mut sink = Vec::new();
            let _ = std::fs::File::open(path).and_then(|mut f| f.read_to_end(&mut sink));
        }
        match writer.join() {
            Ok(Ok(())) => out,
            Ok(Err(e)) => panic!("FIFO writer: {e}"),
            Err(_) => panic!("FIFO writer panicked"),
        }
    })
}

/// A per-process scratch folder under the system's temporary folder.
fn scratch_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::temp_dir().join(format!("driftless-fuzz-{}", std::process::id()));
        if let Err(e) = std::fs::create_dir_all(&d) {
            panic!("cannot create {}: {e}", d.display());
        }
        d
    })
}

/// A FIFO in the scratch folder, made once by `mkfifo` (`None` where there is none: the
/// non-regular path is then not exercised).
fn fifo(dir: &Path) -> Option<&'static Path> {
    static FIFO: OnceLock<Option<PathBuf>> = OnceLock::new();
    FIFO.get_or_init(|| {
        let p = dir.join("input.fifo");
        let _ = std::fs::remove_file(&p);
        let made = std::process::Command::new("mkfifo")
            .arg(&p)
            .status()
            .is_ok_and(|s| s.success());
        made.then_some(p)
    })
    .as_deref()
}
