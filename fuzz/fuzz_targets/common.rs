// Shared by the targets: the loaders take paths, so each input is written to a per-process
// scratch file with the extension that selects the format.
use std::path::PathBuf;

pub fn scratch(ext: &str, data: &[u8]) -> PathBuf {
    let p = std::env::temp_dir().join(format!("viewsynth-fuzz-{}.{ext}", std::process::id()));
    std::fs::write(&p, data).expect("scratch file");
    p
}
