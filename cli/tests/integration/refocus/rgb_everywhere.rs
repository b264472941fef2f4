//! `--rgb-everywhere`: colour at every target pixel inside the source frame, mask and depth
//! unchanged.
//!
//! Bounds, from the numerics:
//! - mask and depth: the option only adds a colour write (the full-screen pass, before the
//!   coverage test) or a colour draw at the far depth before the mesh draws (which pass the depth
//!   test over it and write what they wrote before), so both are bit-identical to a render
//!   without it, on every backend and convention.
//! - colour: the same f32 bilinear over the same gathered texels as the covered pixels, whose
//!   bound `refocus_accuracy` derives: within one level of the f64 twin's exact value, with
//!   either neighbour of a rounding tie counted right ([`metrics::quantization_error`]). Which
//!   pixels are inside the frame is decided in f64 by the same span on both sides
//!   ([`viewsynth::refocus::frame_span`]), so outside it both are exactly 0.

use crate::cli::{bin, scratch};
use crate::common::*;
use std::path::Path;
use viewsynth::camera::PinholeCamera;
use viewsynth::convention::Conventions;
use viewsynth::io;
use viewsynth::metrics;
use viewsynth::pass::Device;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::reference::{bilinear_rgb, refocus_reference_with, ReferenceImage};
use viewsynth::refocus::{source_point, BreakRule, Method, OutputSet, RefocusOutput, RefocusSource, Refocuser};

const SCALES: [f64; 3] = [0.5, 1.0, 2.0];

fn targets(src: &RefocusSource) -> Vec<PinholeCamera> {
    TargetSpec {
        scales: SCALES.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&src.camera())
    .unwrap()
}

/// Largest level difference of `out`'s colour from the twin's exact colour, over every pixel.
fn worst_colour(out: &RefocusOutput, twin: &ReferenceImage) -> u32 {
    let c = &out.rgb.as_ref().unwrap().data;
    twin.rgb
        .iter()
        .enumerate()
        .flat_map(|(i, px)| (0..3).map(move |k| (i * 3 + k, px[k])))
        .map(|(o, exact)| metrics::quantization_error(c[o], exact))
        .max()
        .unwrap_or(0)
}

/// On `device`, under every convention and both methods: with the option, mask and depth are
/// bit-identical to the render without it, covered colour too, and every pixel's colour is
/// within one level of the twin's (which is 0 outside the frame).
fn matches_the_twin_on(api: &str, device: &Device) {
    for (name, src) in [("TUM", real_frame("TUM")), ("synthetic", synthetic(160, 120))] {
        let targets = targets(&src);
        let twins: Vec<ReferenceImage> = targets
            .iter()
            .map(|t| refocus_reference_with(&src, &BreakRule::default(), t, true))
            .collect();
        for method in [Method::Fullscreen, Method::Mesh] {
            for conv in Conventions::all() {
                let rule = BreakRule::default();
                let mut plain = Refocuser::new(device, &src, &rule, method, OutputSet::default(), conv).unwrap();
                let mut every = Refocuser::new(device, &src, &rule, method, OutputSet::default(), conv).unwrap();
                every.set_rgb_everywhere(true);
                for ((s, t), twin) in SCALES.iter().zip(&targets).zip(&twins) {
                    let tag = format!("{api} {name} {method:?} {} s{s}", conv.label());
                    let (a, b) = (plain.render(t).unwrap(), every.render(t).unwrap());
                    let (ma, mb) = (&a.mask.as_ref().unwrap().data, &b.mask.as_ref().unwrap().data);
                    assert_eq!(ma, mb, "{tag}: mask changed");
                    let bits = |o: &RefocusOutput| -> Vec<u32> {
                        o.depth.as_ref().unwrap().data.iter().map(|z| z.to_bits()).collect()
                    };
                    assert_eq!(bits(&a), bits(&b), "{tag}: depth changed");
                    let (ca, cb) = (&a.rgb.as_ref().unwrap().data, &b.rgb.as_ref().unwrap().data);
                    let covered_differs =
                        (0..ma.len()).filter(|&i| ma[i] != 0 && ca[3 * i..3 * i + 3] != cb[3 * i..3 * i + 3]);
                    assert_eq!(covered_differs.count(), 0, "{tag}: covered colour changed");
                    let worst = worst_colour(&b, twin);
                    assert!(worst <= 1, "{tag}: colour {worst} levels from the f64 twin");
                    let outside =
                        (0..ma.len()).filter(|&i| twin.rgb[i] == [0.0; 3] && cb[3 * i..3 * i + 3] != [0, 0, 0]);
                    assert_eq!(outside.count(), 0, "{tag}: colour outside the frame");
                }
            }
        }
    }
}

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
