//! The one path the commands write notes, warnings, progress and errors to stderr through
//! ([`errln!`]): a refused write (`2>/dev/full`, a closed descriptor) is remembered and the run
//! ends with exit 1 once it has finished, where std's `eprintln!` panics (exit 101) at the first
//! note. A closed pipe still ends the process by SIGPIPE, as it ends `cat` (see
//! `quiet_on_closed_pipe` in main.rs).

use std::fmt;
use std::io::{self, Write};
use std::sync::OnceLock;

/// A write to stderr that failed (the first one).
#[derive(Debug, thiserror::Error)]
#[error("writing to stderr: {0}")]
pub(crate) struct StderrError(String);

/// The first refused write, from any thread (progress lines come from a ticker thread).
static FAILED: OnceLock<String> = OnceLock::new();

/// Writes `args` and a newline to stderr; a failure is kept for [`failure`].
pub(crate) fn write(args: fmt::Arguments<'_>) {
    let mut err = io::stderr().lock();
    if let Err(e) = err.write_fmt(args).and_then(|()| err.write_all(b"\n")) {
        FAILED.get_or_init(|| e.to_string());
    }
}

/// The first write to stderr that failed, if any.
pub(crate) fn failure() -> Option<StderrError> {
    FAILED.get().map(|e| StderrError(e.clone()))
}
