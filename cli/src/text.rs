//! Small text helpers shared by the commands' closing messages.

use std::path::PathBuf;
use viewsynth::pass::Timing;

/// The file names of written outputs, comma-separated.
pub(crate) fn file_names(paths: &[PathBuf]) -> String {
    let names: Vec<String> = paths
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    names.join(", ")
}

/// "12.3 ms wall, 4.5 ms GPU" (the GPU time where timer queries mean something).
pub(crate) fn ms_text(t: &Timing) -> String {
    match t.gpu_ms {
        Some(g) => format!("{:.1} ms wall, {g:.1} ms GPU", t.wall_ms),
        None => format!("{:.1} ms wall", t.wall_ms),
    }
}
