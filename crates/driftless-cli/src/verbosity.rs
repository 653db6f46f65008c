//! How much a run says on standard error: the global `--quiet` / `--verbose` flags.
//!
//! Standard output carries only the result (tables or JSON). Standard error carries
//! errors, warnings, notes and progress bars:
//!
//! * errors and warnings that the result depends on are always printed;
//! * notes ([`note!`]) and progress bars are silenced by `--quiet`;
//! * `--verbose` adds detail where a command has it (every rejected GNSS fix, every IMU
//!   finding).
//!
//! The level is set once by `main` from the parsed flags, before any command runs.

use std::sync::OnceLock;

/// How much to say on standard error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verbosity {
    /// Errors and warnings only (`--quiet`).
    Quiet,
    /// Errors, warnings, notes and progress bars.
    Normal,
    /// Also the detail a command has (`--verbose`).
    Verbose,
}

static LEVEL: OnceLock<Verbosity> = OnceLock::new();

/// Sets the level for the run; a second call keeps the first level.
pub fn set(level: Verbosity) {
    let _ = LEVEL.set(level);
}

fn level() -> Verbosity {
    LEVEL.get().copied().unwrap_or(Verbosity::Normal)
}

/// `--quiet` given: no notes, no progress bars.
pub fn quiet() -> bool {
    level() == Verbosity::Quiet
}

/// `--verbose` given: every detail a command has.
pub fn verbose() -> bool {
    level() == Verbosity::Verbose
}

/// `eprintln!` of a note: silenced by `--quiet` (module docs).
macro_rules! note {
    ($($arg:tt)*) => {
        if !$crate::verbosity::quiet() {
            eprintln!($($arg)*);
        }
    };
}
