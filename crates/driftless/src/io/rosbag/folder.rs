//! ROS 2 bag folders: `metadata.yaml` (rosbag2's `rosbag2_bagfile_information`) names the
//! storage files in recording order (`relative_file_paths`) and the compression
//! (`compression_mode`: none, `message` or `file`; `compression_format`: `zstd`).

use std::path::{Path, PathBuf};

use crate::io::error::{Location, LogError};

/// A ROS 2 bag folder (one holding `metadata.yaml`): its storage files in recording order
/// and the compression its metadata declares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Ros2BagFolder {
    /// The storage files (`.mcap`, `.db3`), in the order `relative_file_paths` lists them.
    pub storage: Vec<PathBuf>,
    /// Whether each message is Zstandard-compressed (`compression_mode: message`).
    pub message_zstd: bool,
}

/// The ROS 2 bag folder at `dir`: `None` when `dir` holds no `metadata.yaml`; an error when
/// the metadata cannot be read, names a missing file, declares whole-file compression, or
/// (without `relative_file_paths`) the folder holds no `.mcap` / `.db3` file.
pub(crate) fn ros2_bag_folder(dir: &Path) -> Result<Option<Ros2BagFolder>, LogError> {
    use saphyr::{Scalar, YamlData};
    let meta = dir.join("metadata.yaml");
    if !meta.is_file() {
        return Ok(None);
    }
    let (meta_name, text) = crate::io::yaml::read_named(&meta)?;
    let root = crate::io::yaml::load_root(&text, &meta_name, "rosbag2 metadata")?;
    let bad = |message: String| LogError::InvalidOptions {
        at: Location::input(&meta_name),
        message,
    };
    let info = match &root.data {
        YamlData::Mapping(m) => crate::io::yaml::mapping_get(m, "rosbag2_bagfile_information"),
        _ => None,
    };
    let info = match info.map(|(_, v)| &v.data) {
        Some(YamlData::Mapping(m)) => m,
        _ => return Err(bad("no rosbag2_bagfile_information mapping".into())),
    };
    let string = |key: &str| match crate::io::yaml::mapping_get(info, key).map(|(_, v)| &v.data) {
        Some(YamlData::Value(Scalar::String(s))) => s.to_string(),
        _ => String::new(),
    };
    let mode = string("compression_mode").to_ascii_lowercase();
    let format = string("compression_format");
    let mut storage: Vec<PathBuf> = Vec::new();
    if let Some((_, v)) = crate::io::yaml::mapping_get(info, "relative_file_paths") {
        let YamlData::Sequence(list) = &v.data else {
            return Err(bad("relative_file_paths is not a list".into()));
        };
        for item in list {
            let YamlData::Value(Scalar::String(f)) = &item.data else {
                return Err(bad("relative_file_paths holds a non-string entry".into()));
            };
            storage.push(dir.join(f.as_ref()));
        }
    }
    match (mode.as_str(), format.as_str()) {
        ("" | "none", _) | ("message", "zstd") => {}
        ("file", f) => {
            return Err(bad(format!(
                "a file-compressed bag ({f}): decompress its storage files first (`{f} -d {}`), \
                 then give the decompressed .db3 / .mcap file",
                storage
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            )));
        }
        (m, f) => {
            return Err(bad(format!(
                "compression_mode {m:?} with compression_format {f:?}: only per-message zstd \
                 compression is read"
            )));
        }
    }
    if storage.is_empty() {
        let name = dir.display().to_string();
        let entries = std::fs::read_dir(dir).map_err(|error| LogError::Io {
            path: name.clone(),
            error,
        })?;
        storage = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_file() && p.extension().is_some_and(|x| x == "mcap" || x == "db3"))
            .collect();
        storage.sort();
        if storage.is_empty() {
            return Err(LogError::InvalidOptions {
                at: Location::input(&name),
                message: "a ROS 2 bag folder (metadata.yaml) without a .mcap or .db3 file".into(),
            });
        }
    }
    if let Some(missing) = storage.iter().find(|p| !p.is_file()) {
        return Err(bad(format!(
            "relative_file_paths names {}, which is not a file",
            missing.display()
        )));
    }
    Ok(Some(Ros2BagFolder {
        storage,
        message_zstd: mode == "message",
    }))
}
