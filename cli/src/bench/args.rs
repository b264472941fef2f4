//! `viewsynth bench` options.

use crate::options::GpuArgs;
use crate::options::{MEASURE, OUTPUTS};
use clap::Args;
use viewsynth_lab::job::bench::{BenchJob, BenchOptions};
use viewsynth_lab::job::ArgError;

/// The example under `viewsynth bench --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  viewsynth bench --sizes 640x480 --repeats 3
  viewsynth bench --batch 4 --jobs 2           # the pipelined refocus batch on 4 frames
  viewsynth bench --sizes 320x240 --repeats 1 --json";

#[derive(Args)]
pub(crate) struct BenchArgs {
    /// Sizes WxH to measure.
    #[arg(help_heading = MEASURE, long, value_delimiter = ',', default_value = "640x480,1280x720")]
    sizes: Vec<String>,
    /// Repetitions per measurement (the median is reported).
    #[arg(help_heading = MEASURE, long, default_value_t = 7, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=1000))]
    repeats: usize,
    /// Benchmark the pipelined refocus batch instead: N frames of the built-in scene, or a
    /// manifest FILE; runs the synchronous batch as the in-run baseline and prints frames/s,
    /// per-stage medians and the stage that bounds the throughput.
    #[arg(help_heading = MEASURE, long, value_name = "N|FILE")]
    batch: Option<String>,
    /// With --batch: threads per CPU pool (default: the number of cores).
    #[arg(help_heading = MEASURE, long, requires = "batch")]
    jobs: Option<usize>,
    /// With --batch: PNG compression (fast, default, best).
    #[arg(help_heading = MEASURE, long, default_value = "fast", requires = "batch")]
    png_compression: String,
    /// Also time every pass on the Vulkan device (`--device auto`; the same shaders as SPIR-V)
    /// beside GL; with --batch, the same pipelined batch on it.
    #[arg(help_heading = MEASURE, long)]
    with_vulkan: bool,
    /// Print one JSON object instead of the tables.
    #[arg(help_heading = OUTPUTS, long)]
    pub json: bool,
    #[command(flatten)]
    gpu: GpuArgs,
}

impl TryFrom<BenchArgs> for BenchJob {
    type Error = ArgError;
    fn try_from(a: BenchArgs) -> Result<Self, ArgError> {
        BenchJob::new(BenchOptions {
            sizes: a.sizes,
            repeats: a.repeats,
            batch: a.batch,
            jobs: a.jobs,
            png_compression: a.png_compression,
            with_vulkan: a.with_vulkan,
            gpu: a.gpu.try_into()?,
        })
    }
}
