//! The log line of counted work (batch frames) where no terminal shows a bar, here so that the
//! CLI and the Python package write the same lines: [`CountLog`]. (The stages of the lab's long
//! runs, `demo` and `report`, are the lab's: `viewsynth_lab::progress`.)

use std::time::{Duration, Instant};

/// How often a [`CountLog`] writes its line: often enough to show a run is alive in a log, rare
/// enough not to flood one.
pub const LOG_EVERY: Duration = Duration::from_secs(10);

/// Lines for a log (Docker, Slurm, CI, a file: no terminal) of items finished out of a known
/// total: one after the first item (the run started), one every [`LOG_EVERY`], and one after
/// the last. Each gives the count, the rate and the time left; see [`count_line`].
pub struct CountLog {
    what: String,
    total: u64,
    every: Duration,
    start: Instant,
    last: Option<Instant>,
}

impl CountLog {
    /// A log of `total` items named `what` ("batch frames"), starting now.
    pub fn new(what: impl Into<String>, total: u64) -> Self {
        Self::starting_at(what, total, LOG_EVERY, Instant::now())
    }

    /// As [`CountLog::new`] with a given interval and start time.
    pub fn starting_at(what: impl Into<String>, total: u64, every: Duration, start: Instant) -> Self {
        CountLog {
            what: what.into(),
            total,
            every,
            start,
            last: None,
        }
    }

    /// `done` items are finished: the line to write now, if one is due.
    pub fn line(&mut self, done: u64) -> Option<String> {
        self.line_at(done, Instant::now())
    }

    /// As [`CountLog::line`], at time `now`.
    pub fn line_at(&mut self, done: u64, now: Instant) -> Option<String> {
        let due = match self.last {
            None => true,
            Some(last) => now.duration_since(last) >= self.every || done >= self.total,
        };
        if !due {
            return None;
        }
        self.last = Some(now);
        Some(count_line(&self.what, done, self.total, now.duration_since(self.start)))
    }
}

/// "batch frames: 120/800 (15.0 %), 4.02 /s, ETA 2m49s" after `elapsed`.
pub fn count_line(what: &str, done: u64, total: u64, elapsed: Duration) -> String {
    let secs = elapsed.as_secs_f64().max(1e-9);
    let rate = done as f64 / secs;
    let eta = if done > 0 && total >= done {
        let left = ((total - done) as f64 / rate).round() as u64;
        format!("{}m{:02}s", left / 60, left % 60)
    } else {
        "?".to_string()
    };
    let pct = if total > 0 {
        100.0 * done as f64 / total as f64
    } else {
        100.0
    };
    format!("{what}: {done}/{total} ({pct:.1} %), {rate:.2} /s, ETA {eta}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn count_line_gives_rate_and_eta() {
        let l = count_line("batch frames", 30, 120, Duration::from_secs(10));
        assert_eq!(l, "batch frames: 30/120 (25.0 %), 3.00 /s, ETA 0m30s");
        assert!(count_line("x", 0, 5, Duration::from_secs(1)).ends_with("ETA ?"));
    }

    #[test]
    fn count_log_writes_the_first_item_each_interval_and_the_last() {
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        let mut log = CountLog::starting_at("frames", 5, Duration::from_secs(10), t0);
        let lines: Vec<Option<String>> = [(1, 1_000), (2, 5_000), (3, 11_000), (4, 12_000), (5, 13_000)]
            .into_iter()
            .map(|(done, ms)| log.line_at(done, at(ms)))
            .collect();
        let written: Vec<usize> = (0..5).filter(|&i| lines[i].is_some()).collect();
        // The first item, the first one 10 s after that line, and the last.
        assert_eq!(written, [0, 2, 4]);
        assert_eq!(lines[0].as_deref(), Some("frames: 1/5 (20.0 %), 1.00 /s, ETA 0m04s"));
        assert_eq!(lines[4].as_deref(), Some("frames: 5/5 (100.0 %), 0.38 /s, ETA 0m00s"));
    }
}
