//! Output files: every file driftless writes goes through this module, so that a run that
//! fails or is interrupted leaves every earlier file intact and no complete-looking new one.
//!
//! * [`file`](mod@file): [`AtomicFile`] — written to a temporary file beside the destination, flushed,
//!   synced and renamed over the final name on [`AtomicFile::commit`]; dropped without a
//!   commit (an error, a panic), the temporary file is removed. [`write()`] for whole
//!   buffers.
//! * [`guard`]: refusals before any work — an output that is one of the inputs (same device
//!   and inode, through links and `./`), an output folder that already holds files.
//! * [`folder`]: [`lock_folder`] — one run at a time per output folder, held until every
//!   file is committed ([`claim_folder`]: the lock, then the refusal of a folder in use).
//!
//! A destination that exists and is not a regular file (`/dev/null`, `/dev/stdout`, a FIFO)
//! is written in place: there is nothing to keep and nothing to rename over. A symbolic link
//! to a regular file is followed: the file it points to is replaced, the link kept.
//!
//! A process killed outright (`kill -9`, power loss before the rename) can leave its
//! temporary file, named `.NAME.partial-PID-N` beside the destination: hidden, and never
//! under the final name. The next run that locks the folder removes such files once their
//! process has ended (known on Linux; elsewhere they stay), and they never count as
//! another run's files.

pub mod file;
pub mod folder;
pub mod guard;

pub use file::{AtomicFile, partial_owner, write};
pub use folder::{FolderLock, claim_folder, is_stale_partial, lock_folder, remove_stale_partials};
pub use guard::{OutputError, refuse_folder_in_use, refuse_same_file};
