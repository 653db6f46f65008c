//! Output files: every file driftless writes goes through this module, so that a run that
//! fails or is interrupted leaves every earlier file intact and no complete-looking new one.
//!
//! * [`file`]: [`AtomicFile`] — written to a temporary file beside the destination, flushed,
//!   synced and renamed over the final name on [`AtomicFile::commit`]; dropped without a
//!   commit (an error, a panic), the temporary file is removed. [`write`] for whole
//!   buffers.
//! * [`guard`]: refusals before any work — an output that is one of the inputs (same device
//!   and inode, through links and `./`), an output folder that already holds files.
//!
//! A destination that exists and is not a regular file (`/dev/null`, `/dev/stdout`, a FIFO)
//! is written in place: there is nothing to keep and nothing to rename over. A symbolic link
//! to a regular file is followed: the file it points to is replaced, the link kept.
//!
//! A process killed outright (`kill -9`, power loss before the rename) can leave its
//! temporary file, named `.NAME.partial-PID-N` beside the destination: hidden, and never
//! under the final name.

pub mod file;
pub mod guard;

pub use file::{AtomicFile, write};
pub use guard::{OutputError, refuse_folder_in_use, refuse_same_file};
