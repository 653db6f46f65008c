//! Looks at input paths before reading them: what a path is (file, folder, pipe or
//! device, missing) and the first line of a file, for format detection. Reads at most
//! a bounded prefix and never consumes a pipe it was not asked to.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// What a path names, following symbolic links.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PathKind {
    /// Nothing there (or not accessible).
    Missing,
    /// A folder.
    Dir,
    /// A regular file.
    File,
    /// Something readable once that is neither (a pipe, FIFO, device, `/dev/stdin`).
    Other,
}

impl PathKind {
    /// The kind of `path`.
    pub fn of(path: &Path) -> PathKind {
        match std::fs::metadata(path) {
            Err(_) => PathKind::Missing,
            Ok(m) if m.is_dir() => PathKind::Dir,
            Ok(m) if m.is_file() => PathKind::File,
            Ok(_) => PathKind::Other,
        }
    }
}

/// The first line of `path` (with its line ending) read from at most `max_bytes` bytes,
/// or `None` when the file cannot be opened or read.
pub(crate) fn first_line(path: &Path, max_bytes: u64) -> Option<String> {
    let f = std::fs::File::open(path).ok()?;
    let mut line = String::new();
    BufReader::new(f.take(max_bytes))
        .read_line(&mut line)
        .ok()?;
    Some(line)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_first_line() {
        let dir = std::env::temp_dir().join(format!("driftless-probe-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("a.csv");
        std::fs::write(&f, "time,gyro_x\n1,2\n").unwrap();
        assert_eq!(PathKind::of(&dir), PathKind::Dir);
        assert_eq!(PathKind::of(&f), PathKind::File);
        assert_eq!(PathKind::of(&dir.join("none")), PathKind::Missing);
        assert_eq!(first_line(&f, 1024).as_deref(), Some("time,gyro_x\n"));
        assert_eq!(first_line(&f, 4).as_deref(), Some("time"));
        assert_eq!(first_line(&dir.join("none"), 1024), None);
        std::fs::remove_dir_all(&dir).ok();
    }
}
