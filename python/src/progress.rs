//! `refocus_batch(progress=...)`: a callable `f(done, total)`, or True for stderr as the CLI
//! writes it: a bar with rate and ETA on a terminal (indicatif), otherwise the library's log
//! lines (`viewsynth::progress::CountLog`: newline-terminated, count, rate and ETA, the first
//! frame, every 10 s and the last), which a log file or a notebook's captured stderr keeps
//! readable.

use crate::errors;
use pyo3::prelude::*;
use pyo3::types::PyBool;
use std::cell::{Cell, RefCell};
use std::io::IsTerminal;
use viewsynth::progress::CountLog;

/// What the frames of a batch are called in the bar and the log lines.
const WHAT: &str = "refocus_batch frames";

enum Report {
    None,
    Bar(indicatif::ProgressBar),
    Log(RefCell<CountLog>),
    Call(Py<PyAny>),
}

/// Progress of a batch: called once per frame on the thread that runs it (with the GIL
/// released, so a callable call takes it back for the call). The first exception a callable
/// raises is kept, later calls are skipped, and `finish` raises it once the batch is over (the
/// frames already written stay).
pub struct Progress {
    report: Report,
    total: usize,
    done: Cell<usize>,
    error: RefCell<Option<PyErr>>,
}

impl Progress {
    /// `progress=`: None or False (silent), True (stderr), or a callable `f(done, total)`.
    pub fn new(progress: Option<Bound<'_, PyAny>>, total: usize) -> PyResult<Self> {
        let report = match progress {
            None => Report::None,
            Some(p) if p.is_instance_of::<PyBool>() => match p.extract::<bool>()? {
                true => stderr_report(total as u64),
                false => Report::None,
            },
            Some(p) if p.is_callable() => Report::Call(p.unbind()),
            Some(_) => {
                return Err(errors::invalid(
                    "progress",
                    "expected a callable f(done, total), True or None",
                ))
            }
        };
        Ok(Progress {
            report,
            total,
            done: Cell::new(0),
            error: RefCell::new(None),
        })
    }

    /// One more frame finished.
    pub fn advance(&self) {
        let done = self.done.get() + 1;
        self.done.set(done);
        match &self.report {
            Report::None => {}
            Report::Bar(bar) => bar.inc(1),
            Report::Log(log) => {
                if let Some(line) = log.borrow_mut().line(done as u64) {
                    eprintln!("{line}");
                }
            }
            Report::Call(f) => {
                if self.error.borrow().is_some() {
                    return;
                }
                if let Err(e) = Python::attach(|py| f.call1(py, (done, self.total)).map(drop)) {
                    *self.error.borrow_mut() = Some(e);
                }
            }
        }
    }

    /// Clear the bar; raise what a callable raised.
    pub fn finish(self) -> PyResult<()> {
        if let Report::Bar(bar) = &self.report {
            bar.finish_and_clear();
        }
        match self.error.into_inner() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// The CLI's choice: a bar where stderr is a terminal, log lines everywhere else.
fn stderr_report(total: u64) -> Report {
    if !std::io::stderr().is_terminal() {
        return Report::Log(RefCell::new(CountLog::new(WHAT, total)));
    }
    let bar = indicatif::ProgressBar::new(total);
    let style = indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {per_sec} ETA {eta}")
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
    bar.set_style(style.progress_chars("=> "));
    bar.set_message(WHAT);
    Report::Bar(bar)
}
