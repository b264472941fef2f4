//! The one path the commands print their results through ([`outln!`], [`out!`]): a failed
//! write to stdout (`>/dev/full`, a closed descriptor) becomes an error, so exit 1 with a
//! message, where std's `println!` panics (exit 101). A closed pipe still ends the process by
//! SIGPIPE, as it ends `cat` (see `quiet_on_closed_pipe` in main.rs).

use std::fmt;
use std::io::{self, Write};

/// A write to stdout that failed.
#[derive(Debug, thiserror::Error)]
#[error("writing to stdout: {0}")]
pub(crate) struct StdoutError(#[source] io::Error);

/// Writes `args` to stdout, then a newline when `newline`.
pub(crate) fn write(args: fmt::Arguments<'_>, newline: bool) -> Result<(), StdoutError> {
    let mut out = io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| if newline { out.write_all(b"\n") } else { Ok(()) })
        .map_err(StdoutError)
}

/// Flushes what [`write`] left buffered (text without a final newline), as the last step of a
/// successful run: std's own flush at exit ignores its error.
pub(crate) fn flush() -> Result<(), StdoutError> {
    io::stdout().lock().flush().map_err(StdoutError)
}
