//! `refocus --rgb-everywhere` on a real frame: the source colour kept, no black holes inside the
//! frame (the pass against its twin, bounds derived, is `viewsynth_tests`' `refocus::rgb_everywhere`).

use crate::cli::{bin, scratch};
use crate::common::*;
use std::path::Path;
use viewsynth::io;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::reference::bilinear_rgb;
use viewsynth::refocus::source_point;

fn refocus_tum(out: &Path, extra: &[&str]) {
    let d = data_dir().join("rgbd_open3d_testdata");
    let o = bin()
        .args(["refocus", "--rgb"])
        .arg(d.join("TUM_color.png"))
        .arg("--depth")
        .arg(d.join("TUM_depth.png"))
        .args([
            "--depth-scale",
            "5000",
            "--fx",
            "525",
            "--fy",
            "525",
            "--cx",
            "319.5",
            "--cy",
            "239.5",
        ])
        .args(["--zoom-range", "1,2", "--out-dir"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The must-show, through the command line on the quick start's TUM frame: at s = 1 the
/// colour is the source's (within one level) on >= 99.9 % of pixels; at s = 2 no pixel inside
/// the frame is black where the source around its point is not; masks and depth files are byte
/// for byte those of the run without the option.
#[test]
fn tum_with_rgb_everywhere_keeps_the_source_colour_and_has_no_black_holes() {
    let dir = scratch("rgb-everywhere-tum");
    let (plain, every) = (dir.join("plain"), dir.join("every"));
    refocus_tum(&plain, &[]);
    refocus_tum(&every, &["--rgb-everywhere"]);
    for f in ["s1_mask.png", "s2_mask.png", "s1_depth.exr", "s2_depth.exr"] {
        let (a, b) = (
            std::fs::read(plain.join(f)).unwrap(),
            std::fs::read(every.join(f)).unwrap(),
        );
        assert!(a == b, "{f} differs with --rgb-everywhere");
    }
    let manifest = std::fs::read_to_string(every.join("manifest.json")).unwrap();
    assert!(manifest.contains("\"rgb_everywhere\": true"), "{manifest}");

    let src = io::load_rgb(&data_dir().join("rgbd_open3d_testdata/TUM_color.png")).unwrap();
    let within_one = |out: &Path| {
        let o = io::load_rgb(&out.join("s1_rgb.png")).unwrap();
        let good = (0..o.data.len() / 3)
            .filter(|&i| (0..3).all(|c| (o.data[3 * i + c] as i32 - src.data[3 * i + c] as i32).abs() <= 1))
            .count();
        good as f64 / (o.data.len() / 3) as f64
    };
    let (before, after) = (within_one(&plain), within_one(&every));
    eprintln!(
        "TUM s = 1: source colour within 1 level on {:.2} % of pixels without the option, {:.3} % with it",
        before * 100.0,
        after * 100.0
    );
    assert!(after >= 0.999, "s = 1: only {:.3} % within one level", after * 100.0);

    // s = 2: a black pixel whose source point's bilinear colour is at least one level is a hole.
    let frame = real_frame("TUM");
    let holes = |out: &Path| {
        let o = io::load_rgb(&out.join("s2_rgb.png")).unwrap();
        let target = &TargetSpec {
            scales: vec![2.0],
            size: None,
            principal: None,
        }
        .targets(&frame.camera())
        .unwrap()[0];
        let mut n = 0;
        for y in 0..o.height {
            for x in 0..o.width {
                let i = 3 * (y * o.width + x) as usize;
                if o.data[i..i + 3] == [0, 0, 0] {
                    let [u, v] = source_point(&frame.k, &target.k, x as f64, y as f64);
                    n += bilinear_rgb(&frame, u, v).iter().any(|c| *c >= 1.0) as usize;
                }
            }
        }
        n as f64 / (o.width * o.height) as f64
    };
    let (before, after) = (holes(&plain), holes(&every));
    eprintln!(
        "TUM s = 2: black where the source is not on {:.2} % of pixels without the option, {:.4} % with it",
        before * 100.0,
        after * 100.0
    );
    assert_eq!(after, 0.0, "s = 2: black pixels inside the frame");
}
