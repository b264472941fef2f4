//! What the safety tables share: a small input pair, the binary under a time and address-space
//! limit, and the table's failure report.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use viewsynth::io::{self, DepthMap, RgbImage};

pub(crate) const W: u32 = 32;
pub(crate) const H: u32 = 24;

pub(crate) fn inputs(dir: &Path) -> (PathBuf, PathBuf) {
    let rgb: Vec<u8> = (0..W * H * 3).map(|i| (i % 251) as u8).collect();
    let depth: Vec<f32> = (0..W * H).map(|i| 1.0 + 0.01 * (i % W) as f32).collect();
    let (r, d) = (dir.join("rgb.png"), dir.join("depth.npy"));
    io::save_rgb(&r, &RgbImage::new(W, H, rgb).unwrap()).unwrap();
    io::save_depth_npy(&d, &DepthMap::new(W, H, depth).unwrap()).unwrap();
    (r, d)
}

/// The binary with `args` under a 20 s limit and a 1.5 GB address-space limit (a refusal that
/// came after decoding would show as a crash or a timeout, not pass).
pub(crate) fn run(args: &[String]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1500000; exec timeout 20 \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_viewsynth"))
        .args(args)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

pub(crate) fn s(v: &[&str]) -> Vec<String> {
    v.iter().map(|x| x.to_string()).collect()
}

pub(crate) fn p(path: &Path) -> String {
    path.to_str().unwrap().to_string()
}

pub(crate) fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

pub(crate) fn mkfifo(path: &Path) {
    let st = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(st.success());
}
