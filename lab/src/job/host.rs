//! What a lab job needs from the program around it beyond the library's [`Host`]: someone to
//! tell the lab's own events to (the stages of a long run, a skipped data folder).

use crate::progress::Progress;
use std::path::Path;
use viewsynth::job::Host;

/// Something a lab job tells the person running it, beside the library's
/// [`Event`](viewsynth::job::Event)s.
#[derive(Debug)]
pub enum LabEvent<'a> {
    /// `--data-dir` exists but is empty: the real-data rows are skipped.
    EmptyDataDir(&'a Path),
    /// Stage `index` (1-based) of `total` of a long run (`demo`, `report`) starts.
    Stage {
        /// This stage's number.
        index: usize,
        /// How many stages the run announced.
        total: usize,
        /// What the stage does.
        label: &'a str,
    },
}

/// The program around a lab job: the library's [`Host`], and a listener for [`LabEvent`]s.
pub trait LabHost: Host {
    /// Something to tell the person running the lab job.
    fn lab_event(&self, event: LabEvent<'_>);
}

/// A job's stages told to its host as [`LabEvent::Stage`] (the lab's [`Progress`] sink for
/// long runs).
pub struct HostStages<'h>(pub &'h dyn LabHost);

impl Progress for HostStages<'_> {
    fn stage(&self, index: usize, total: usize, label: &str) {
        self.0.lab_event(LabEvent::Stage { index, total, label });
    }
}
