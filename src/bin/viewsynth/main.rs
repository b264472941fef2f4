//! viewsynth command line. Each command's `args.rs` parses its options (clap) and converts them
//! into a checked job of the library (`viewsynth::job`) before any work; its `run.rs` runs the
//! job and prints the result. This file only parses, dispatches and maps failures to exit codes:
//!
//! - 0: success;
//! - 2: anything wrong with the command line: it does not parse (clap's own usage error,
//!   printed with `try '--help'`), or a value parses but the job's conversion refuses it (out
//!   of range, conflicting options; [`viewsynth::job::ArgError::is_usage`]);
//! - 1: anything found while running: inputs (a file named by an option included), the GPU,
//!   output files, a failed batch frame or stress case, a broken compare threshold.
//!
//! anyhow lives here only, at the edge; the library's errors are typed.

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::process::ExitCode;
use viewsynth::io;

mod host;
mod options;
mod progress;
mod text;

mod bench {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod compare {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod cyclopean {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod demo {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod info {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod refocus {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod report {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod reproject {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod scene {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod stitch {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod stress {
    pub(crate) mod args;
    pub(crate) mod run;
}

#[derive(Parser)]
#[command(
    name = "viewsynth",
    version,
    about = "Headless GPU view synthesis from RGB-D and stereo images"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Largest image (width x height) any input may declare or any output may have; checked
    /// from file headers before pixels are read (default 8192 x 8192, about 1.5 GB for the
    /// heaviest command).
    #[arg(long, global = true, default_value_t = io::DEFAULT_MAX_PIXELS,
          value_parser = clap::value_parser!(u64).range(1..=(1u64 << 32)))]
    max_pixels: u64,
}

#[derive(Subcommand)]
enum Command {
    /// Print the GPU, GL version, EGL platform/device and limits this machine renders with.
    #[command(allow_negative_numbers = true)]
    Info(info::args::InfoArgs),
    /// Re-render RGB + metric depth at other focal lengths (same pose).
    #[command(allow_negative_numbers = true)]
    Refocus(Box<refocus::args::RefocusArgs>),
    /// Synthesise the middle (spectator) view of a stereo pair from each eye's colour and depth.
    #[command(allow_negative_numbers = true)]
    Cyclopean(Box<cyclopean::args::CyclopeanArgs>),
    /// Reproject one view of a parallel stereo rig (left eye, centre view or right eye) to the
    /// other eye(s) from colour + depth (view Z, device depth or disparity); disocclusions stay
    /// invalid (mask 0), nothing is hole-filled.
    #[command(allow_negative_numbers = true)]
    Reproject(Box<reproject::args::ReprojectArgs>),
    /// Stitch an omni-directional stereo (ODS) 360 equirect (top-bottom, left eye on top) from
    /// six over-wide cube faces per eye: the built-in scene's, or your own from --faces DIR.
    #[command(allow_negative_numbers = true)]
    Stitch(Box<stitch::args::StitchArgs>),
    /// Ray-trace a ground-truth scene (built-in or JSON) on the GPU from a stereo rig: left, right
    /// and middle colour, view distance and device depth, and a cameras.json that
    /// `viewsynth cyclopean` reads.
    #[command(allow_negative_numbers = true)]
    Scene(scene::args::SceneArgs),
    /// Compare two renderings (e.g. ours and a Vulkan renderer's) after converting row order,
    /// NDC depth range, reversed-Z and device vs linear depth; names a convention that fits far
    /// better than the declared one. Writes a diff image.
    #[command(allow_negative_numbers = true)]
    Compare(Box<compare::args::CompareArgs>),
    /// Render the built-in scene, refocus it at 5 scales, synthesise the cyclopean middle view of
    /// a stereo pair with each method, and write every output plus the error/run-time report.
    #[command(allow_negative_numbers = true)]
    Demo(demo::args::DemoArgs),
    /// Measure every method's error against ground truth (built-in scene, and real data when
    /// --data-dir holds ../shared/data's sets) next to its run time: report.{md,csv,svg}.
    #[command(allow_negative_numbers = true)]
    Report(report::args::ReportArgs),
    /// Benchmark refocus (mesh and full-screen paths) and cyclopean (2 x 1280x720 eyes) and print
    /// median timings.
    #[command(allow_negative_numbers = true)]
    Bench(bench::args::BenchArgs),
    /// Sweep stiff and extreme cases of every capability (focal scales 0.05..20, 1 mm..100 km,
    /// near/far 1e-7, standard vs reversed-Z, NaN/Inf depth, 1x1 to the largest image, parallel
    /// gaze, zero IPD, ...): GPU f32 against the f64 reference, as a table with the first failing
    /// case. Exits 1 if any case fails.
    #[command(allow_negative_numbers = true)]
    Stress(stress::args::StressArgs),
}

/// Exit status of a failure found while running.
const RUN_ERROR: u8 = 1;
/// Exit status of a command line that is wrong (clap uses the same for what it refuses).
const USAGE_ERROR: u8 = 2;

/// A conversion's refusal of the command line (exit 2), told apart from run errors in `main`.
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
struct Usage(viewsynth::job::ArgError);

/// The job a command's options convert to; a refusal of the command line itself becomes
/// [`Usage`], one found in a file an option names stays a run error.
fn job<A, J: TryFrom<A, Error = viewsynth::job::ArgError>>(args: A) -> Result<J> {
    J::try_from(args).map_err(|e| {
        if e.is_usage() {
            anyhow::Error::new(Usage(e))
        } else {
            anyhow::Error::new(e)
        }
    })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = io::set_max_pixels(cli.max_pixels)
        .map_err(anyhow::Error::from)
        .and_then(|()| run(cli.command));
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", error_chain(&e));
            if e.is::<Usage>() {
                // As clap ends its own usage errors: both kinds read alike.
                eprintln!("\nFor more information, try '--help'.");
                return ExitCode::from(USAGE_ERROR);
            }
            ExitCode::from(RUN_ERROR)
        }
    }
}

/// The error and its causes joined by ": ", skipping a cause whose text the message already
/// holds (the library's I/O errors print their source, which is also their cause).
fn error_chain(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text
}

/// Converts the command's options into its job (every check, before any work), then runs it.
fn run(command: Command) -> Result<ExitCode> {
    match command {
        Command::Info(a) => info::run::info(&job(a)?)?,
        Command::Refocus(a) => refocus::run::refocus(job(*a)?)?,
        Command::Cyclopean(a) => cyclopean::run::cyclopean(&job(*a)?)?,
        Command::Reproject(a) => reproject::run::reproject(&job(*a)?)?,
        Command::Stitch(a) => stitch::run::stitch(&job(*a)?)?,
        Command::Scene(a) => scene::run::scene(&job(a)?)?,
        Command::Compare(a) => return compare::run::compare(&job(*a)?),
        Command::Demo(a) => demo::run::demo(&job(a)?)?,
        Command::Report(a) => report::run::report(&job(a)?)?,
        Command::Bench(a) => {
            let json = a.json;
            bench::run::bench(&job(a)?, json)?
        }
        Command::Stress(a) => stress::run::stress(&job(a)?)?,
    }
    Ok(ExitCode::SUCCESS)
}
