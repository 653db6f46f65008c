//! Checks made before a run produces anything: an output must not be one of the inputs,
//! and an output folder must not hold another run's files unless the user said so.

use std::path::Path;

/// Why an output path is refused.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The output is an input (same device and inode).
    #[error(
        "output {output} is the input {input} itself: writing it would replace the data being \
         read; choose another output path"
    )]
    SameAsInput { output: String, input: String },
    /// The output folder holds files already.
    #[error(
        "output folder {path} already holds files ({example}{more}); choose an empty or new \
         folder, or pass --force to replace its files"
    )]
    FolderInUse {
        path: String,
        example: String,
        more: String,
    },
    /// Another run holds the output folder's lock ([`super::lock_folder`]).
    #[error(
        "output folder {path}: another driftless run is writing it (it holds the folder's \
         lock); wait for that run to end, or choose another folder"
    )]
    Locked { path: String },
    /// The output folder could not be created.
    #[error("creating output folder {path}: {error}")]
    CreateFolder {
        path: String,
        #[source]
        error: std::io::Error,
    },
    /// The output folder could not be inspected.
    #[error("{path}: {error}")]
    Io {
        path: String,
        #[source]
        error: std::io::Error,
    },
}

/// A file's identity: device and inode where the platform has them, else its canonical path.
#[derive(PartialEq, Eq)]
enum Identity {
    #[cfg(unix)]
    Inode(u64, u64),
    #[cfg(not(unix))]
    Path(std::path::PathBuf),
}

/// The identity of the regular file at `p` (links followed); `None` when `p` does not exist
/// or is not a regular file (devices such as `/dev/stdout` are never "the same data").
fn identity(p: &Path) -> Option<Identity> {
    let m = std::fs::metadata(p).ok()?;
    if !m.is_file() {
        return None;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Some(Identity::Inode(m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        std::fs::canonicalize(p).ok().map(Identity::Path)
    }
}

/// Refuses `output` when it is the same file as one of `inputs` (hard and symbolic links,
/// `./` and `..` included). A missing output or input is no conflict.
pub fn refuse_same_file<P: AsRef<Path>>(
    output: impl AsRef<Path>,
    inputs: impl IntoIterator<Item = P>,
) -> Result<(), OutputError> {
    let output = output.as_ref();
    let Some(out_id) = identity(output) else {
        return Ok(());
    };
    for input in inputs {
        let input = input.as_ref();
        if identity(input).as_ref() == Some(&out_id) {
            return Err(OutputError::SameAsInput {
                output: output.display().to_string(),
                input: input.display().to_string(),
            });
        }
    }
    Ok(())
}

/// Refuses an output folder that exists and holds anything, unless `force`: its files would
/// mix with this run's. A missing or empty folder is fine; so is one that holds only
/// temporary files of ended runs ([`super::is_stale_partial`]) and the
/// `LOCK_FILE`.
pub fn refuse_folder_in_use(dir: impl AsRef<Path>, force: bool) -> Result<(), OutputError> {
    let dir = dir.as_ref();
    if force {
        return Ok(());
    }
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(error) => {
            return Err(OutputError::Io {
                path: dir.display().to_string(),
                error,
            });
        }
    };
    let mut names: Vec<String> = Vec::new();
    for e in entries {
        let e = e.map_err(|error| OutputError::Io {
            path: dir.display().to_string(),
            error,
        })?;
        let name = e.file_name().to_string_lossy().into_owned();
        let is_file = e.file_type().is_ok_and(|t| t.is_file());
        if is_file && (name == super::folder::LOCK_FILE || super::is_stale_partial(&name)) {
            continue;
        }
        names.push(name);
    }
    names.sort();
    match names.split_first() {
        None => Ok(()),
        Some((first, rest)) => Err(OutputError::FolderInUse {
            path: dir.display().to_string(),
            example: first.clone(),
            more: if rest.is_empty() {
                String::new()
            } else {
                format!(" and {} more", rest.len())
            },
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_file_is_found_through_links_and_dots() {
        let d = std::env::temp_dir().join(format!("driftless-guard-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("sub")).unwrap();
        let log = d.join("log.csv");
        std::fs::write(&log, "1\n").unwrap();
        let other = d.join("other.csv");
        std::fs::write(&other, "1\n").unwrap();
        let dotted = d.join("sub/../././log.csv");
        assert!(refuse_same_file(&dotted, [&other, &log]).is_err());
        #[cfg(unix)]
        {
            let link = d.join("link.csv");
            std::os::unix::fs::symlink(&log, &link).unwrap();
            let hard = d.join("hard.csv");
            std::fs::hard_link(&log, &hard).unwrap();
            let msg = refuse_same_file(&link, [&log]).unwrap_err().to_string();
            assert!(
                msg.contains("link.csv") && msg.contains("is the input"),
                "{msg}"
            );
            assert!(refuse_same_file(&hard, [&log]).is_err());
            assert!(refuse_same_file("/dev/null", ["/dev/null"]).is_ok());
        }
        assert!(refuse_same_file(&other, [&log]).is_ok());
        assert!(refuse_same_file(d.join("new.csv"), [&log]).is_ok());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_folder_with_files_needs_force() {
        let d = std::env::temp_dir().join(format!("driftless-folder-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        assert!(refuse_folder_in_use(&d, false).is_ok());
        std::fs::create_dir_all(&d).unwrap();
        assert!(refuse_folder_in_use(&d, false).is_ok());
        std::fs::write(d.join("imu.csv"), "x").unwrap();
        std::fs::write(d.join("gnss.txt"), "x").unwrap();
        let msg = refuse_folder_in_use(&d, false).unwrap_err().to_string();
        assert!(
            msg.contains("gnss.txt and 1 more") && msg.contains("--force"),
            "{msg}"
        );
        assert!(refuse_folder_in_use(&d, true).is_ok());
        std::fs::remove_dir_all(&d).unwrap();
    }
}
