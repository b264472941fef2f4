//! `viewsynth index` options.

use clap::Args;
use std::path::PathBuf;

/// The example under `viewsynth index --help`.
pub(crate) const EXAMPLES: &str = "\
Examples:
  # two shards wrote index.part-0-of-2.jsonl and index.part-1-of-2.jsonl; join them
  viewsynth index out/shards";

#[derive(Args)]
pub(crate) struct IndexArgs {
    /// A `refocus --batch` output folder holding its runs' index parts.
    #[arg(help_heading = crate::options::INPUTS)]
    pub(crate) out_dir: PathBuf,
}
