//! [`AtomicFile`]: an output file that appears under its final name only once complete.

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// A file being written: bytes go to a temporary file in the destination's folder, which
/// [`AtomicFile::commit`] flushes, syncs and renames over the destination. Dropped without
/// a commit, the temporary file is removed and the destination left as it was.
#[derive(Debug)]
pub struct AtomicFile {
    file: Option<File>,
    /// The temporary file; `None` when the destination is written in place (not a
    /// regular file) or once committed.
    temp: Option<PathBuf>,
    dest: PathBuf,
    durable: bool,
}

/// Distinguishes temporary files of one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// What separates the destination's name from the writer's process id in a temporary
/// file's name.
const PARTIAL: &str = ".partial-";

/// The temporary file for destination `name`, written by process `pid`: `.NAME.partial-PID-N`.
fn partial_name(name: &str, pid: u32, n: u64) -> String {
    format!(".{name}{PARTIAL}{pid}-{n}")
}

/// The destination's name and the writer's process id of the temporary file called
/// `name` (`.NAME.partial-PID-N`, as [`AtomicFile`] names them); `None` for any other name.
pub(super) fn parse_partial(name: &str) -> Option<(&str, u32)> {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let (stem, tail) = name.strip_prefix('.')?.rsplit_once(PARTIAL)?;
    let (pid, n) = tail.split_once('-')?;
    if stem.is_empty() || !digits(pid) || !digits(n) {
        return None;
    }
    Some((stem, pid.parse().ok()?))
}

/// The id of the process that wrote the temporary file called `name`
/// (`.NAME.partial-PID-N`, as [`AtomicFile`] names them); `None` for any other name.
pub fn partial_owner(name: &str) -> Option<u32> {
    parse_partial(name).map(|(_, pid)| pid)
}

impl AtomicFile {
    /// Starts writing `path`. Errors are those of creating the temporary file (a missing
    /// folder, no permission) — reported before any data is produced.
    pub fn create(path: impl AsRef<Path>) -> io::Result<Self> {
        let path = path.as_ref();
        match std::fs::metadata(path) {
            Ok(m) if !m.is_file() && !m.is_dir() => {
                // A device, FIFO or socket: written in place.
                let file = OpenOptions::new().write(true).open(path)?;
                return Ok(AtomicFile {
                    file: Some(file),
                    temp: None,
                    dest: path.to_path_buf(),
                    durable: true,
                });
            }
            _ => {}
        }
        // Through symbolic links to the file they name, so that the link is kept.
        let dest = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let old_permissions = std::fs::metadata(&dest).ok().map(|m| m.permissions());
        let dir = match dest.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = dest
            .file_name()
            .ok_or_else(|| {
                io::Error::new(io::ErrorKind::InvalidInput, "the output path names no file")
            })?
            .to_string_lossy()
            .into_owned();
        // What a killed writer of this same file left: removed once it is known dead.
        super::folder::remove_stale_partials_of(&dir, Some(&name));
        let (file, temp) = loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let temp = dir.join(partial_name(&name, std::process::id(), n));
            match OpenOptions::new().write(true).create_new(true).open(&temp) {
                Ok(f) => break (f, temp),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        };
        let out = AtomicFile {
            file: Some(file),
            temp: Some(temp),
            dest,
            durable: true,
        };
        if let (Some(p), Some(f)) = (old_permissions, &out.file) {
            f.set_permissions(p)?;
        }
        Ok(out)
    }

    /// Whether [`AtomicFile::commit`] syncs the data to the disk before the rename (on by
    /// default). Off, a kill still never leaves a partial file under the final name, but a
    /// power loss right after the commit may leave an empty one on file systems that
    /// delay allocation.
    pub fn durable(mut self, durable: bool) -> Self {
        self.durable = durable;
        self
    }

    /// The final name (after links were followed).
    pub fn path(&self) -> &Path {
        &self.dest
    }

    /// Flushes and syncs the data and renames the temporary file over the final name.
    pub fn commit(mut self) -> io::Result<()> {
        let Some(mut file) = self.file.take() else {
            return Ok(());
        };
        file.flush()?;
        let Some(temp) = self.temp.as_ref() else {
            return Ok(());
        };
        if self.durable {
            file.sync_all()?;
        } else {
            // ext4 (`auto_da_alloc`) writes the data of a file renamed over another at the
            // rename, synchronously for this thread; renamed onto a free name, it is written
            // back later as any new file. A kill between the two steps leaves no file.
            match std::fs::remove_file(&self.dest) {
                Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(e),
                _ => {}
            }
        }
        drop(file);
        std::fs::rename(temp, &self.dest)?;
        self.temp = None;
        if self.durable {
            // The rename itself reaches the disk with its folder; not every file system
            // syncs folders, so this is best effort.
            if let Some(dir) = self.dest.parent().filter(|d| !d.as_os_str().is_empty()) {
                let _ = File::open(dir).and_then(|d| d.sync_all());
            }
        }
        Ok(())
    }

    fn file(&mut self) -> io::Result<&mut File> {
        self.file
            .as_mut()
            .ok_or_else(|| io::Error::other("output file already committed"))
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file()?.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.file()?.write_all(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file()?.flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        self.file = None;
        if let Some(temp) = self.temp.take() {
            let _ = std::fs::remove_file(temp);
        }
    }
}

/// Writes `bytes` to `path` atomically (the [`std::fs::write`] of this module).
pub fn write(path: impl AsRef<Path>, bytes: impl AsRef<[u8]>) -> io::Result<()> {
    let mut f = AtomicFile::create(path)?;
    f.write_all(bytes.as_ref())?;
    f.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("driftless-atomic-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn the_final_name_appears_only_on_commit() {
        let d = scratch("commit");
        let p = d.join("out.txt");
        std::fs::write(&p, "old").unwrap();
        let mut f = AtomicFile::create(&p).unwrap();
        f.write_all(b"new data").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        assert_eq!(entries(&d).len(), 2);
        f.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new data");
        assert_eq!(entries(&d), ["out.txt"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_dropped_file_leaves_the_old_one_and_no_temporary() {
        let d = scratch("drop");
        let p = d.join("out.txt");
        std::fs::write(&p, "old").unwrap();
        {
            let mut f = std::io::BufWriter::new(AtomicFile::create(&p).unwrap());
            f.write_all(b"half").unwrap();
        }
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        assert_eq!(entries(&d), ["out.txt"]);
        // No old file: none afterwards either.
        let q = d.join("new.txt");
        drop(AtomicFile::create(&q).unwrap());
        assert_eq!(entries(&d), ["out.txt"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn links_are_followed_and_permissions_kept() {
        use std::os::unix::fs::PermissionsExt;
        let d = scratch("link");
        let target = d.join("target.txt");
        std::fs::write(&target, "old").unwrap();
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        let link = d.join("link.txt");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        write(&link, "new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        let mode = std::fs::metadata(&target).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn devices_are_written_in_place() {
        write("/dev/null", "discarded").unwrap();
        let e = write("/dev/full", "no room").unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::StorageFull);
    }

    #[test]
    fn temporary_names_carry_their_writer() {
        let d = scratch("names");
        let f = AtomicFile::create(d.join("imu.partial-3.csv")).unwrap();
        let names = entries(&d);
        assert_eq!(names.len(), 1);
        assert_eq!(partial_owner(&names[0]), Some(std::process::id()));
        drop(f);
        assert_eq!(partial_owner(".imu.csv.partial-123-4"), Some(123));
        assert_eq!(partial_owner(".a.partial-1-2.partial-77-0"), Some(77));
        for other in [
            "imu.csv.partial-123-4",
            "..partial-123-4",
            ".imu.csv.partial-123",
            ".imu.csv.partial-123-",
            ".imu.csv.partial--4",
            ".imu.csv.partial-12a-4",
            ".imu.csv.partial-99999999999-4",
            ".imu.csv",
        ] {
            assert_eq!(partial_owner(other), None, "{other}");
        }
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_missing_folder_fails_at_creation() {
        let d = scratch("missing");
        let e = AtomicFile::create(d.join("no/such/out.txt")).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::NotFound);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
