//! Progress of the lab's long runs (`demo`, `report`, `bench`, `stress`), handed to the caller
//! rather than printed: the lab names each stage as it starts, and the caller shows it as it
//! likes (the CLI: a bar on a terminal, a log line per stage otherwise).

use std::cell::Cell;

/// Receives the stages of a long run.
pub trait Progress {
    /// Stage `index` (1-based) of `total` starts; `label` says what it does.
    fn stage(&self, index: usize, total: usize, label: &str);
}

/// Reports nothing: for callers that do not watch.
pub struct Silent;

impl Progress for Silent {
    fn stage(&self, _: usize, _: usize, _: &str) {}
}

/// A run of a known number of stages, numbered as they start.
pub struct Stages<'a> {
    sink: &'a dyn Progress,
    total: usize,
    started: Cell<usize>,
}

impl<'a> Stages<'a> {
    /// A run of `total` stages reported to `sink`; none has started.
    pub fn new(sink: &'a dyn Progress, total: usize) -> Self {
        Stages {
            sink,
            total,
            started: Cell::new(0),
        }
    }

    /// The next stage starts. A run that starts more stages than announced reports the larger
    /// count rather than an index beyond the total.
    pub fn start(&self, label: &str) {
        let index = self.started.get() + 1;
        self.started.set(index);
        self.sink.stage(index, self.total.max(index), label);
    }

    /// Stages started so far.
    pub fn started(&self) -> usize {
        self.started.get()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    struct Log(RefCell<Vec<(usize, usize, String)>>);
    impl Progress for Log {
        fn stage(&self, index: usize, total: usize, label: &str) {
            self.0.borrow_mut().push((index, total, label.to_string()));
        }
    }

    #[test]
    fn stages_are_numbered_in_order_and_never_past_the_total() {
        let log = Log(RefCell::new(Vec::new()));
        let stages = Stages::new(&log, 2);
        for label in ["a", "b", "c"] {
            stages.start(label);
        }
        assert_eq!(stages.started(), 3);
        let got = log.0.into_inner();
        assert_eq!(
            got,
            [
                (1, 2, "a".to_string()),
                (2, 2, "b".to_string()),
                (3, 3, "c".to_string())
            ]
        );
    }
}
