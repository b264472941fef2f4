//! `report` and `demo`: every method's error against ground truth next to its run time
//! (report.{md,csv,svg}), and the demo that renders, refocuses and reports in one go.

use super::{ArgError, HostStages, JobError, LabEvent, LabHost};
use crate::report::WrittenReport;
use std::path::{Path, PathBuf};
use viewsynth::job::{Event, GpuRequest};

/// A checked report run.
#[derive(Debug, Clone)]
pub struct ReportJob {
    /// Output folder.
    pub out_dir: PathBuf,
    /// Folder with the real-data sets (skipped when absent).
    pub data_dir: Option<PathBuf>,
    /// User cyclopean cases laid out as `viewsynth scene` writes them.
    pub cases: Vec<PathBuf>,
    /// The interpolating peers' folders of middle views, one image per real pair
    /// ([`crate::eval::flow_peer`]: DIS flow, RIFE); need `data_dir`.
    pub peers: Vec<crate::eval::flow_peer::PeerImages>,
    /// Timed repetitions per row.
    pub repeats: usize,
    /// The GPU to render on.
    pub gpu: GpuRequest,
}

impl ReportJob {
    /// Refuses a `--case` that is no case folder (one `viewsynth scene` wrote, with its
    /// cameras.json): a wrong command line (exit 2), seen before the GPU opens or a row is measured.
    pub fn check_cases(cases: &[PathBuf]) -> Result<(), viewsynth::job::ArgError> {
        match cases.iter().find(|c| !c.join("cameras.json").is_file()) {
            Some(case) => Err(viewsynth::job::ArgError::Invalid(viewsynth::Error::param(
                "--case",
                format!(
                    "{} is not a case folder (no cameras.json; `viewsynth scene --out-dir` writes one)",
                    viewsynth::error::excerpt(&case.display().to_string())
                ),
            ))),
            None => Ok(()),
        }
    }

    /// Measures every row and writes the report files; returns the report and their paths.
    pub fn run(&self, host: &dyn LabHost) -> Result<WrittenReport, JobError> {
        Self::check_cases(&self.cases)?;
        if let Some(d) = &self.data_dir {
            if !d.is_dir() {
                return Err(ArgError::DataDirMissing(d.clone()).into());
            }
            if std::fs::read_dir(d).map_or(true, |mut e| e.next().is_none()) {
                host.lab_event(LabEvent::EmptyDataDir(d));
            }
        }
        if let Some(data) = &self.data_dir {
            for images in &self.peers {
                // A missing peer image fails the run before the GPU opens or a row is measured.
                crate::eval::flow_peer::check_peer(data, images)?;
            }
        }
        let device = host.open_device(&self.gpu, viewsynth::job::Backend::Gl)?;
        let files = crate::eval::run_report_with_progress(
            &device,
            &self.out_dir,
            self.data_dir.as_deref(),
            &self.cases,
            &self.peers,
            self.repeats,
            &HostStages(host),
        );
        host.event(Event::Finished);
        Ok(files?)
    }
}

/// The demo: the built-in scene rendered, refocused at 5 scales and synthesised with every
/// cyclopean method, with its report.
#[derive(Debug, Clone)]
pub struct DemoJob {
    /// Output folder.
    pub out_dir: PathBuf,
    /// The GPU to render on.
    pub gpu: GpuRequest,
}

impl DemoJob {
    /// Renders everything; returns the report, its files and, last, refocus_check.md.
    pub fn run(&self, host: &dyn LabHost) -> Result<WrittenReport, JobError> {
        let device = host.open_device(&self.gpu, viewsynth::job::Backend::Gl)?;
        let report = crate::demo::run_with_progress(&device, Path::new(&self.out_dir), &HostStages(host));
        host.event(Event::Finished);
        Ok(report?)
    }
}
