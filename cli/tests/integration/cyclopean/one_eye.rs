//! cyclopean with one eye's disparity (Middlebury 2014 ships the left only): the other eye's map
//! is derived by forward-warping the given one (src/cyclopean/one_eye.rs). On Cones, dropping
//! either map must still give a sensible middle view against the truth im4.

use crate::common::data_dir;
use std::path::{Path, PathBuf};
use viewsynth::io::{self, RgbImage};
use viewsynth::metrics;

/// Runs cyclopean on Cones at --disparity-scale 4 with the maps named; returns the colour, the
/// mask (true = some eye saw the pixel) and stderr.
fn cones_view(maps: &[(&str, &str)], out: &Path) -> (RgbImage, Vec<bool>, String) {
    let dir = data_dir().join("middlebury2003_cones");
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_viewsynth"));
    c.args(["cyclopean", "--disparity-scale", "4", "--outputs", "rgb,mask"])
        .arg("--left-rgb")
        .arg(dir.join("im2.png"))
        .arg("--right-rgb")
        .arg(dir.join("im6.png"))
        .arg("--out-dir")
        .arg(out);
    for (flag, file) in maps {
        c.arg(flag).arg(dir.join(file));
    }
    let o = c.output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{maps:?}: {stderr}");
    let mask = io::load_rgb(&out.join("middle_mask.png")).unwrap();
    let mask = mask.data.chunks(3).map(|p| p[0] > 0).collect();
    (io::load_rgb(&out.join("middle_rgb.png")).unwrap(), mask, stderr)
}

fn psnr(a: &RgbImage, b: &RgbImage, mask: &[bool]) -> f64 {
    let (mut sq, mut n) = (0.0, 0usize);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        n += 1;
        for c in 0..3 {
            let d = f64::from(a.data[i * 3 + c]) - f64::from(b.data[i * 3 + c]);
            sq += d * d;
        }
    }
    metrics::psnr_from_mse(sq / (3 * n) as f64)
}

fn share(mask: &[bool]) -> f64 {
    mask.iter().filter(|m| **m).count() as f64 / mask.len() as f64
}

#[test]
fn one_eyes_disparity_gives_a_view_close_to_both_on_cones() {
    let root: PathBuf = std::env::temp_dir().join(format!("viewsynth-one-eye-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let truth = io::load_rgb(&data_dir().join("middlebury2003_cones/im4.png")).unwrap();
    let (both, both_mask, _) = cones_view(
        &[("--left-disparity", "disp2.pgm"), ("--right-disparity", "disp6.pgm")],
        &root.join("both"),
    );
    let both_db = psnr(&both, &truth, &both_mask);
    for (flag, file, derived) in [
        ("--left-disparity", "disp2.pgm", "right"),
        ("--right-disparity", "disp6.pgm", "left"),
    ] {
        let (one, mask, stderr) = cones_view(&[(flag, file)], &root.join(derived));
        assert!(
            stderr.contains(&format!("note: no --{derived}-disparity")),
            "the derived side is told: {stderr}"
        );
        let common: Vec<bool> = mask.iter().zip(&both_mask).map(|(a, b)| *a && *b).collect();
        let (one_db, both_common_db) = (psnr(&one, &truth, &mask), psnr(&both, &truth, &common));
        let msg = format!(
            "{flag} alone: {:.1} % covered, {one_db:.2} dB on them ({:.2} dB on those both \
             cover; both maps {both_common_db:.2} dB there); both maps: {:.1} % covered, {both_db:.2} dB",
            100.0 * share(&mask),
            psnr(&one, &truth, &common),
            100.0 * share(&both_mask),
        );
        eprintln!("{msg}");
        // What only the derived eye sees is lost (occluded in the given eye), nothing more.
        assert!(share(&mask) > 0.88 && share(&mask) < share(&both_mask), "{msg}");
        // Where it covers, the view is as good as with both maps, within 0.5 dB.
        assert!(one_db > both_db - 0.5, "{msg}");
    }
    let _ = std::fs::remove_dir_all(&root);
}
