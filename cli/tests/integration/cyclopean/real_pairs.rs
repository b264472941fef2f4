//! The splat-gather middle view on real stereo (Middlebury 2003 Cones), on thin structures, and
//! against its f64 twin; the rectified-stereo CLI.
//!
//! GPU vs twin tolerance, from the numerics: the GPU computes positions in f32, the twin in f64.
//! A pixel's answer can only differ where a decision sits within f32 reach of its threshold: a
//! splat near a pixel border that may change a neighbourhood's nearest distance, a middle ray
//! near the half-texel that decides the nearest eye texel, or two disparities near the
//! same-surface tolerance. `splat_reference::ambiguity` marks those pixels from the twin's own
//! geometry (bounds derived in src/cyclopean/ambiguity.rs); only they are excused. Every other
//! pixel must carry the twin's source bits, its colour within one level (the same weighted sum of
//! the same texels; rounding of a value near a half level) and its middle depth within 2e-5
//! relative (the f32 error of the chain, ~1e-6; as for the gather method). So one pixel 40 levels
//! off fails. The marked share is bounded per case (see `splat_gather_twin`).

use crate::common::{data_dir, gpu};
use std::path::{Path, PathBuf};
use viewsynth::camera::{gl_projection, Intrinsics, PinholeCamera};
use viewsynth::convention::Conventions;
use viewsynth::convention::DepthPlanes;
use viewsynth::cyclopean::baseline::{forward_splat, forward_splat_offset, forward_splat_rounded, Rounding};
use viewsynth::cyclopean::disparity_frame::{disparity_frame, median_fixation, DisparityRig};
use viewsynth::cyclopean::reference::CyclopeanReference;
use viewsynth::cyclopean::render::CyclopeanRenderer;
use viewsynth::cyclopean::scene_frame::{scene_frame, StereoRig};
use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
use viewsynth::cyclopean::splat_reference::{self, splat_reference};
use viewsynth::cyclopean::{CyclopeanOutput, CyclopeanOutputs, CyclopeanParams, FrameDepth, Method, StereoFrame};
use viewsynth::io::{self, DepthDecode, DepthMap, RgbImage};
use viewsynth::metrics;
use viewsynth_lab::eval::cyclopean::{estimated_cases, estimated_eyes};

fn splat_gpu(frame: &StereoFrame, mid: &viewsynth::cyclopean::MiddleCamera) -> CyclopeanOutput {
    splat_on(&viewsynth::pass::Device::gl(&gpu()).unwrap(), frame, mid)
}

fn splat_on(
    device: &viewsynth::pass::Device,
    frame: &StereoFrame,
    mid: &viewsynth::cyclopean::MiddleCamera,
) -> CyclopeanOutput {
    SplatRenderer::new(device, frame, SplatParams::default(), CyclopeanOutputs::default())
        .unwrap()
        .render(mid)
        .unwrap()
        .0
}

fn gather_gpu(
    frame: &StereoFrame,
    mid: &viewsynth::cyclopean::MiddleCamera,
    params: CyclopeanParams,
) -> CyclopeanOutput {
    CyclopeanRenderer::new(&gpu(), frame, params)
        .unwrap()
        .render(mid)
        .unwrap()
        .0
}

fn out_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("viewsynth-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Among the pixels the twin does not mark `ambiguous`: those whose source bits differ; those
/// (same bits) whose colour differs by more than one level; those (same bits) whose depth
/// differs by more than 2e-5 relative.
fn compare(out: &CyclopeanOutput, r: &CyclopeanReference, ambiguous: &[bool]) -> (Vec<usize>, usize, usize) {
    let (mut src, mut col, mut z) = (Vec::new(), 0, 0);
    let color = out.color().unwrap();
    let depth = out.depth().unwrap();
    for i in (0..r.depth.len()).filter(|&i| !ambiguous[i]) {
        if out.sources[i] != r.sources[i] {
            src.push(i);
            continue;
        }
        let e = (0..3)
            .map(|c| metrics::quantization_error(color.data[i * 3 + c], r.color[i][c]))
            .max()
            .unwrap();
        col += (e > 1) as usize;
        if r.sources[i] != 0 {
            z += ((depth.data[i] as f64 - r.depth[i]).abs() > 2e-5 * r.depth[i]) as usize;
        }
    }
    (src, col, z)
}

/// Write the GPU image, the twin's and their difference (x8) for a failed comparison.
fn dump(tag: &str, out: &CyclopeanOutput, r: &CyclopeanReference, w: u32, h: u32) -> String {
    let dir = out_dir(&format!("splat-twin-{tag}"));
    let twin = r.to_output(w, h);
    let (g, t) = (out.color().unwrap(), twin.color().unwrap());
    let diff: Vec<u8> = g
        .data
        .iter()
        .zip(&t.data)
        .map(|(a, b)| (a.abs_diff(*b) as u32 * 8).min(255) as u8)
        .collect();
    io::save_rgb(&dir.join("gpu.png"), g).unwrap();
    io::save_rgb(&dir.join("twin.png"), t).unwrap();
    io::save_rgb(&dir.join("diff_x8.png"), &RgbImage::new(w, h, diff).unwrap()).unwrap();
    dir.display().to_string()
}

/// No pixel outside those the twin marks ambiguous may differ (in source bits, colour beyond one
/// level or depth beyond 2e-5 relative), and at most `max_ambiguous` of the pixels are marked.
fn check_twin(
    device: &viewsynth::pass::Device,
    tag: &str,
    frame: &StereoFrame,
    mid: &viewsynth::cyclopean::MiddleCamera,
    max_ambiguous: f64,
) {
    let out = splat_on(device, frame, mid);
    let r = splat_reference(frame, mid, &SplatParams::default()).unwrap();
    let ambiguous = splat_reference::ambiguity(frame, mid, &SplatParams::default()).unwrap();
    let (src, col, z) = compare(&out, &r, &ambiguous);
    let n = r.depth.len();
    let marked = ambiguous.iter().filter(|a| **a).count();
    let w = mid.width as usize;
    // How many of the marked pixels this device answers otherwise (told, not asserted: another
    // driver may round the other way).
    let unmarked: Vec<bool> = ambiguous.iter().map(|a| !a).collect();
    let (m_src, m_col, m_z) = compare(&out, &r, &unmarked);
    let msg = format!(
        "{tag}: of {n} pixels, {marked} ({:.2} %) ambiguous (of them, on this device, {} differ in source bits, {m_col} in colour, {m_z} in depth); of the others {} differ in source bits (first {:?}), {col} in colour, {z} in depth",
        marked as f64 * 100.0 / n as f64,
        m_src.len(),
        src.len(),
        src.first().map(|i| (i % w, i / w))
    );
    if !src.is_empty() || col + z > 0 || marked as f64 > max_ambiguous * n as f64 {
        let dir = dump(tag, &out, &r, mid.width, mid.height);
        panic!("{msg}; images in {dir}");
    }
    eprintln!("{msg}");
}

/// The share of Cones the twin may mark ambiguous. Its disparities are quarter pixels (d = k/4)
/// and the middle view sits halfway, so each eye's texels move by k/8 px: for k = 4 mod 8 (one
/// disparity value in eight) a texel centre lands exactly on a pixel border, and a middle ray's
/// nearest eye texel exactly on a texel border, for whole surfaces at once; f32 may land either
/// side there. One eye in eight, either of two eyes: 1 - (7/8)^2 = 23 % of the pixels, against
/// 22.22 % marked (measured when written; 23.97 % before nearest-texel choices were tested for
/// their effect, see `splat_reference::ambiguity`). The marks are not too broad: on llvmpipe and
/// lavapipe alike 1499 of the marked pixels take other source bits, 132 another colour and 500
/// another depth (each printed by the test), none outside them; which of them go which way is
/// the driver's rounding, so only their share is bounded: 30 %. Every other pixel must match.
/// On the built-in scene (generic geometry) 0.01 % (one pixel) was marked when written (none
/// now); the bound there is 0.5 %.
const CONES_MAX_AMBIGUOUS: f64 = 0.30;

fn splat_gather_twin(device: &viewsynth::pass::Device) {
    eprintln!("splat-gather twin check on {:?}", device.api());
    let mut rig = StereoRig::demo(160, 120);
    rig.ipd = 0.2;
    for conv in Conventions::all() {
        for kind in [FrameDepth::Device, FrameDepth::ViewZ] {
            let (frame, mid, _) = scene_frame(&rig, conv, kind);
            check_twin(device, &format!("scene-{}-{kind:?}", conv.label()), &frame, &mid, 0.005);
        }
    }
    let (l, r, _) = cones();
    let (frame, mid) = disparity_frame(l, r, &DisparityRig::middle(400.0, 0.1), Conventions::default()).unwrap();
    check_twin(device, "cones", &frame, &mid, CONES_MAX_AMBIGUOUS);
}

type Eye = (RgbImage, DepthMap);

fn cones() -> (Eye, Eye, RgbImage) {
    let dir = data_dir().join("middlebury2003_cones");
    let dec = DepthDecode {
        scale: Some(4.0),
        ..Default::default()
    };
    let eye = |im: &str, disp: &str| {
        (
            io::load_rgb(&dir.join(im)).unwrap(),
            io::load_depth(&dir.join(disp), &dec).unwrap(),
        )
    };
    (
        eye("im2.png", "disp2.pgm"),
        eye("im6.png", "disp6.pgm"),
        io::load_rgb(&dir.join("im4.png")).unwrap(),
    )
}

fn psnr(a: &RgbImage, b: &RgbImage, mask: &[bool]) -> f64 {
    let (mut sq, mut n) = (0.0, 0usize);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        n += 1;
        for c in 0..3 {
            let d = a.data[i * 3 + c] as f64 - b.data[i * 3 + c] as f64;
            sq += d * d;
        }
    }
    metrics::psnr_from_mse(sq / (3 * n) as f64)
}

fn count(mask: &[bool]) -> usize {
    mask.iter().filter(|m| **m).count()
}

/// A far textured wall (disparity 4 px) behind poles 1, 2 and 3 px wide (disparity 20.6 px: the
/// middle view shifts them by 10.3 px, off the pixel grid), rendered exactly into both eyes.
fn poles_frame() -> (Eye, Eye, Vec<(usize, usize)>) {
    let (w, h) = (96usize, 24usize);
    let (d_wall, d_pole) = (4.0f32, 20.6f32);
    let poles = [(30usize, 1usize), (50, 2), (70, 3)]; // left-image x and width
    let wall = |x: f64| -> [u8; 3] {
        // Texture in wall coordinates (left-image x).
        let k = (x.floor() as i64).rem_euclid(7) as u8;
        [200, 40 + 20 * k, 30]
    };
    const POLE: [u8; 3] = [20, 30, 230];
    let render = |right: bool| -> Eye {
        let mut rgb = vec![0u8; w * h * 3];
        let mut disp = vec![0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                // The pole texels: in the left image x0..x0+width; in the right shifted by -d_pole.
                let xl_pole = if right { x as f64 + d_pole as f64 } else { x as f64 };
                let on_pole = poles
                    .iter()
                    .any(|&(x0, pw)| xl_pole >= x0 as f64 - 1e-9 && xl_pole < (x0 + pw) as f64 - 1e-9);
                let (c, d) = if on_pole {
                    (POLE, d_pole)
                } else {
                    (wall(if right { x as f64 + d_wall as f64 } else { x as f64 }), d_wall)
                };
                rgb[(y * w + x) * 3..(y * w + x) * 3 + 3].copy_from_slice(&c);
                disp[y * w + x] = d;
            }
        }
        (
            RgbImage::new(w as u32, h as u32, rgb).unwrap(),
            DepthMap::new(w as u32, h as u32, disp).unwrap(),
        )
    };
    (render(false), render(true), poles.to_vec())
}

fn viewsynth(args: &[&str], paths: &[(&str, &Path)]) -> std::process::Output {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_viewsynth"));
    c.arg("cyclopean").args(args);
    for (flag, p) in paths {
        c.arg(flag).arg(p);
    }
    c.output().unwrap()
}

#[test]
fn cli_rectified_pair_matches_the_library_and_refuses_bad_input_cleanly() {
    let dir = data_dir().join("middlebury2003_cones");
    let out = out_dir("cyclopean-stereo-cli");
    let inputs = [
        ("--left-rgb", dir.join("im2.png")),
        ("--right-rgb", dir.join("im6.png")),
        ("--left-disparity", dir.join("disp2.pgm")),
        ("--right-disparity", dir.join("disp6.pgm")),
    ];
    let mut paths: Vec<(&str, &Path)> = inputs.iter().map(|(f, p)| (*f, p.as_path())).collect();
    let good = out.join("good");
    paths.push(("--out-dir", &good));
    let o = viewsynth(
        &["--disparity-scale", "4", "--focal", "400", "--baseline", "0.1"],
        &paths,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (l, r, _) = cones();
    let (frame, mid) = disparity_frame(l, r, &DisparityRig::middle(400.0, 0.1), Conventions::default()).unwrap();
    let lib = splat_gpu(&frame, &mid);
    assert_eq!(
        io::load_rgb(&good.join("middle_rgb.png")).unwrap(),
        *lib.color().unwrap()
    );
    let z = io::load_depth(&good.join("middle_depth.exr"), &Default::default()).unwrap();
    assert_eq!(z, *lib.depth().unwrap(), "metric depth f B / d");
    assert!(good.join("middle_mask.png").is_file());

    // No focal/baseline: colour and mask only; --position 0 is the left eye itself.
    let left = out.join("left");
    paths.pop();
    paths.push(("--out-dir", &left));
    let o = viewsynth(&["--disparity-scale", "4", "--position", "0"], &paths);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(crate::cli::files_in(&left), ["middle_mask.png", "middle_rgb.png"]);
    let im2 = io::load_rgb(&dir.join("im2.png")).unwrap();
    let mask = io::load_mask_png(&left.join("middle_mask.png")).unwrap();
    let rgb = io::load_rgb(&left.join("middle_rgb.png")).unwrap();
    // Where the left disparity is known the view is the left image itself (the right eye's
    // weight is 0 at the left eye); elsewhere the right eye fills in.
    let disp2 = io::load_depth(
        &dir.join("disp2.pgm"),
        &DepthDecode {
            scale: Some(4.0),
            ..Default::default()
        },
    )
    .unwrap();
    let known: Vec<usize> = (0..disp2.data.len())
        .filter(|&i| disp2.data[i] > 0.0 && mask.data[i] != 0)
        .collect();
    let exact = known
        .iter()
        .filter(|&&i| rgb.data[i * 3..i * 3 + 3] == im2.data[i * 3..i * 3 + 3])
        .count();
    assert!(
        exact as f64 >= 0.99 * known.len() as f64,
        "position 0 reproduces the left eye on {exact} of {} pixels",
        known.len()
    );

    // Bad input: a clear message naming the flag (usage, exit 2) or file (run error, exit 1),
    // nothing written.
    for (args, extra, needle, code) in [
        (vec!["--outputs", "rgb,depth"], None, "--focal", 2),
        (vec!["--position", "1.5"], None, "position", 2),
        (vec!["--method", "forward", "--blend", "soft"], None, "--blend", 2),
        (
            vec![],
            Some(("--right-disparity", dir.join("missing.pgm"))),
            "missing.pgm",
            1,
        ),
    ] {
        let bad = out.join("bad");
        let mut p: Vec<(&str, &Path)> = inputs
            .iter()
            .filter(|(f, _)| extra.as_ref().is_none_or(|(e, _)| e != f))
            .map(|(f, p)| (*f, p.as_path()))
            .collect();
        if let Some((f, path)) = &extra {
            p.push((f, path.as_path()));
        }
        p.push(("--out-dir", &bad));
        let mut a = vec!["--disparity-scale", "4"];
        a.extend(args);
        let o = viewsynth(&a, &p);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{a:?}: {err}");
        assert!(err.contains(needle) && !err.contains("panicked"), "{a:?}: {err}");
        assert!(!bad.exists(), "{a:?}: nothing written");
    }
}

/// On one estimated-disparity case, the default against a forward-splat baseline on the pixels
/// both cover: (default dB, baseline dB) there, and (default, baseline) covered pixel counts.
struct Versus {
    db: (f64, f64),
    covered: (usize, usize),
}

/// The default against both forward splats (round half away from zero, then numpy's half to
/// even) on the case whose scene name starts with `scene_prefix`.
fn estimated_versus_splats(scene_prefix: &str) -> [Versus; 2] {
    let (cases, skipped) = estimated_cases(&data_dir()).unwrap();
    let case = cases
        .iter()
        .find(|c| c.scene.starts_with(scene_prefix))
        .unwrap_or_else(|| panic!("{scene_prefix}: not in the data folder ({skipped:?})"));
    let (l, r, rig) = estimated_eyes(case).unwrap();
    let bases = [Rounding::HalfAway, Rounding::HalfEven]
        .map(|rounding| forward_splat_rounded((&l.0, &l.1), (&r.0, &r.1), rig.position, [0.0, 0.0], rounding).unwrap());
    let (frame, mid) = disparity_frame(l, r, &rig, Conventions::default()).unwrap();
    let out = splat_gpu(&frame, &mid);
    let covered: Vec<bool> = out.sources.iter().map(|s| *s != 0).collect();
    bases.map(|base| {
        let common: Vec<bool> = covered.iter().zip(&base.covered).map(|(a, b)| *a && *b).collect();
        let v = Versus {
            db: (
                psnr(out.color().unwrap(), &case.truth, &common),
                psnr(&base.color, &case.truth, &common),
            ),
            covered: (count(&covered), count(&base.covered)),
        };
        eprintln!(
            "{}, {}: splat-gather {:.3} dB vs splat baseline {:.3} dB ({:+.3}) on {} common pixels; covered {:.2} % vs {:.2} %",
            case.scene,
            case.setting,
            v.db.0,
            v.db.1,
            v.db.0 - v.db.1,
            count(&common),
            100.0 * v.covered.0 as f64 / covered.len() as f64,
            100.0 * v.covered.1 as f64 / covered.len() as f64,
        );
        v
    })
}

/// Two images alone: the CLI estimates the disparities with the census matcher (its GPU pass)
/// and renders as if they had been given. Oracle: the matcher's twin's disparities (the GPU
/// pass is bit-exact with it, cli/tests/integration/matcher.rs) written to files and given
/// with --left-disparity/--right-disparity must give the same files, byte for byte. Options
/// that decode disparity files, and a search range with disparities given, are usage errors.
#[test]
fn cli_two_images_alone_render_the_matchers_disparities() {
    let dir = data_dir().join("middlebury2003_cones");
    let out = out_dir("cyclopean-two-images");
    let (l, r) = (dir.join("im2.png"), dir.join("im6.png"));
    let (dl, dr) =
        viewsynth::cyclopean::matcher::estimate_disparities(&io::load_rgb(&l).unwrap(), &io::load_rgb(&r).unwrap(), 64)
            .unwrap();
    let (dl_file, dr_file) = (out.join("dl.npy"), out.join("dr.npy"));
    io::save_depth_npy(&dl_file, &dl).unwrap();
    io::save_depth_npy(&dr_file, &dr).unwrap();
    let (alone, given) = (out.join("alone"), out.join("given"));
    // With --confidence: the view must not change (compared with the given disparities below).
    let o = viewsynth(
        &["--max-disparity", "64", "--confidence"],
        &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &alone)],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Each eye's confidence file holds the matcher's confidence stage: its twin on the twin's
    // disparities, within the stage's GPU-vs-twin bound (CONFIDENCE_BOUND, derived beside it in
    // cli/tests/integration/matcher.rs), and exactly 0 where the disparity is unknown.
    let twin = viewsynth::cyclopean::matcher::confidence_reference(&dl, &dr).unwrap();
    for (name, want, d) in [
        ("left_confidence.exr", &twin.0, &dl),
        ("right_confidence.exr", &twin.1, &dr),
    ] {
        let got = io::load_depth(&alone.join(name), &io::DepthDecode::default()).unwrap();
        assert_eq!((got.width, got.height), (want.width, want.height), "{name}");
        let worst = crate::common::max_abs_difference(&got.data, &want.data);
        viewsynth_lab::eval::image_check::ensure(
            worst <= viewsynth_tests::CONFIDENCE_BOUND,
            &format!("cli confidence {name}"),
            want.width,
            want.height,
            &[(
                "confidence",
                viewsynth_lab::eval::image_check::Plane::Depth(&got.data),
                viewsynth_lab::eval::image_check::Plane::Depth(&want.data),
            )],
            format!("{name}: off the twin by up to {worst:e}"),
        );
        let unknown_nonzero = got
            .data
            .iter()
            .zip(&d.data)
            .filter(|(c, d)| **d <= 0.0 && **c != 0.0)
            .count();
        assert_eq!(unknown_nonzero, 0, "{name}: confidence where the disparity is unknown");
        assert!(
            got.data.iter().all(|c| (0.0..=1.0).contains(c)),
            "{name}: outside [0, 1]"
        );
        assert!(got.data.iter().any(|c| *c > 0.5), "{name}: no confident pixel");
    }
    let o = viewsynth(
        &[],
        &[
            ("--left-rgb", &l),
            ("--right-rgb", &r),
            ("--left-disparity", &dl_file),
            ("--right-disparity", &dr_file),
            ("--out-dir", &given),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for name in ["middle_rgb.png", "middle_mask.png"] {
        let (a, b) = (
            std::fs::read(alone.join(name)).unwrap(),
            std::fs::read(given.join(name)).unwrap(),
        );
        assert!(
            a == b,
            "{name}: two images alone differ from the matcher's disparities given as files"
        );
    }
    let usage = |args: &[&str], paths: &[(&str, &Path)]| {
        let o = viewsynth(args, paths);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let bad = out.join("bad");
    let e = usage(
        &["--max-disparity", "64"],
        &[
            ("--left-rgb", &l),
            ("--right-rgb", &r),
            ("--left-disparity", &dl_file),
            ("--right-disparity", &dr_file),
            ("--out-dir", &bad),
        ],
    );
    assert!(e.contains("--max-disparity applies to two images alone"), "{e}");
    let e = usage(
        &["--confidence"],
        &[
            ("--left-rgb", &l),
            ("--right-rgb", &r),
            ("--left-disparity", &dl_file),
            ("--right-disparity", &dr_file),
            ("--out-dir", &bad),
        ],
    );
    assert!(e.contains("--confidence applies to two images alone"), "{e}");

    // --min-confidence trades coverage for precision: fewer pixels, and those kept are the
    // ones the matcher trusts, so the view's error against im4 on them is no worse.
    let truth = io::load_rgb(&dir.join("im4.png")).unwrap();
    let mut prev: Option<(f64, f64)> = None;
    for c in ["0", "0.5", "0.9"] {
        let o_dir = out.join(format!("conf{c}"));
        let o = viewsynth(
            &["--max-disparity", "64", "--min-confidence", c],
            &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &o_dir)],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mask = io::load_mask_png(&o_dir.join("middle_mask.png")).unwrap();
        let seen: Vec<bool> = mask.data.iter().map(|m| *m != 0).collect();
        let rgb = io::load_rgb(&o_dir.join("middle_rgb.png")).unwrap();
        let (cover, db) = (count(&seen) as f64 / seen.len() as f64, psnr(&rgb, &truth, &seen));
        if c == "0" {
            // Confidence 0 drops only what is already unknown: the plain estimate's view.
            let plain = std::fs::read(alone.join("middle_rgb.png")).unwrap();
            assert!(
                std::fs::read(o_dir.join("middle_rgb.png")).unwrap() == plain,
                "--min-confidence 0"
            );
        }
        if let Some((c0, db0)) = prev {
            assert!(
                cover < c0,
                "--min-confidence {c}: coverage {cover:.4} not below {c0:.4}"
            );
            // The kept pixels are those seen by surfaces the matcher trusts: allow 0.1 dB of
            // the metric's own noise (fewer pixels averaged), no real loss.
            assert!(db > db0 - 0.1, "--min-confidence {c}: {db:.2} dB against {db0:.2}");
        }
        prev = Some((cover, db));
    }
    let e = usage(
        &["--min-confidence", "1.5"],
        &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &bad)],
    );
    assert!(e.contains("outside [0, 1]"), "{e}");
    let e = usage(
        &["--disparity-scale", "4"],
        &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &bad)],
    );
    assert!(e.contains("--disparity-scale decodes disparity or depth files"), "{e}");
    assert!(!bad.exists(), "a refused run writes nothing");
}

/// `--matcher sgm`: two images alone render the semi-global matcher's disparities. Oracle as
/// above: its twin's disparities given as files give the same files, byte for byte (the census
/// matcher's would not: checked, so the option is not ignored). With disparities given, or an
/// unknown name, it is a usage error.
#[test]
fn cli_two_images_alone_render_the_semi_global_matchers_disparities() {
    use viewsynth::cyclopean::matcher::MatcherMethod;
    let dir = data_dir().join("tsukuba_5view_no_gt");
    let out = out_dir("cyclopean-two-images-sgm");
    let (l, r) = (dir.join("tsukuba2.png"), dir.join("tsukuba4.png"));
    let (li, ri) = (io::load_rgb(&l).unwrap(), io::load_rgb(&r).unwrap());
    let mut files = Vec::new();
    for method in [MatcherMethod::Sgm, MatcherMethod::Census] {
        let (dl, dr) = method.estimate_reference(&li, &ri, 32).unwrap();
        let (dl_file, dr_file) = (
            out.join(format!("{method:?}_l.npy")),
            out.join(format!("{method:?}_r.npy")),
        );
        io::save_depth_npy(&dl_file, &dl).unwrap();
        io::save_depth_npy(&dr_file, &dr).unwrap();
        files.push((dl_file, dr_file));
    }
    let alone = out.join("alone");
    let o = viewsynth(
        &["--max-disparity", "32", "--matcher", "sgm"],
        &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &alone)],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (k, (dl_file, dr_file)) in files.iter().enumerate() {
        let given = out.join(format!("given{k}"));
        let o = viewsynth(
            &[],
            &[
                ("--left-rgb", &l),
                ("--right-rgb", &r),
                ("--left-disparity", dl_file),
                ("--right-disparity", dr_file),
                ("--out-dir", &given),
            ],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let same = std::fs::read(alone.join("middle_rgb.png")).unwrap()
            == std::fs::read(given.join("middle_rgb.png")).unwrap();
        assert_eq!(
            same,
            k == 0,
            "the view from --matcher sgm vs the {} twin's disparities given",
            ["sgm", "census"][k]
        );
    }
    let bad = out.join("bad");
    for (args, want) in [
        (&["--matcher", "sgm"][..], "--matcher applies to two images alone"),
        (&["--matcher", "bogus"][..], "bogus"),
    ] {
        let o = viewsynth(
            args,
            &[
                ("--left-rgb", &l),
                ("--right-rgb", &r),
                ("--left-disparity", &files[0].0),
                ("--right-disparity", &files[0].1),
                ("--out-dir", &bad),
            ],
        );
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(want), "{args:?}: {e}");
        assert!(!bad.exists(), "{args:?}");
    }
}
