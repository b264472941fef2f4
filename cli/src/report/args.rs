//! `viewsynth report` options.

use crate::options::GpuArgs;
use crate::options::{INPUTS, MEASURE, OUTPUTS};
use clap::Args;
use std::path::PathBuf;
use viewsynth::job::ArgError;
use viewsynth_lab::eval::flow_peer::{PeerImages, DIS_FLOW, RIFE};
use viewsynth_lab::job::report::ReportJob;

/// The example under `viewsynth report --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  viewsynth report --data-dir ../shared/data --out-dir out/report
  viewsynth report --case out/scene --out-dir out/report_case   # with a user stereo case";

#[derive(Args)]
pub(crate) struct ReportArgs {
    /// Folder with middlebury2003_cones/ and middlebury2003_teddy/ (skipped when absent).
    #[arg(help_heading = INPUTS, long)]
    data_dir: Option<PathBuf>,
    /// A user cyclopean case with a reference middle view, laid out as `viewsynth scene` writes it
    /// (cameras.json, {left,right}_rgb.png, *_device_depth.exr, middle_rgb.png).
    ///
    /// Repeatable.
    #[arg(help_heading = INPUTS, long = "case")]
    cases: Vec<PathBuf>,
    /// Folder with the DIS optical-flow peer's middle views, one PNG per real pair with a true
    /// middle view (cones_2_6_4.png, tsukuba_2_4_3.png, tsukuba_1_5_3.png and, with the
    /// development set, art_1_5_3.png ... midd2_1_5_3.png), written by
    /// python/peers/flow_interpolation.py: scored over all pixels in a "DIS flow interpolation"
    /// row beside viewsynth's complete frame from the same two images, measured only when a peer
    /// is given (docs/report.md). A missing file is an error.
    #[arg(help_heading = INPUTS, long, value_name = "DIR", requires = "data_dir")]
    flow_peer: Option<PathBuf>,
    /// Folder with the RIFE v4.25 peer's middle views, named as for --flow-peer, written by
    /// python/peers/rife_interpolation.py: scored in a "RIFE v4.25 interpolation" row beside
    /// them. A missing file is an error.
    #[arg(help_heading = INPUTS, long, value_name = "DIR", requires = "data_dir")]
    rife_peer: Option<PathBuf>,
    /// Timed repetitions per row (the median is reported).
    #[arg(help_heading = MEASURE, long, default_value_t = 3, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=1000))]
    repeats: usize,
    /// Output folder (created if missing): report.md, report.csv, report.svg.
    #[arg(help_heading = OUTPUTS, long, default_value = "out/report")]
    out_dir: PathBuf,
    /// Print the whole report table to stdout (by default a summary per method; the table is
    /// in <out-dir>/report.md either way).
    #[arg(help_heading = OUTPUTS, long, short)]
    pub verbose: bool,
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
            peers: [(DIS_FLOW, a.flow_peer), (RIFE, a.rife_peer)]
                .into_iter()
                .filter_map(|(peer, dir)| dir.map(|dir| PeerImages { peer, dir }))
                .collect(),
            repeats: a.repeats,
            gpu: a.gpu.try_into()?,
        })
    }
}
