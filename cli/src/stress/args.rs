//! `viewsynth stress` options.

use crate::options::GpuArgs;
use crate::options::{MEASURE, OUTPUTS};
use clap::Args;
use std::path::PathBuf;
use viewsynth_lab::job::stress::StressJob;
use viewsynth_lab::job::ArgError;

/// The example under `viewsynth stress --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  viewsynth stress --quick --only refocus,stitch
  viewsynth stress --quick --json out/stress.json   # the table as JSON (without --quick: every case)";

#[derive(Args)]
pub(crate) struct StressArgs {
    /// Smaller images and sub-cases (what the test suite runs).
    #[arg(help_heading = MEASURE, long)]
    quick: bool,
    /// Capabilities to sweep.
    #[arg(
        help_heading = MEASURE,
        long,
        value_delimiter = ',',
        default_value = "camera,refocus,cyclopean,reproject,stitch"
    )]
    only: Vec<String>,
    /// Also write the rows as JSON here.
    #[arg(help_heading = OUTPUTS, long)]
    json: Option<PathBuf>,
    #[command(flatten)]
    gpu: GpuArgs,
}

impl TryFrom<StressArgs> for StressJob {
    type Error = ArgError;
    fn try_from(a: StressArgs) -> Result<Self, ArgError> {
        StressJob::new(a.quick, &a.only, a.json, a.gpu.try_into()?)
    }
}
