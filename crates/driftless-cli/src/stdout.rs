//! Standard output that never panics. `println!` panics when stdout is a closed pipe
//! (`driftless … | head`) or a full device; [`outln!`] and [`out!`] instead unwind with a
//! [`StdoutFailed`] payload — without the panic message, running destructors (so output
//! files in progress are removed) — which `main` turns into a quiet exit for a closed
//! pipe and an error with exit status 1 otherwise.

use std::io::Write;

/// The payload of an unwind started by a failed write to standard output.
#[derive(Debug)]
pub struct StdoutFailed(pub std::io::Error);

impl std::fmt::Display for StdoutFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "writing to standard output: {}", self.0)
    }
}

impl std::error::Error for StdoutFailed {}

/// Writes to standard output; on an error unwinds with [`StdoutFailed`].
pub fn write_fmt(args: std::fmt::Arguments<'_>) {
    if let Err(e) = std::io::stdout().lock().write_fmt(args) {
        std::panic::resume_unwind(Box::new(StdoutFailed(e)));
    }
}

/// Flushes standard output at the end of a run.
pub fn flush() -> std::io::Result<()> {
    std::io::stdout().lock().flush()
}

/// `println!` that does not panic (module docs).
macro_rules! outln {
    () => {
        $crate::stdout::write_fmt(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::stdout::write_fmt(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` that does not panic (module docs).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::stdout::write_fmt(format_args!($($arg)*))
    };
}
