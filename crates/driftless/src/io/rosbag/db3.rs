//! ROS 2 sqlite3 storage (`.db3`, rosbag2's `sqlite3` plugin): table `topics(id, name, type,
//! serialization_format, offered_qos_profiles, …)` gives the connections, table
//! `messages(id, topic_id, timestamp, data)` the messages, read in rowid order (the order
//! rosbag2 inserted them, as a ROS 1 bag or MCAP file is read in file order). Columns are
//! found by name in the tables' `CREATE TABLE` statements, so the schema versions that add
//! columns (`type_description_hash`) read alike.
//!
//! A bag whose recording did not finish cleanly is refused: a non-empty `-wal` file beside
//! it holds committed rows not yet in the database, a `-journal` file an interrupted
//! transaction; both need SQLite itself to resolve.

use std::path::Path;

use super::Item;
use super::sqlite::{Db, Table, Value, column_names};
use crate::io::error::{Location, LogError};

const FORMAT: &str = "ROS 2 sqlite3 bag";

/// Errors for the files SQLite leaves beside a database that was not closed.
fn check_unfinished(name: &str) -> Result<(), LogError> {
    for (suffix, what) in [
        (
            "-wal",
            "holds committed messages not yet in the database (write-ahead log)",
        ),
        (
            "-journal",
            "holds an interrupted transaction (rollback journal)",
        ),
    ] {
        let side = format!("{name}{suffix}");
        if std::fs::metadata(Path::new(&side)).is_ok_and(|m| m.len() > 0) {
            return Err(LogError::InvalidOptions {
                at: Location::input(name),
                message: format!(
                    "{side} {what}: the recording did not close the bag. Let SQLite finish it \
                     first (`sqlite3 {name} 'PRAGMA wal_checkpoint(TRUNCATE);'` opens and \
                     closes it, which applies or rolls back that file), then read it again"
                ),
            });
        }
    }
    Ok(())
}

/// The table `name` and the positions of `columns` in it.
fn table<'t, const N: usize>(
    tables: &'t [Table],
    name: &str,
    columns: [&str; N],
    file: &str,
) -> Result<(&'t Table, [usize; N]), LogError> {
    let bad = |message: String| LogError::Malformed {
        at: Location::input(file),
        format: FORMAT,
        message,
    };
    let t = tables.iter().find(|t| t.name == name).ok_or_else(|| {
        bad(format!(
            "no table {name}: not a rosbag2 sqlite3 bag (tables: {})",
            tables
                .iter()
                .map(|t| t.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })?;
    let have = column_names(&t.sql);
    let mut at = [0; N];
    for (slot, want) in at.iter_mut().zip(columns) {
        *slot = have.iter().position(|c| c == want).ok_or_else(|| {
            bad(format!(
                "table {name} has no column {want} (columns: {})",
                have.join(", ")
            ))
        })?;
    }
    Ok((t, at))
}

/// A text value as UTF-8.
fn text<'a>(v: Option<&Value<'a>>) -> Option<&'a str> {
    match v {
        Some(Value::Text(s)) => std::str::from_utf8(s).ok(),
        _ => None,
    }
}

/// Reads the bag front to back: every topic as a connection (id = the topic's id), then
/// every message in rowid order.
pub(crate) fn scan(
    file: &mut std::fs::File,
    name: &str,
    size: u64,
    visit: &mut dyn FnMut(Item<'_>) -> Result<(), LogError>,
) -> Result<(), LogError> {
    check_unfinished(name)?;
    let mut db = Db::open(file, name, size)?;
    let tables = db.tables()?;
    let (topics, [id_c, name_c, type_c, ser_c]) = table(
        &tables,
        "topics",
        ["id", "name", "type", "serialization_format"],
        name,
    )?;
    let (messages, [topic_c, data_c]) = table(&tables, "messages", ["topic_id", "data"], name)?;
    db.scan(topics.root, &mut |db, rowid, at, payload| {
        let err = |m: String| LogError::AtByte {
            path: db.name.to_owned(),
            byte_offset: at,
            format: FORMAT,
            message: format!("topics row {rowid}: {m}"),
        };
        let v = super::sqlite::record(payload).map_err(err)?;
        // `id INTEGER PRIMARY KEY` is the rowid, stored as NULL in the record.
        let id = match v.get(id_c) {
            Some(Value::Int(i)) => *i,
            _ => rowid,
        };
        let id = u32::try_from(id).map_err(|_| err(format!("topic id {id} out of range")))?;
        let (Some(topic), Some(ty), Some(ser)) =
            (text(v.get(name_c)), text(v.get(type_c)), text(v.get(ser_c)))
        else {
            return Err(err(
                "name, type or serialization_format is not UTF-8 text".into()
            ));
        };
        // Only CDR is decoded: another serialization makes the type one that is not read.
        let msg_type = if ser == "cdr" {
            ty.to_owned()
        } else {
            format!("{ty} in {ser} serialization")
        };
        visit(Item::Connection {
            id,
            topic,
            msg_type: &msg_type,
        })
    })?;
    db.scan(messages.root, &mut |db, rowid, at, payload| {
        let err = |m: String| LogError::AtByte {
            path: db.name.to_owned(),
            byte_offset: at,
            format: FORMAT,
            message: format!("messages row {rowid}: {m}"),
        };
        let v = super::sqlite::record(payload).map_err(err)?;
        let conn = match v.get(topic_c) {
            Some(&Value::Int(t)) => u32::try_from(t).ok(),
            _ => None,
        };
        // A topic id that no topic has is no topic read here: skipped, as ROS tools do.
        let Some(conn) = conn else { return Ok(()) };
        let data = match v.get(data_c) {
            Some(Value::Blob(b) | Value::Text(b)) => *b,
            Some(Value::Null) | None => &[][..],
            Some(_) => return Err(err("data is a number, not a blob".into())),
        };
        visit(Item::Message {
            conn,
            byte_offset: at,
            data,
        })
    })
}
