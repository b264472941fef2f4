//! viewsynth command line. Each command's `args.rs` parses its options (clap) and converts them
//! into a checked job of the library (`viewsynth::job`) before any work; its `run.rs` runs the
//! job and prints the result. This file only parses, dispatches and maps failures to exit codes:
//!
//! - 0: success;
//! - 2: anything wrong with the command line: it does not parse (clap's own usage error,
//!   printed with `try '--help'`; a malformed `--shard` included), or a value parses but the
//!   job's conversion refuses it (out of range, conflicting options;
//!   [`viewsynth::job::ArgError::is_usage`], [`viewsynth_lab::job::ArgError::is_usage`]);
//! - 1: anything found while running: inputs (a file named by an option included), the GPU,
//!   output files, a failed batch frame or stress case, a broken compare threshold;
//! - killed by SIGPIPE (141 in a shell): stdout or stderr was closed early (`| head`).
//!
//! anyhow lives here only, at the edge; the library's errors are typed.

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::process::ExitCode;
use viewsynth::io;

/// `println!` for a command's results, through [`stdout::write`]: returns from the enclosing
/// function with an error (exit 1) when stdout refuses the text.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::stdout::write(format_args!($($arg)*), true)?
    };
}

/// `print!` through [`stdout::write`] (see [`outln!`]).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::stdout::write(format_args!($($arg)*), false)?
    };
}

/// `eprintln!` through [`stderr::write`]: never panics; a refused write makes the run exit 1.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::stderr::write(format_args!($($arg)*))
    };
}

#[cfg(test)]
mod front_ends;
mod host;
mod options;
mod progress;
mod stderr;
mod stdout;
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
mod index {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod info {
    pub(crate) mod args;
    pub(crate) mod run;
}
mod manifest {
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
    #[arg(long, global = true, default_value_t = io::DEFAULT_MAX_PIXELS, help_heading = options::INPUTS,
          value_parser = clap::value_parser!(u64).range(1..=(1u64 << 32)))]
    max_pixels: u64,
}

#[derive(Subcommand)]
enum Command {
    /// Print the GPU, GL version, EGL platform/device and limits this machine renders with.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = info::args::EXAMPLES)]
    Info(info::args::InfoArgs),
    /// Re-render RGB + metric depth at other focal lengths (same pose).
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = refocus::args::EXAMPLES)]
    Refocus(Box<refocus::args::RefocusArgs>),
    /// Join the index parts that `refocus --batch` runs (shards) wrote into OUT/index.jsonl: one
    /// row per target (frame, scale, K', size, coverage, files).
    #[command(after_help = SHORT_HELP_NOTE, after_long_help = index::args::EXAMPLES)]
    Index(index::args::IndexArgs),
    /// Make a `refocus --batch` manifest (CSV) from a TUM-style RGB-D sequence: rgb.txt and
    /// depth.txt paired by nearest timestamp, with the dataset's intrinsics and depth scale.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = manifest::args::EXAMPLES)]
    Manifest(manifest::args::ManifestArgs),
    /// Synthesise the middle (spectator) view of a stereo pair from each eye's colour and depth.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = cyclopean::args::EXAMPLES)]
    Cyclopean(Box<cyclopean::args::CyclopeanArgs>),
    /// Reproject one view of a parallel stereo rig (left eye, centre view or right eye) to the
    /// other eye(s) from colour + depth (view Z, device depth or disparity); disocclusions stay
    /// invalid (mask 0), nothing is hole-filled.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = reproject::args::EXAMPLES)]
    Reproject(Box<reproject::args::ReprojectArgs>),
    /// Stitch an omni-directional stereo (ODS) 360 equirect (top-bottom, left eye on top) from
    /// six over-wide cube faces per eye: the built-in scene's, or your own from --faces DIR.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = stitch::args::EXAMPLES)]
    Stitch(Box<stitch::args::StitchArgs>),
    /// Ray-trace a ground-truth scene (built-in or JSON) on the GPU from a stereo rig: left, right
    /// and middle colour, view distance and device depth, and a cameras.json that
    /// `viewsynth cyclopean` reads.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = scene::args::EXAMPLES)]
    Scene(scene::args::SceneArgs),
    /// Compare two renderings (e.g. ours and a Vulkan renderer's) after converting row order,
    /// NDC depth range, reversed-Z and device vs linear depth: error distributions, share gates
    /// and FLIP for CI; names a convention that fits far better than the declared one.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = compare::args::EXAMPLES)]
    Compare(Box<compare::args::CompareArgs>),
    /// Render the built-in scene, refocus it at 5 scales, synthesise the cyclopean middle view of
    /// a stereo pair with each method, and write every output plus the error/run-time report.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = demo::args::EXAMPLES)]
    Demo(demo::args::DemoArgs),
    /// Measure every method's error against ground truth (built-in scene, and real data when
    /// --data-dir holds ../shared/data's sets) next to its run time: report.{md,csv,svg}.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = report::args::EXAMPLES)]
    Report(report::args::ReportArgs),
    /// Benchmark refocus (mesh and full-screen paths) and cyclopean (2 x 1280x720 eyes) and print
    /// median timings.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = bench::args::EXAMPLES)]
    Bench(bench::args::BenchArgs),
    /// Sweep stiff and extreme cases of every capability (focal scales 0.05..20, 1 mm..100 km,
    /// near/far 1e-7, standard vs reversed-Z, NaN/Inf depth, 1x1 to the largest image, parallel
    /// gaze, zero IPD, ...): GPU f32 against the f64 reference, as a table with the first failing
    /// case. Exits 1 if any case fails.
    #[command(allow_negative_numbers = true, after_help = SHORT_HELP_NOTE, after_long_help = stress::args::EXAMPLES)]
    Stress(stress::args::StressArgs),
}

/// What `-h` ends with: it lists the options in a line each; `--help` adds the detail and the
/// examples.
const SHORT_HELP_NOTE: &str = "Examples and each option in detail: --help";

/// Exit status of a failure found while running.
const RUN_ERROR: u8 = 1;
/// Exit status of a command line that is wrong (clap uses the same for what it refuses).
const USAGE_ERROR: u8 = 2;

/// A conversion's refusal of the command line (exit 2), told apart from run errors in `main`;
/// it reads as the refusal it holds (its message, then its causes).
#[derive(Debug)]
struct Usage(Box<dyn std::error::Error + Send + Sync>);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for Usage {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

/// A job conversion's refusal: the library's or the lab's, each saying whether the command
/// line itself is at fault.
trait Refusal: std::error::Error + Send + Sync + 'static {
    fn is_usage(&self) -> bool;
}

impl Refusal for viewsynth::job::ArgError {
    fn is_usage(&self) -> bool {
        viewsynth::job::ArgError::is_usage(self)
    }
}

impl Refusal for viewsynth_lab::job::ArgError {
    fn is_usage(&self) -> bool {
        viewsynth_lab::job::ArgError::is_usage(self)
    }
}

/// The job a command's options convert to; a refusal of the command line itself becomes
/// [`Usage`], one found in a file an option names stays a run error.
fn job<A, J: TryFrom<A, Error = E>, E: Refusal>(args: A) -> Result<J> {
    J::try_from(args).map_err(|e| {
        if e.is_usage() {
            anyhow::Error::new(Usage(Box::new(e)))
        } else {
            anyhow::Error::new(e)
        }
    })
}

fn main() -> ExitCode {
    quiet_on_closed_pipe();
    file_too_large_is_an_error();
    keep_freed_images_for_reuse();
    let cli = Cli::parse();
    let result = io::set_max_pixels(cli.max_pixels)
        .map_err(anyhow::Error::from)
        .and_then(|()| run(cli.command))
        .and_then(|code| stdout::flush().map(|()| code).map_err(anyhow::Error::from))
        .and_then(|code| stderr::failure().map_or(Ok(code), |e| Err(e.into())));
    match result {
        Ok(code) => code,
        Err(e) => {
            errln!("error: {}", error_chain(&e));
            if e.is::<Usage>() {
                // As clap ends its own usage errors: both kinds read alike.
                errln!("\nFor more information, try '--help'.");
                return ExitCode::from(USAGE_ERROR);
            }
            ExitCode::from(RUN_ERROR)
        }
    }
}

/// A closed stdout or stderr (`viewsynth demo | head`) ends the process as it ends `cat` or
/// `grep`: killed by SIGPIPE, status 141 in a shell, no message. Rust ignores SIGPIPE, so every
/// `println!`/`eprintln!` would panic (exit 101) on EPIPE instead; restoring the default
/// disposition covers every print site at once (ours, clap's, indicatif's, worker threads'),
/// where catching `BrokenPipe` would have to be repeated at each of them and a missed one
/// panics. Outputs are staged and renamed only when complete, so a run cut short this way
/// leaves the previous files as they were. The process writes to no other pipe or socket.
fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: at the start of main, before any thread exists; SIG_DFL is a valid disposition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// A file growing past `ulimit -f` raises SIGXFSZ, whose default action kills the process
/// (status 153, no message, after the earlier files of the set were already written to the
/// staging folder). Ignored, the write fails with EFBIG instead: the set's error path names the
/// file ("File too large"), removes the staging folder and exits 1, leaving the previous files.
fn file_too_large_is_an_error() {
    #[cfg(unix)]
    // SAFETY: at the start of main, before any thread exists; SIG_IGN is a valid disposition.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// glibc gives every image-sized buffer back to the kernel when it is freed (above its mmap
/// threshold, or trimmed off the top of the heap), so each batch frame's readback and encode
/// buffers faulted in fresh zeroed pages: 4-5 ms of a VGA refocus frame's host CPU on llvmpipe,
/// half its readback stage. Fixed thresholds (the largest mmap threshold glibc takes, 32 MiB,
/// and a 512 MiB trim threshold) keep them in the heap for the next frame. Peak memory is
/// unchanged (the batch bounds its frames in flight); it is only not returned between frames.
/// Other allocators have no such switch and lose nothing.
fn keep_freed_images_for_reuse() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: at the start of main, before any thread exists or anything is allocated that
    // depends on the thresholds; both values are in the ranges glibc accepts.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 512 << 20);
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
        Command::Index(a) => index::run::index(&a)?,
        Command::Manifest(a) => manifest::run::manifest(&job(a)?)?,
        Command::Cyclopean(a) => cyclopean::run::cyclopean(&job(*a)?)?,
        Command::Reproject(a) => reproject::run::reproject(&job(*a)?)?,
        Command::Stitch(a) => stitch::run::stitch(&job(*a)?)?,
        Command::Scene(a) => scene::run::scene(&job(a)?)?,
        Command::Compare(a) => return compare::run::compare(&job(*a)?),
        Command::Demo(a) => {
            let verbose = a.verbose;
            demo::run::demo(&job(a)?, verbose)?
        }
        Command::Report(a) => {
            let verbose = a.verbose;
            report::run::report(&job(a)?, verbose)?
        }
        Command::Bench(a) => {
            let json = a.json;
            bench::run::bench(&job(a)?, json)?
        }
        Command::Stress(a) => stress::run::stress(&job(a)?)?,
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    /// `--help` teaches: every option of every command says what it does and sits under a
    /// heading (inputs, intrinsics, targets, ...), and every command shows an example.
    #[test]
    fn every_option_is_described_under_a_heading_and_every_command_has_an_example() {
        let mut cli = Cli::command();
        cli.build();
        let mut options = 0;
        for sub in cli.get_subcommands() {
            let name = sub.get_name();
            if name == "help" {
                continue;
            }
            for arg in sub.get_arguments() {
                let id = arg.get_id().as_str();
                let help = arg
                    .get_long_help()
                    .or(arg.get_help())
                    .map(|h| h.to_string())
                    .unwrap_or_default();
                assert!(!help.trim().is_empty(), "viewsynth {name} --{id} has no description");
                if !["help", "version"].contains(&id) {
                    assert!(
                        arg.get_help_heading().is_some(),
                        "viewsynth {name} --{id} has no heading"
                    );
                    options += 1;
                }
            }
            let after = sub.get_after_long_help().map(|h| h.to_string()).unwrap_or_default();
            assert!(
                after.starts_with("Examples:") && after.contains(&format!("viewsynth {name}")),
                "viewsynth {name} --help shows no example of itself: {after:?}"
            );
        }
        // Guards the walk itself: the commands hold well over a hundred options.
        assert!(options > 150, "only {options} options seen");
    }
}
