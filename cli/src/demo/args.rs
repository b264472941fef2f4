//! `viewsynth demo` options.

use crate::options::GpuArgs;
use crate::options::OUTPUTS;
use clap::Args;
use std::path::PathBuf;
use viewsynth::job::ArgError;
use viewsynth_lab::job::report::DemoJob;

/// The example under `viewsynth demo --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  viewsynth demo --out-dir out/demo             # a summary; the full report in out/demo/report.md
  viewsynth demo --out-dir out/demo --verbose   # the whole report on stdout";

#[derive(Args)]
pub(crate) struct DemoArgs {
    /// Output folder (created if missing).
    #[arg(help_heading = OUTPUTS, long, default_value = "out/demo")]
    out_dir: PathBuf,
    /// Print the whole report table to stdout (by default a summary per method; the table is
    /// in <out-dir>/report.md either way).
    #[arg(help_heading = OUTPUTS, long, short)]
    pub verbose: bool,
    #[command(flatten)]
    gpu: GpuArgs,
}

impl TryFrom<DemoArgs> for DemoJob {
    type Error = ArgError;
    fn try_from(a: DemoArgs) -> Result<Self, ArgError> {
        Ok(DemoJob {
            out_dir: a.out_dir,
            gpu: a.gpu.try_into()?,
        })
    }
}
