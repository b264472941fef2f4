//! Refocus depth outputs beyond EXR/NPY, end to end: 16-bit millimetre PNG, the colour-mapped
//! preview, --depth-trunc on the input, and files named by --focal-list.

use super::cli::{bin, files_in, scratch};
use std::path::{Path, PathBuf};
use std::process::Output;
use viewsynth::io::{self, DepthDecode, DepthMap, RgbImage};

/// Colour and a depth ramp from 1 m (left) to 4.1 m (right).
fn inputs(dir: &Path, w: u32, h: u32) -> (PathBuf, PathBuf) {
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
    let depth: Vec<f32> = (0..w * h).map(|i| 1.0 + 0.1 * (i % w) as f32).collect();
    let (rp, dp) = (dir.join("rgb.png"), dir.join("depth.npy"));
    io::save_rgb(&rp, &RgbImage::new(w, h, rgb).unwrap()).unwrap();
    io::save_depth_npy(&dp, &DepthMap::new(w, h, depth).unwrap()).unwrap();
    (rp, dp)
}

fn refocus(rgb: &Path, depth: &Path, out: &Path, extra: &[&str]) -> Output {
    bin()
        .args([
            "refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5", "--rgb",
        ])
        .arg(rgb)
        .arg("--depth")
        .arg(depth)
        .arg("--out-dir")
        .arg(out)
        .args(extra)
        .output()
        .expect("run viewsynth")
}

fn manifest(out: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap()
}

#[test]
fn png16_depth_matches_the_exr_to_half_a_millimetre() {
    let d = scratch("depthout-png16");
    let (rgb, depth) = inputs(&d, 32, 24);
    let out = d.join("out");
    let o = refocus(
        &rgb,
        &depth,
        &out,
        &["--zoom-range", "1", "--depth-format", "exr,png16"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        files_in(&out),
        [
            "manifest.json",
            "s1_depth.exr",
            "s1_depth.png",
            "s1_mask.png",
            "s1_rgb.png"
        ]
    );
    let exr = io::load_depth(&out.join("s1_depth.exr"), &DepthDecode::default()).unwrap();
    let mm = DepthDecode {
        scale: Some(1000.0),
        ..Default::default()
    };
    let png = io::load_depth(&out.join("s1_depth.png"), &mm).unwrap();
    let valid = exr.data.iter().filter(|z| **z > 0.0).count();
    assert!(valid > exr.data.len() / 2, "{valid}");
    for (a, b) in exr.data.iter().zip(&png.data) {
        assert!((a - b).abs() <= 0.0005 + 1e-6, "{a} vs {b}");
    }
    let m = manifest(&out);
    assert_eq!(m["outputs"][0]["depth_png16"], "s1_depth.png");
    assert_eq!(m["outputs"][0]["depth_png16_clipped"], 0);
    assert!(m["files"]
        .as_array()
        .unwrap()
        .iter()
        .any(|f| f["name"] == "s1_depth.png"));

    let o = refocus(&rgb, &depth, &d.join("bad"), &["--depth-format", "exr,png8"]);
    super::cli::assert_clean_failure(&o, "png16", &d.join("bad"));
}
