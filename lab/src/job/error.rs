//! The lab's own refusals and failures, beside the library's ([`viewsynth::job::ArgError`],
//! [`viewsynth::job::JobError`]), which they carry unchanged. Each message names the option at
//! fault, worded as the command line gives it.

use std::path::PathBuf;

/// Lab options that do not make a valid job: refused before any work.
#[derive(Debug, thiserror::Error)]
pub enum ArgError {
    /// A library rule refused a value (`--device`, `--jobs`, sizes, ...).
    #[error(transparent)]
    Job(#[from] viewsynth::job::ArgError),
    /// `bench --batch 0`.
    #[error("--batch 0: give a number of frames >= 1 or a manifest file")]
    NoBenchFrames,
    /// `bench --batch N` beyond what the built-in scene is rendered for.
    #[error("--batch {0}: at most 100000 frames of the built-in scene")]
    TooManyBenchFrames(usize),
    /// A `bench --sizes` entry without the `x`.
    #[error("--sizes '{0}': expected WxH with W, H >= 1")]
    BenchSize(String),
    /// A `bench --sizes` side that is no number.
    #[error("--sizes: a side is no whole number")]
    BenchSide(#[from] std::num::ParseIntError),
    /// `stress --only` names no capability.
    #[error("--only '{given}': expected a list of {known}")]
    StressCapability {
        /// The unknown name.
        given: String,
        /// The names known, comma-separated.
        known: String,
    },
    /// `stress --only` given but naming nothing.
    #[error("--only '{0}': names no capability (omit --only to sweep them all)")]
    StressNothing(String),
    /// `report --data-dir` is no folder.
    #[error("--data-dir {}: not a directory", .0.display())]
    DataDirMissing(PathBuf),
}

impl ArgError {
    /// Whether the command line itself is at fault (exit 2): every lab refusal, and the
    /// library's as [`viewsynth::job::ArgError::is_usage`] says.
    pub fn is_usage(&self) -> bool {
        match self {
            ArgError::Job(e) => e.is_usage(),
            _ => true,
        }
    }
}

impl From<viewsynth::Error> for ArgError {
    fn from(e: viewsynth::Error) -> Self {
        ArgError::Job(e.into())
    }
}

/// A lab job that failed while running.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The library failed, or one of its jobs did.
    #[error(transparent)]
    Job(#[from] viewsynth::job::JobError),
    /// A lab option checked against the file system while running.
    #[error(transparent)]
    Arg(#[from] ArgError),
    /// A stress case exceeded its bound.
    #[error("stress case failed: {capability} / {case} ({worst})")]
    StressFailed {
        /// Capability of the first failing row.
        capability: String,
        /// Its case.
        case: String,
        /// Its worst error against the bound.
        worst: String,
    },
}

impl From<viewsynth::Error> for JobError {
    fn from(e: viewsynth::Error) -> Self {
        JobError::Job(e.into())
    }
}

impl From<viewsynth::job::ArgError> for JobError {
    fn from(e: viewsynth::job::ArgError) -> Self {
        JobError::Job(e.into())
    }
}

#[cfg(test)]
mod tests {
    use super::ArgError;

    #[test]
    fn lab_refusals_are_usage_errors_and_a_file_the_library_read_is_not() {
        assert!(ArgError::NoBenchFrames.is_usage());
        assert!(ArgError::StressNothing(",".into()).is_usage());
        let param: ArgError = viewsynth::Error::param("--sizes", "too large").into();
        assert!(param.is_usage());
        let read: ArgError = viewsynth::Error::decode("frames.csv", "no header").into();
        assert!(!read.is_usage(), "{read}");
        // The library's refusal reads as it did before the lab wrapped it.
        assert_eq!(param.to_string(), "invalid --sizes: too large");
    }
}
