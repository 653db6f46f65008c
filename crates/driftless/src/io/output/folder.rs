//! Output folders: one driftless run at a time per folder, and the temporary files of a
//! killed run cleared away.
//!
//! [`lock_folder`] takes an exclusive advisory lock ([`File::try_lock`], `flock` on unix)
//! on the folder itself, opened read-only, so no lock file is left behind; elsewhere the
//! lock is taken on a `LOCK_FILE` inside the folder, which stays. The lock is released
//! when the [`FolderLock`] is dropped or the process ends in any way, `kill -9` included.
//! A second run into a locked folder fails at once instead of mixing its files with the
//! first one's.

use super::file::{parse_partial, partial_owner};
use super::guard::{OutputError, refuse_folder_in_use};
use std::fs::File;
use std::path::{Path, PathBuf};

/// The lock file inside an output folder where a folder itself cannot be locked
/// (non-unix platforms). Never counted as another run's file.
pub(crate) const LOCK_FILE: &str = ".driftless.lock";

/// An output folder held by this run: while it lives, every other driftless run that
/// tries to write the folder is refused. Keep it until every file is committed.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
    /// The locked handle; `None` on a file system that has no locks.
    file: Option<File>,
    /// Whether [`lock_folder`] created the folder: then it is removed again when left
    /// empty (a run that failed before writing anything).
    created: bool,
}

impl FolderLock {
    /// The folder.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        if self.created {
            // Only an empty folder is removed, and while still locked, so that no run
            // that locks it next finds it gone.
            let _ = std::fs::remove_dir(&self.path);
        }
        self.file = None;
    }
}

fn io_error(dir: &Path) -> impl Fn(std::io::Error) -> OutputError + '_ {
    move |error| OutputError::Io {
        path: dir.display().to_string(),
        error,
    }
}

/// Creates `dir` when missing and locks it against other driftless runs until the
/// returned [`FolderLock`] is dropped; then removes the temporary files that killed runs
/// left in it ([`remove_stale_partials`]).
///
/// Errors: [`OutputError::Locked`] when another run holds the folder,
/// [`OutputError::Io`] when it cannot be created or opened. A file system without locks
/// is written unlocked.
pub fn lock_folder(dir: impl AsRef<Path>) -> Result<FolderLock, OutputError> {
    let dir = dir.as_ref();
    let created = !dir.exists();
    std::fs::create_dir_all(dir).map_err(|error| OutputError::CreateFolder {
        path: dir.display().to_string(),
        error,
    })?;
    let mut lock = FolderLock {
        path: dir.to_path_buf(),
        file: None,
        created,
    };
    #[cfg(unix)]
    let file = File::open(dir).map_err(io_error(dir))?;
    #[cfg(not(unix))]
    let file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(dir.join(LOCK_FILE))
        .map_err(io_error(dir))?;
    match file.try_lock() {
        Ok(()) => lock.file = Some(file),
        Err(std::fs::TryLockError::WouldBlock) => {
            // Not ours to remove: the other run is writing into it.
            lock.created = false;
            return Err(OutputError::Locked {
                path: dir.display().to_string(),
            });
        }
        Err(std::fs::TryLockError::Error(e)) if e.kind() == std::io::ErrorKind::Unsupported => {}
        Err(std::fs::TryLockError::Error(e)) => return Err(io_error(dir)(e)),
    }
    remove_stale_partials(dir);
    Ok(lock)
}

/// [`lock_folder`], then [`refuse_folder_in_use`]: the folder of a run that writes a
/// whole set of files (`simulate --out`, `experiment --out`). Locking first makes a
/// second concurrent run fail on the lock, not on the first run's files.
pub fn claim_folder(dir: impl AsRef<Path>, force: bool) -> Result<FolderLock, OutputError> {
    let lock = lock_folder(&dir)?;
    refuse_folder_in_use(&dir, force)?;
    Ok(lock)
}

/// Whether process `pid` is running: known on Linux (from `/proc`), `None` elsewhere.
fn process_alive(pid: u32) -> Option<bool> {
    if pid == std::process::id() {
        return Some(true);
    }
    #[cfg(target_os = "linux")]
    if Path::new("/proc/self").exists() {
        return Some(Path::new(&format!("/proc/{pid}")).exists());
    }
    None
}

/// Whether `name` is a temporary file of [`super::AtomicFile`] whose writer is known to
/// have ended without committing or removing it (killed, or the machine stopped). A
/// process id reused since then keeps the file: it is left, never wrongly removed.
pub fn is_stale_partial(name: &str) -> bool {
    partial_owner(name).is_some_and(|pid| process_alive(pid) == Some(false))
}

/// Removes the stale temporary files ([`is_stale_partial`]) directly in `dir`; returns how
/// many. Best effort: a file that cannot be removed stays (and is still never counted as
/// another run's file by [`refuse_folder_in_use`]). Where process ids cannot be checked
/// (non-Linux), nothing is removed.
pub fn remove_stale_partials(dir: impl AsRef<Path>) -> usize {
    remove_stale_partials_of(dir.as_ref(), None)
}

/// [`remove_stale_partials`], of destination `only` when given (what
/// [`super::AtomicFile::create`] clears before writing it).
pub(super) fn remove_stale_partials_of(dir: &Path, only: Option<&str>) -> usize {
    if !cfg!(target_os = "linux") {
        return 0;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .filter_map(Result::ok)
        .filter(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            parse_partial(&name).is_some_and(|(stem, _)| only.is_none_or(|o| o == stem))
                && is_stale_partial(&name)
        })
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter(|e| std::fs::remove_file(e.path()).is_ok())
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("driftless-lock-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn a_locked_folder_is_refused_until_released() {
        let d = scratch("twice");
        let first = lock_folder(&d).unwrap();
        assert!(d.is_dir());
        // A second lock on the folder, even from this process, is refused at once.
        let e = lock_folder(&d).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, OutputError::Locked { .. }), "{e:?}");
        assert!(
            msg.contains(&d.display().to_string())
                && msg.contains("another driftless run is writing it"),
            "{msg}"
        );
        assert!(claim_folder(&d, true).is_err());
        std::fs::write(d.join("imu.csv"), "x").unwrap();
        drop(first);
        // Released; the folder holds a file now, so it is kept.
        assert!(d.is_dir());
        let again = claim_folder(&d, true).unwrap();
        assert_eq!(again.path(), d.as_path());
        drop(again);
        assert!(claim_folder(&d, false).is_err());
        #[cfg(unix)]
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            1,
            "no lock file left"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_folder_created_for_a_run_that_wrote_nothing_is_removed() {
        let d = scratch("created");
        drop(lock_folder(&d).unwrap());
        assert!(!d.exists());
        // An existing empty folder is the user's: kept.
        std::fs::create_dir_all(&d).unwrap();
        drop(lock_folder(&d).unwrap());
        assert!(d.is_dir());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_folder_path_that_is_a_file_is_an_error() {
        let d = scratch("file");
        std::fs::create_dir_all(&d).unwrap();
        let f = d.join("plain");
        std::fs::write(&f, "x").unwrap();
        let msg = lock_folder(&f).unwrap_err().to_string();
        assert!(msg.contains("plain"), "{msg}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// The names in `d`, sorted.
    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// The id of a process that has ended (and been reaped).
    #[cfg(target_os = "linux")]
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        pid
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn partial_files_of_ended_runs_are_removed_and_not_counted() {
        let d = scratch("stale");
        std::fs::create_dir_all(&d).unwrap();
        let dead = dead_pid();
        let me = std::process::id();
        let stale = format!(".imu.csv.partial-{dead}-0");
        let live = format!(".imu.csv.partial-{me}-99");
        std::fs::write(d.join(&stale), "half").unwrap();
        assert!(is_stale_partial(&stale) && !is_stale_partial(&live));
        assert!(!is_stale_partial("imu.csv"));
        // Not another run's files: the folder counts as empty.
        refuse_folder_in_use(&d, false).unwrap();
        std::fs::write(d.join(&live), "being written").unwrap();
        let msg = refuse_folder_in_use(&d, false).unwrap_err().to_string();
        assert!(msg.contains(&live) && !msg.contains("more"), "{msg}");
        // Locking the folder clears the stale one only.
        let lock = lock_folder(&d).unwrap();
        assert_eq!(names(&d), std::slice::from_ref(&live));
        // A folder of the same name is not a temporary file.
        std::fs::remove_file(d.join(&live)).unwrap();
        std::fs::create_dir(d.join(&stale)).unwrap();
        assert_eq!(remove_stale_partials(&d), 0);
        assert!(d.join(&stale).is_dir());
        drop(lock);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn writing_a_file_clears_what_a_killed_writer_of_it_left() {
        let d = scratch("same-name");
        std::fs::create_dir_all(&d).unwrap();
        let dead = dead_pid();
        let mine = format!(".out.csv.partial-{dead}-3");
        let other = format!(".gnss.txt.partial-{dead}-4");
        std::fs::write(d.join(&mine), "half").unwrap();
        std::fs::write(d.join(&other), "half").unwrap();
        super::super::write(d.join("out.csv"), "whole").unwrap();
        assert_eq!(names(&d), [other, "out.csv".to_string()]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
