//! The command line's test helpers: the library tests' shared helpers (`viewsynth_tests`), and
//! `viewsynth cyclopean` on the files they write.

pub use viewsynth_tests::*;

/// `viewsynth cyclopean` on the files [`write_cyclopean_files`] wrote in `dir`, with the camera
/// file `cameras` (in `dir`), the options `extra`, into `out`.
pub fn cyclopean_cli(
    dir: &std::path::Path,
    cameras: &str,
    extra: &[&str],
    out: &std::path::Path,
) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_viewsynth"))
        .arg("cyclopean")
        .args(extra)
        .arg("--left-rgb")
        .arg(dir.join("left.png"))
        .arg("--left-depth")
        .arg(dir.join("left.exr"))
        .arg("--right-rgb")
        .arg(dir.join("right.png"))
        .arg("--right-depth")
        .arg(dir.join("right.exr"))
        .arg("--cameras")
        .arg(dir.join(cameras))
        .arg("--out-dir")
        .arg(out)
        .output()
        .unwrap()
}
