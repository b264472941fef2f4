//! The input summary every rendering command prints to stderr before it renders: size, valid
//! depth, min / median / max in metres, and a warning when that looks like a wrong scale or kind.

use super::*;
use viewsynth::io::{DepthMap, DepthSummary};

/// Prints the summary of `depth_m` (view Z in metres, 0 where invalid) read from `path`; `hint`
/// names the options that set the decoding.
pub(crate) fn print_depth_summary(path: &Path, depth_m: &DepthMap, hint: &str) {
    let summary = DepthSummary::of(depth_m);
    eprintln!("input depth {}: {summary}", path.display());
    for w in summary.warnings() {
        eprintln!("warning: {}: {w}; {hint}", path.display());
    }
}
