//! `viewsynth demo` options.

use crate::options::GpuArgs;
use clap::Args;
use std::path::PathBuf;
use viewsynth::job::report::DemoJob;
use viewsynth::job::ArgError;

#[derive(Args)]
pub(crate) struct DemoArgs {
    /// Output folder (created if missing).
    #[arg(long, default_value = "out/demo")]
    out_dir: PathBuf,
    /// Print the whole report table to stdout (by default a summary per method; the table is
    /// in <out-dir>/report.md either way).
    #[arg(long, short)]
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
