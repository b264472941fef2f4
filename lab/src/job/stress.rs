//! `stress`: stiff and extreme cases of every capability, GPU f32 against the f64 reference.
//! The options become a [`StressJob`]; a failing case fails the job after the table is
//! written.

use super::{ArgError, HostStages, JobError, LabHost};
use crate::progress::Progress as _;
use crate::stress::{first_failure, run_stress, StressOptions, StressRow, CAPABILITIES};
use std::path::PathBuf;
use viewsynth::job::InContext;
use viewsynth::job::{Event, GpuRequest};

/// A checked stress sweep.
#[derive(Debug, Clone)]
pub struct StressJob {
    capabilities: Vec<&'static str>,
    quick: bool,
    json: Option<PathBuf>,
    gpu: GpuRequest,
}

impl StressJob {
    /// `only` names capabilities of [`CAPABILITIES`] (blank entries are ignored).
    pub fn new(quick: bool, only: &[String], json: Option<PathBuf>, gpu: GpuRequest) -> Result<Self, ArgError> {
        let mut capabilities = Vec::new();
        for c in only.iter().map(|s| s.trim()).filter(|s| !s.is_empty()) {
            let known = CAPABILITIES
                .iter()
                .find(|k| **k == c)
                .ok_or_else(|| ArgError::StressCapability {
                    given: c.to_string(),
                    known: CAPABILITIES.join(", "),
                })?;
            capabilities.push(*known);
        }
        // `--only ""` or `--only ,`: asked for a subset and named none (0 rows must not pass).
        if !only.is_empty() && capabilities.is_empty() {
            return Err(ArgError::StressNothing(only.join(",")));
        }
        Ok(StressJob {
            capabilities,
            quick,
            json,
            gpu,
        })
    }

    /// Sweeps the cases: one row each.
    pub fn run(&self, host: &dyn LabHost) -> Result<Vec<StressRow>, JobError> {
        let device = host.open_device(&self.gpu, viewsynth::job::Backend::Gl)?;
        // One capability at a time, each a stage of the progress shown.
        let (stages, mut rows) = (HostStages(host), Vec::new());
        let total = self.capabilities.len();
        let swept = (|| -> viewsynth::Result<()> {
            for (i, cap) in self.capabilities.iter().enumerate() {
                stages.stage(i + 1, total, &format!("stress: {cap}"));
                rows.extend(run_stress(&device, &[cap], StressOptions { quick: self.quick })?);
            }
            Ok(())
        })();
        host.event(Event::Finished);
        swept?;
        Ok(rows)
    }

    /// Writes the rows as JSON where `--json` asked (after the table is shown).
    pub fn write_json(&self, rows: &[StressRow]) -> Result<(), JobError> {
        if let Some(path) = &self.json {
            // The file layer every output goes through (a FIFO or device at the path is refused).
            let text =
                serde_json::to_string_pretty(rows).map_err(|e| viewsynth::Error::param("json", e.to_string()))?;
            let write: viewsynth::io::PathWriter<'_> =
                Box::new(|staged| std::fs::write(staged, text.as_bytes()).map_err(|e| viewsynth::Error::io(staged, e)));
            viewsynth::io::write_paths_all_or_none(vec![(path.clone(), write)])
                .within(|| format!("writing {}", path.display()))?;
        }
        Ok(())
    }

    /// An error naming the first failing case, if any.
    pub fn outcome(rows: &[StressRow]) -> Result<(), JobError> {
        match first_failure(rows) {
            Some(r) => Err(JobError::StressFailed {
                capability: r.capability.to_string(),
                case: r.case.clone(),
                worst: r.worst.clone(),
            }),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{GpuRequest, StressJob};

    #[test]
    fn only_known_capabilities_are_swept() {
        let only = ["camera".to_string(), " stitch ".to_string(), String::new()];
        let job = StressJob::new(true, &only, None, GpuRequest::default()).unwrap();
        assert_eq!(job.capabilities, ["camera", "stitch"]);
        let bad = StressJob::new(true, &["optics".to_string()], None, GpuRequest::default()).unwrap_err();
        assert!(
            bad.to_string()
                .starts_with("--only 'optics': expected a list of camera"),
            "{bad}"
        );
    }
}
