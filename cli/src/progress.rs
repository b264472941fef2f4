//! Progress of long commands: a bar with rate and ETA on a terminal (indicatif), a log line
//! every few seconds otherwise (Docker, Slurm and CI logs have no terminal), so no long run is
//! silent.

use std::cell::{Cell, RefCell};
use std::io::IsTerminal;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use viewsynth::progress::{CountLog, LOG_EVERY};

pub(crate) struct Progress {
    bar: Option<indicatif::ProgressBar>,
    /// The library's log lines where stderr is not a terminal (the Python package writes the same).
    log: RefCell<CountLog>,
    done: Cell<u64>,
}

impl Progress {
    pub(crate) fn new(what: &'static str, total: u64) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = indicatif::ProgressBar::new(total);
            let style = indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {per_sec} ETA {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            bar.set_style(style.progress_chars("=> "));
            bar.set_message(what);
            bar
        });
        Progress {
            bar,
            log: RefCell::new(CountLog::new(what, total)),
            done: Cell::new(0),
        }
    }

    /// One more item finished.
    pub(crate) fn inc(&self) {
        let done = self.done.get() + 1;
        self.done.set(done);
        if let Some(bar) = &self.bar {
            bar.inc(1);
            return;
        }
        if let Some(line) = self.log.borrow_mut().line(done) {
            errln!("{line}");
        }
    }

    pub(crate) fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// The lab's stage reports ([`viewsynth_lab::progress::Progress`]) for `demo` and `report`: on a
/// terminal a bar whose message is the running stage and whose clock keeps ticking through long
/// stages; otherwise a log line when a stage starts and every [`LOG_EVERY`] while it runs.
pub(crate) struct StageProgress {
    bar: Option<indicatif::ProgressBar>,
    log: Option<StageLog>,
    start: Instant,
}

/// The non-terminal log: the running stage, shared with a thread that repeats its line.
struct StageLog {
    state: Arc<(Mutex<LogState>, Condvar)>,
    ticker: Option<std::thread::JoinHandle<()>>,
}

struct LogState {
    stage: Option<(usize, usize, String)>,
    last_line: Instant,
    done: bool,
}

impl StageProgress {
    pub(crate) fn new() -> Self {
        if std::io::stderr().is_terminal() {
            let bar = indicatif::ProgressBar::new(0);
            let style = indicatif::ProgressStyle::with_template("{spinner} [{pos}/{len}] {msg} ({elapsed})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner());
            bar.set_style(style);
            bar.enable_steady_tick(Duration::from_millis(200));
            return StageProgress {
                bar: Some(bar),
                log: None,
                start: Instant::now(),
            };
        }
        let start = Instant::now();
        let state = Arc::new((
            Mutex::new(LogState {
                stage: None,
                last_line: start,
                done: false,
            }),
            Condvar::new(),
        ));
        let shared = Arc::clone(&state);
        let ticker = std::thread::spawn(move || {
            let (lock, wake) = &*shared;
            let Ok(mut st) = lock.lock() else { return };
            while !st.done {
                let due = st.last_line + LOG_EVERY;
                let now = Instant::now();
                if now >= due {
                    if let Some((i, n, label)) = &st.stage {
                        errln!("{}, still running", stage_line(*i, *n, label, start.elapsed()));
                    }
                    st.last_line = now;
                    continue;
                }
                st = match wake.wait_timeout(st, due - now) {
                    Ok((st, _)) => st,
                    Err(_) => return,
                };
            }
        });
        StageProgress {
            bar: None,
            log: Some(StageLog {
                state,
                ticker: Some(ticker),
            }),
            start,
        }
    }

    pub(crate) fn finish(&mut self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        if let Some(log) = &mut self.log {
            if let Ok(mut st) = log.state.0.lock() {
                st.done = true;
            }
            log.state.1.notify_all();
            if let Some(t) = log.ticker.take() {
                let _ = t.join();
            }
        }
    }
}

impl Drop for StageProgress {
    fn drop(&mut self) {
        self.finish();
    }
}

impl viewsynth_lab::progress::Progress for StageProgress {
    fn stage(&self, index: usize, total: usize, label: &str) {
        if let Some(bar) = &self.bar {
            bar.set_length(total as u64);
            bar.set_position(index as u64 - 1);
            bar.set_message(label.to_string());
        }
        if let Some(log) = &self.log {
            if let Ok(mut st) = log.state.0.lock() {
                st.stage = Some((index, total, label.to_string()));
                st.last_line = Instant::now();
                errln!("{}", stage_line(index, total, label, self.start.elapsed()));
            }
        }
    }
}

/// "[3/9] demo: cyclopean middle views (41 s so far)".
fn stage_line(index: usize, total: usize, label: &str, elapsed: Duration) -> String {
    format!("[{index}/{total}] {label} ({} s so far)", elapsed.as_secs())
}

#[cfg(test)]
mod tests {
    use super::stage_line;
    use std::time::Duration;

    #[test]
    fn stage_line_names_the_stage_and_the_time() {
        let l = stage_line(3, 9, "demo: cyclopean middle views", Duration::from_millis(41_700));
        assert_eq!(l, "[3/9] demo: cyclopean middle views (41 s so far)");
    }
}
