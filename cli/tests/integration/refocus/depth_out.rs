//! Refocus depth outputs beyond EXR/NPY, end to end: 16-bit millimetre PNG, the colour-mapped
//! preview, --depth-trunc on the input, and files named by --focal-list.

use crate::cli::{bin, files_in, scratch};
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
    crate::cli::assert_clean_failure(crate::cli::USAGE, &o, "png16", &d.join("bad"));
}

#[test]
fn depth_preview_is_written_with_its_range() {
    let d = scratch("depthout-preview");
    let (rgb, depth) = inputs(&d, 32, 24);
    let out = d.join("out");
    let o = refocus(
        &rgb,
        &depth,
        &out,
        &["--zoom-range", "0.5", "--depth-preview", "--outputs", "depth"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        files_in(&out),
        ["manifest.json", "s0.5_depth.exr", "s0.5_depth_preview.png"]
    );
    let m = manifest(&out);
    let range = &m["outputs"][0]["depth_preview_range_m"];
    let (lo, hi) = (range["min_m"].as_f64().unwrap(), range["max_m"].as_f64().unwrap());
    // The ramp runs 1.0-4.1 m (its steep near end breaks into holes); the 2nd-98th
    // percentile of what is rendered lies inside and is not flat.
    assert!(1.0 <= lo && lo + 1.0 < hi && hi <= 4.11, "{lo} {hi}");
    // At half the focal length the source covers the middle only: a border of holes.
    let z = io::load_depth(&out.join("s0.5_depth.exr"), &DepthDecode::default()).unwrap();
    let img = io::load_rgb(&out.join("s0.5_depth_preview.png")).unwrap();
    let px = |i: usize| &img.data[3 * i..3 * i + 3];
    let (mut near, mut far, mut holes) = (None, None, 0);
    for (i, &zi) in z.data.iter().enumerate() {
        if zi <= 0.0 {
            assert_eq!(px(i), [0, 0, 0], "invalid pixel {i}");
            holes += 1;
        } else if zi < lo as f32 + 0.05 {
            near = Some(i);
        } else if zi > hi as f32 - 0.05 {
            far = Some(i);
        }
    }
    let (near, far) = (near.expect("a near pixel"), far.expect("a far pixel"));
    assert_ne!(px(near), px(far));
    assert_ne!(px(near), [0, 0, 0]);
    assert!(holes > 0 && holes < z.data.len(), "{holes}");

    let bad = d.join("bad");
    let o = refocus(&rgb, &depth, &bad, &["--depth-preview", "--outputs", "rgb"]);
    crate::cli::assert_clean_failure(crate::cli::USAGE, &o, "--depth-preview", &bad);
}

/// Columns of the 32x24 ramp whose depth 1 + 0.1 x lies beyond 2.5 m start at x = 16.
fn assert_far_columns_are_holes(mask_png: &Path) {
    let mask = io::load_mask_png(mask_png).unwrap();
    let at = |x: u32, y: u32| mask.data[(y * mask.width + x) as usize];
    for y in 0..mask.height {
        for x in 17..mask.width {
            assert_eq!(at(x, y), 0, "{}: ({x}, {y}) lies beyond 2.5 m", mask_png.display());
        }
    }
    let kept = (0..mask.height)
        .flat_map(|y| (0..15).map(move |x| (x, y)))
        .filter(|&(x, y)| at(x, y) == 1);
    assert!(kept.count() > 0, "{}: nearer pixels stay", mask_png.display());
}

#[test]
fn depth_trunc_makes_far_input_holes_single_frame_and_batch() {
    let d = scratch("depthout-trunc");
    let (rgb, depth) = inputs(&d, 32, 24);
    let out = d.join("out");
    let plain = d.join("plain");
    let o = refocus(&rgb, &depth, &plain, &["--zoom-range", "1", "--outputs", "mask"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m = io::load_mask_png(&plain.join("s1_mask.png")).unwrap();
    assert!(
        m.data[(10 * 32 + 20) as usize] == 1,
        "without the option the far side renders"
    );

    let o = refocus(
        &rgb,
        &depth,
        &out,
        &["--zoom-range", "1", "--outputs", "mask,depth", "--depth-trunc", "2.5"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_far_columns_are_holes(&out.join("s1_mask.png"));
    let z = io::load_depth(&out.join("s1_depth.exr"), &DepthDecode::default()).unwrap();
    assert!(
        z.data.iter().all(|&v| v <= 2.5),
        "no output depth beyond the truncation"
    );

    let csv = d.join("frames.csv");
    std::fs::write(
        &csv,
        "rgb,depth,fx,fy,cx,cy,name\nrgb.png,depth.npy,40,40,15.5,11.5,a\n",
    )
    .unwrap();
    let batch_out = d.join("batch");
    let o = bin()
        .args([
            "refocus",
            "--zoom-range",
            "1",
            "--outputs",
            "mask",
            "--depth-trunc",
            "2.5",
            "--batch",
        ])
        .arg(&csv)
        .arg("--out-dir")
        .arg(&batch_out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_far_columns_are_holes(&batch_out.join("a/s1_mask.png"));
    assert_eq!(manifest(&batch_out.join("a"))["settings"]["depth_trunc"], 2.5);

    for bad in ["0", "-1", "inf"] {
        let o = refocus(&rgb, &depth, &d.join("bad"), &["--depth-trunc", bad]);
        crate::cli::assert_clean_failure(crate::cli::USAGE, &o, "depth-trunc", &d.join("bad"));
    }
}

#[test]
fn focal_list_names_files_by_the_focal_given() {
    let d = scratch("depthout-focal");
    let (rgb, depth) = inputs(&d, 32, 24);
    let out = d.join("out");
    let o = refocus(
        &rgb,
        &depth,
        &out,
        &["--focal-list", "20,57.5", "--outputs", "rgb,mask"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        files_in(&out),
        [
            "f20_mask.png",
            "f20_rgb.png",
            "f57.5_mask.png",
            "f57.5_rgb.png",
            "manifest.json"
        ]
    );
    let m = manifest(&out);
    assert_eq!(m["outputs"][1]["rgb"], "f57.5_rgb.png");
    assert_eq!(m["outputs"][1]["intrinsics"]["fx"], 57.5);

    let bad = d.join("bad");
    let o = refocus(&rgb, &depth, &bad, &["--focal-list", "30,57.5,57.50000001"]);
    crate::cli::assert_clean_failure(crate::cli::USAGE, &o, "f57.5", &bad);
}
