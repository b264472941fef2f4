//! `viewsynth report` options.

use crate::options::GpuArgs;
use clap::Args;
use std::path::PathBuf;
use viewsynth::job::report::ReportJob;
use viewsynth::job::ArgError;

#[derive(Args)]
pub(crate) struct ReportArgs {
    /// Output folder (created if missing): report.md, report.csv, report.svg.
    #[arg(long, default_value = "out/report")]
    out_dir: PathBuf,
    /// Folder with middlebury2003_cones/ and middlebury2003_teddy/ (skipped when absent).
    #[arg(long)]
    data_dir: Option<PathBuf>,
    /// A user cyclopean case with a reference middle view, laid out as `viewsynth scene`
    /// writes it (cameras.json, {left,right}_rgb.png, *_device_depth.exr, middle_rgb.png).
    /// Repeatable.
    #[arg(long = "case")]
    cases: Vec<PathBuf>,
    /// Timed repetitions per row (the median is reported).
    #[arg(long, default_value_t = 3, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=1000))]
    repeats: usize,
    #[command(flatten)]
    gpu: GpuArgs,
}

impl TryFrom<ReportArgs> for ReportJob {
    type Error = ArgError;
    fn try_from(a: ReportArgs) -> Result<Self, ArgError> {
        ReportJob::check_cases(&a.cases)?;
        Ok(ReportJob {
            out_dir: a.out_dir,
            data_dir: a.data_dir,
            cases: a.cases,
            repeats: a.repeats,
            gpu: a.gpu.try_into()?,
        })
    }
}
