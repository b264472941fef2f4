//! Options shared by several commands (each flattened into a command's arguments).

mod backend;
mod conventions;
mod files;
mod gpu;
mod intrinsics;

pub(crate) use backend::BackendArg;
pub(crate) use conventions::{conventions, ConventionArgs, NdcArg, RowsArg};
pub(crate) use files::{parse_outputs, FileOutputArgs};
pub(crate) use gpu::GpuArgs;
pub(crate) use intrinsics::IntrinsicsArgs;

// The `--help` headings, in the order a user fills a command line in (clap lists each heading
// where its first option appears). Options without one (--help, --max-pixels) come under
// "Options".
pub(crate) const INPUTS: &str = "Inputs";
pub(crate) const INTRINSICS: &str = "Intrinsics";
pub(crate) const TARGETS: &str = "Targets";
pub(crate) const METHOD: &str = "Method";
pub(crate) const BATCH: &str = "Batch";
pub(crate) const OUTPUTS: &str = "Outputs";
pub(crate) const THRESHOLDS: &str = "Thresholds";
pub(crate) const MEASURE: &str = "Measurement";
pub(crate) const CONVENTIONS: &str = "Conventions";
pub(crate) const GPU: &str = "GPU";
