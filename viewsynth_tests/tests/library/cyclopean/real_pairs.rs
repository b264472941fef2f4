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

use viewsynth::camera::{gl_projection, Intrinsics, PinholeCamera};
use viewsynth::convention::Conventions;
use viewsynth::convention::DepthPlanes;
use viewsynth::cyclopean::baseline::{forward_splat, forward_splat_offset, forward_splat_rounded, Rounding};
use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
use viewsynth::cyclopean::splat_reference::{self, splat_reference};
use viewsynth::io::{self, DepthMap, RgbImage};
use viewsynth::metrics;
use viewsynth::stereo::disparity_frame::{disparity_frame, median_fixation, DisparityRig};
use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
use viewsynth::stereo::gather::reference::CyclopeanReference;
use viewsynth::stereo::gather::CyclopeanOutput;
use viewsynth::stereo::gather::CyclopeanOutputs;
use viewsynth::stereo::gather::CyclopeanParams;
use viewsynth::stereo::gather::Method;
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;
use viewsynth::stereo::StereoFrame;
use viewsynth_lab::eval::cyclopean::{estimated_cases, estimated_eyes};
use viewsynth_tests::real_pairs::{cones, count, out_dir, psnr, splat_gpu, splat_on, Eye};
use viewsynth_tests::{data_dir, gpu};

fn gather_gpu(frame: &StereoFrame, mid: &viewsynth::stereo::MiddleCamera, params: CyclopeanParams) -> CyclopeanOutput {
    CyclopeanRenderer::new(&gpu(), frame, params)
        .unwrap()
        .render(mid)
        .unwrap()
        .0
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
    mid: &viewsynth::stereo::MiddleCamera,
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

#[test]
fn splat_gather_gpu_matches_its_f64_twin() {
    splat_gather_twin(&viewsynth::pass::Device::gl(&gpu()).unwrap());
}

/// The Vulkan executor running the same pass descriptions meets the GL bounds above.
#[test]
#[cfg(feature = "vulkan")]
fn vulkan_splat_gather_matches_its_f64_twin() {
    splat_gather_twin(&viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap());
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

#[test]
fn default_beats_the_splat_baseline_on_cones_and_covers_more() {
    let (l, r, truth) = cones();
    let (l0, r0) = (l.clone(), r.clone());
    let base = forward_splat((&l.0, &l.1), (&r.0, &r.1), 0.5).unwrap();
    let (frame, mid) = disparity_frame(l, r, &DisparityRig::middle(400.0, 0.1), Conventions::default()).unwrap();
    let out = splat_gpu(&frame, &mid);
    let covered: Vec<bool> = out.sources.iter().map(|s| *s != 0).collect();
    let common: Vec<bool> = covered.iter().zip(&base.covered).map(|(a, b)| *a && *b).collect();
    let (ours, theirs) = (
        psnr(out.color().unwrap(), &truth, &common),
        psnr(&base.color, &truth, &common),
    );
    let msg = format!(
        "splat-gather {ours:.3} dB vs splat baseline {theirs:.3} dB on {} common pixels; coverage {} vs {} of {}",
        count(&common),
        count(&covered),
        count(&base.covered),
        covered.len()
    );
    eprintln!("{msg}");
    // The margin reached (0.59 dB measured when written, llvmpipe: 29.63 vs 29.04 dB), less
    // 0.1 dB for other GPUs' f32 decisions at quarter-pixel ties (1.3 % of the pixels, along
    // edges, see the twin test). Short of the issue's +1 dB: Cones' im4 sits (+0.25, +0.1) px
    // off the halfway view, which costs the sub-pixel default about 1.6 dB and the rounding
    // baseline nothing (next test).
    assert!(ours >= theirs + 0.5, "{msg}");
    assert!(count(&covered) >= count(&base.covered), "{msg}");
    // Issue 13's own baseline, the 40 lines of numpy whose `np.round` rounds halves to even
    // (89.5 % coverage there and here): its target, >= 1 dB over it on the common pixels with
    // >= 89.5 % coverage. Measured when written: 29.54 vs 28.17 dB (+1.37) on 150,554 pixels,
    // 96.3 % vs 89.5 % covered; the bound keeps about 0.1 dB for other GPUs' f32 decisions as
    // above.
    let issue = forward_splat_rounded((&l0.0, &l0.1), (&r0.0, &r0.1), 0.5, [0.0, 0.0], Rounding::HalfEven).unwrap();
    let common: Vec<bool> = covered.iter().zip(&issue.covered).map(|(a, b)| *a && *b).collect();
    let (ours, theirs) = (
        psnr(out.color().unwrap(), &truth, &common),
        psnr(&issue.color, &truth, &common),
    );
    let n = covered.len() as f64;
    let msg = format!(
        "splat-gather {ours:.3} dB vs issue 13's numpy splat {theirs:.3} dB on {} common pixels; coverage {:.4} vs {:.4}",
        count(&common),
        count(&covered) as f64 / n,
        count(&issue.covered) as f64 / n
    );
    eprintln!("{msg}");
    assert!(ours >= theirs + 1.25, "{msg}");
    assert!(count(&covered) as f64 >= 0.895 * n, "{msg}");
    assert!(
        (count(&issue.covered) as f64 / n - 0.895).abs() < 0.001,
        "the issue's coverage reproduced: {msg}"
    );
    // No worse than that where it matters most: one eye reprojected to the other (im2 -> im6,
    // the right disparity left out), where a splat has no second eye to fill its holes.
    let (l, mut r, _) = cones();
    let im6 = r.0.clone();
    r.1.data.iter_mut().for_each(|d| *d = 0.0);
    let base = forward_splat((&l.0, &l.1), (&r.0, &r.1), 1.0).unwrap();
    let rig = DisparityRig {
        position: 1.0,
        ..DisparityRig::middle(400.0, 0.1)
    };
    let (frame, mid) = disparity_frame(l, r, &rig, Conventions::default()).unwrap();
    let out = splat_gpu(&frame, &mid);
    let covered: Vec<bool> = out.sources.iter().map(|s| *s != 0).collect();
    let common: Vec<bool> = covered.iter().zip(&base.covered).map(|(a, b)| *a && *b).collect();
    let (ours, theirs) = (
        psnr(out.color().unwrap(), &im6, &common),
        psnr(&base.color, &im6, &common),
    );
    assert!(
        ours >= theirs + 0.5 && count(&covered) >= count(&base.covered),
        "im2 -> im6: {ours:.3} vs {theirs:.3} dB, coverage {} vs {}",
        count(&covered),
        count(&base.covered)
    );
}

/// Cones' im4 is not the exact halfway view: fitted against the truth here, the view that im4
/// matches best is the halfway one translated by about (+0.25, +0.1) px (the inputs agree with
/// each other to 0.1 px, so it is im4's own registration: a property of the data, kept in the
/// test above). This measures what that costs each method: the default renders the fitted
/// camera (principal point moved by the offset) and the baseline splats to the same offset.
#[test]
fn cones_im4_sits_off_the_halfway_view_which_costs_the_sub_pixel_default_not_the_baseline() {
    let (l, r, truth) = cones();
    let (w, h) = (truth.width, truth.height);
    let conv = Conventions::default();
    let (frame, mid) = disparity_frame(l.clone(), r.clone(), &DisparityRig::middle(400.0, 0.1), conv).unwrap();
    let mut renderer = SplatRenderer::new(&gpu(), &frame, SplatParams::default(), CyclopeanOutputs::default()).unwrap();
    let mut at = |dx: f64, dy: f64| {
        let cam = PinholeCamera {
            k: Intrinsics {
                fx: 400.0,
                fy: 400.0,
                cx: (w as f64 - 1.0) / 2.0 + dx,
                cy: (h as f64 - 1.0) / 2.0 + dy,
            },
            width: w,
            height: h,
        };
        let shifted = viewsynth::stereo::MiddleCamera {
            proj: gl_projection(&cam, &DepthPlanes { near: 0.01, far: 1e4 }, &conv),
            ..mid
        };
        renderer.render(&shifted).unwrap().0
    };
    let covered = |out: &CyclopeanOutput| -> Vec<bool> { out.sources.iter().map(|s| *s != 0).collect() };
    // Fit on the default's covered pixels, in 0.05 px steps.
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
    for ix in -2..=10 {
        for iy in -2..=4 {
            let (dx, dy) = (ix as f64 * 0.05, iy as f64 * 0.05);
            let out = at(dx, dy);
            let p = psnr(out.color().unwrap(), &truth, &covered(&out));
            if p > best.0 {
                best = (p, dx, dy);
            }
        }
    }
    let (_, dx, dy) = best;
    let score = |out: &CyclopeanOutput, offset: [f64; 2]| {
        let base = forward_splat_offset((&l.0, &l.1), (&r.0, &r.1), 0.5, offset).unwrap();
        let common: Vec<bool> = covered(out).iter().zip(&base.covered).map(|(a, b)| *a && *b).collect();
        (
            psnr(out.color().unwrap(), &truth, &common),
            psnr(&base.color, &truth, &common),
        )
    };
    let (ours_half, base_half) = score(&at(0.0, 0.0), [0.0, 0.0]);
    let (ours_fit, base_fit) = score(&at(dx, dy), [dx, dy]);
    let msg = format!(
        "im4 fitted at ({dx:+.2}, {dy:+.2}) px; halfway: default {ours_half:.3} dB, baseline {base_half:.3} dB; \
         fitted: default {ours_fit:.3} dB, baseline {base_fit:.3} dB (common pixels)"
    );
    eprintln!("{msg}");
    assert!((0.15..=0.35).contains(&dx) && (0.0..=0.2).contains(&dy), "{msg}");
    // Measured when written (llvmpipe): halfway 29.63 vs 29.04 dB, at im4's position 31.28 vs
    // 29.05 dB; the bounds keep 0.2 dB for other GPUs' f32 decisions at ties.
    assert!(ours_fit >= ours_half + 1.4, "the offset costs the default: {msg}");
    assert!((base_fit - base_half).abs() < 0.2, "and the baseline little: {msg}");
    assert!(
        ours_fit >= base_fit + 2.0,
        "at im4's own position the default wins by 2 dB: {msg}"
    );
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

#[test]
fn thin_poles_keep_their_colour_and_width_and_no_wall_shows_through() {
    let (l, r, poles) = poles_frame();
    let (frame, mid) = disparity_frame(l, r, &DisparityRig::middle(100.0, 0.1), Conventions::default()).unwrap();
    let w = mid.width as usize;
    let is_pole = |c: &[u8]| c == [20, 30, 230];
    let pole_columns = |out: &CyclopeanOutput| -> Vec<Vec<usize>> {
        let color = out.color().unwrap();
        (0..mid.height as usize)
            .map(|y| {
                (0..w)
                    .filter(|&x| is_pole(&color.data[(y * w + x) * 3..(y * w + x) * 3 + 3]))
                    .collect()
            })
            .collect()
    };
    // Texel x0 covers [x0 - 0.5, x0 + 0.5]; shifted by 10.3 the pole of width k covers the
    // pixel centres x0 - 10 ..= x0 + k - 11, exactly k pixels.
    let expected: Vec<usize> = poles.iter().flat_map(|&(x0, k)| (x0 - 10)..(x0 + k - 10)).collect();
    let out = splat_gpu(&frame, &mid);
    assert!(out.sources.iter().all(|s| *s != 0), "every pixel is seen by an eye");
    for (y, cols) in pole_columns(&out).iter().enumerate() {
        assert_eq!(cols, &expected, "row {y}: pole pixels (exact pole colour)");
    }
    let twin = splat_reference(&frame, &mid, &SplatParams::default())
        .unwrap()
        .to_output(mid.width, mid.height);
    assert_eq!(pole_columns(&twin), pole_columns(&out), "the f64 twin agrees");
    // The test can fail: the gather walk from a fixation depth on the wall lands behind the
    // poles and shows the wall there.
    let fixation = 100.0 * 0.1 / 4.0;
    let params = CyclopeanParams {
        method: Method::Refine { steps: 6 },
        ..CyclopeanParams::seed(fixation)
    };
    let walk = gather_gpu(&frame, &mid, params);
    let walked = pole_columns(&walk);
    assert!(
        walked.iter().any(|cols| cols != &expected),
        "the refine walk was expected to lose a pole: {:?}",
        walked[0]
    );
}

/// Refine 1 is the seed's step and one refinement: on a wall parallel to the eyes the seed's
/// step already finds the wall's depth from any fixation (it reads the wall wherever the guess
/// projects) and the refinement samples where that depth projects, so the check passes
/// everywhere. It can fail: sampling at the seed's guess instead (refine 1 before this
/// definition) passed only within about 2 px of middle parallax of the fixation (0 % at 8 px
/// nearer or 6 px farther, 8-10 % of Cones).
#[test]
fn refine_one_covers_a_wall_from_any_fixation() {
    let (w, h) = (64u32, 16u32);
    let d_wall = 8.0f32;
    let texture: Vec<u8> = (0..w * h * 3).map(|i| (i * 37 % 251) as u8).collect();
    let eye = || {
        (
            RgbImage::new(w, h, texture.clone()).unwrap(),
            DepthMap::new(w, h, vec![d_wall; (w * h) as usize]).unwrap(),
        )
    };
    let (f, b) = (100.0, 0.1);
    let (frame, mid) = disparity_frame(eye(), eye(), &DisparityRig::middle(f, b), Conventions::default()).unwrap();
    let coverage = |disparity: f64, steps: u32| {
        let params = CyclopeanParams {
            method: Method::Refine { steps },
            ..CyclopeanParams::seed(f * b / disparity)
        };
        let out = gather_gpu(&frame, &mid, params);
        // Columns the eyes cannot both see (the border) aside: the middle 40 columns.
        let inner: Vec<u8> = (0..h as usize)
            .flat_map(|y| out.sources[y * w as usize + 12..y * w as usize + 52].to_vec())
            .collect();
        inner.iter().filter(|s| **s != 0).count() as f64 / inner.len() as f64
    };
    let c = [
        coverage(d_wall as f64, 1),
        coverage(d_wall as f64 + 8.0, 1),
        coverage(d_wall as f64 - 6.0, 1),
        coverage(d_wall as f64 + 8.0, 6),
    ];
    assert!(
        c.iter().all(|c| *c > 0.99),
        "refine 1 on the wall, 8 px nearer, 6 px farther; refine 6 8 px nearer: {c:?}"
    );
}

/// Refine 1 on Cones from the CLI's fixation (the median disparity): most pixels covered and
/// no worse than a few dB under the default. Measured when written (llvmpipe): 94.2 % covered,
/// 26.24 dB on its covered pixels (refine 6: 95.9 %, 26.60 dB; the old refine 1: 10.3 %).
/// Bounds: 2 points of coverage and 0.5 dB under those, for other GPUs' f32 decisions at
/// Cones' quarter-pixel ties (1.3 % of the pixels, see the twin test).
#[test]
fn refine_one_covers_cones() {
    let (l, r, truth) = cones();
    let (frame, mid) = disparity_frame(l, r, &DisparityRig::middle(400.0, 0.1), Conventions::default()).unwrap();
    let fixation = median_fixation(&frame).unwrap();
    let params = CyclopeanParams {
        method: Method::Refine { steps: 1 },
        ..CyclopeanParams::seed(fixation)
    };
    let out = gather_gpu(&frame, &mid, params);
    let covered: Vec<bool> = out.sources.iter().map(|s| *s != 0).collect();
    let fraction = count(&covered) as f64 / covered.len() as f64;
    let db = psnr(out.color().unwrap(), &truth, &covered);
    assert!(
        fraction >= 0.92 && db >= 25.7,
        "refine 1 on Cones: {fraction:.4} covered, {db:.2} dB"
    );
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

/// Issue 13's "generalises": the default's settings, unchanged, on real pairs whose disparities
/// the census matcher (`viewsynth::cyclopean::matcher`) estimated from the two images alone, the
/// cases and search ranges of the report's estimated rows; against both forward splats on the
/// same disparities, on the pixels both cover, and covering at least as many pixels.
///
/// Bounds: the margin measured when written (llvmpipe; rounding half away / half to even), less
/// a part for other GPUs. The matcher (integer costs) and the CPU baselines are the same on every
/// machine; only the GPU's f32 decisions (a splat on a pixel border, two disparities at the
/// same-surface tolerance) may differ. With ground truth on Cones those ties are quarter-pixel
/// disparities on 1.3 % of the pixels and the tests keep 0.1 dB; estimated disparities are
/// parabola quotients and medians, off that grid, so ties are rarer: the bounds keep about half
/// the margin where it is small and 0.06-0.08 dB where it is not.
#[test]
fn default_beats_the_splat_baseline_with_estimated_disparities() {
    for (scene, min_gain_db) in [
        // +0.127 / +0.130 dB, 85.18 % vs 85.15 % covered (+0.156 / +0.159 before the
        // uniqueness test). Small beside ground truth's +0.59 dB:
        // Cones' im4 sits (+0.25, +0.1) px off the halfway view, which costs the sub-pixel
        // default and not the rounding baseline (see the test above).
        ("Middlebury Cones", 0.1),
        // +0.060 / +0.063 dB, 83.00 % vs 82.92 % before the matcher's uniqueness test (issue
        // 38); -0.027 / -0.025 dB, 76.49 % vs 76.47 % since: the test leaves unknown the
        // pixels whose match is ambiguous, where the default's sub-pixel gather and two-eye
        // merge had their edge, and on the clear matches left both methods draw the same
        // colours. A tie, not a win: the bound holds it within 0.06 dB (+0.127 dB on Cones).
        ("Tsukuba (tsukuba2+tsukuba4", -0.06),
        // +0.247 / +0.242 dB, 65.21 % vs 65.20 % (+0.265 / +0.260 before).
        ("Tsukuba (tsukuba1+tsukuba5", 0.2),
        // +1.135 / +1.136 dB, 80.21 % vs 78.30 % (+1.073 / +1.075 before; one eye: the splat has no second eye to fill
        // its cracks).
        ("Middlebury Teddy", 1.0),
        // +0.826 / +0.823 dB, 84.75 % vs 83.63 % (+0.729 / +0.727 before).
        ("Middlebury 2014 Motorcycle", 0.65),
    ] {
        for (baseline, v) in ["half away", "half to even"].iter().zip(estimated_versus_splats(scene)) {
            let msg = format!(
                "{scene}, rounding {baseline}: {:.3} vs {:.3} dB on the common pixels, covered {} vs {}",
                v.db.0, v.db.1, v.covered.0, v.covered.1
            );
            assert!(v.db.0 >= v.db.1 + min_gain_db, "{msg}");
            assert!(v.covered.0 >= v.covered.1, "{msg}");
        }
    }
}

/// The estimated rows skip a set absent from the data folder, each with a note naming it, rather
/// than failing the report; a present set gives its cases with the documented search range.
#[test]
fn estimated_cases_skip_absent_sets_and_search_the_documented_range() {
    let empty = out_dir("estimated-cases-empty");
    let (cases, notes) = estimated_cases(&empty).unwrap();
    assert!(cases.is_empty());
    for set in [
        "middlebury2003_cones",
        "tsukuba_5view_no_gt",
        "middlebury2003_teddy",
        "middlebury2014_motorcycle_skimage",
    ] {
        assert!(
            notes.iter().any(|n| n.contains(set) && n.contains("skipped")),
            "{set}: {notes:?}"
        );
    }
    let (cases, notes) = estimated_cases(&data_dir()).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    let ranges: Vec<(&str, u32)> = cases.iter().map(|c| (c.scene.as_str(), c.max_disparity)).collect();
    assert_eq!(
        ranges,
        [
            ("Middlebury Cones (im2+im6 -> im4)", 64),
            ("Tsukuba (tsukuba2+tsukuba4 -> tsukuba3)", 32),
            ("Tsukuba (tsukuba1+tsukuba5 -> tsukuba3)", 64),
            ("Middlebury Teddy (im2 -> im6)", 64),
            ("Middlebury 2014 Motorcycle (left -> right)", 64),
        ]
    );
}

/// More edge pixels than GL guarantees work groups for (65,535 groups of 64 = 4,194,240): every
/// pixel of a 2,100 x 2,100 view of one-texel stripes at two depths sits at a depth edge, so the
/// edge pass runs its capped work groups over the list more than once (the grid-stride loop in
/// splat_edges.comp). The stripes' half disparities (2.4, 6.4 px) put an edge 0.1 px from many
/// pixel centres, where the colour is mixed (6.3 % of the pixels change with mixing off).
/// Were the list cut at the cap, the pixels beyond it (in append order, anywhere) would keep
/// their unmixed colour: 13,385 (0.3 %) differ from the twin with the loop disabled, none with
/// it. Bound: 0.1 %, as on the built-in scene (off the quarter-pixel grid, f32 and f64 decide
/// alike but for a handful of pixels).
#[test]
fn edge_pass_mixes_more_edge_pixels_than_the_work_group_limit() {
    let (w, h) = (2100u32, 2100u32);
    let texture: Vec<u8> = (0..w * h * 3).map(|i| (i * 37 % 251) as u8).collect();
    let disparity: Vec<f32> = (0..w * h).map(|i| if i % w % 2 == 0 { 4.8 } else { 12.8 }).collect();
    let eye = || {
        (
            RgbImage::new(w, h, texture.clone()).unwrap(),
            DepthMap::new(w, h, disparity.clone()).unwrap(),
        )
    };
    let (frame, mid) =
        disparity_frame(eye(), eye(), &DisparityRig::middle(1000.0, 0.1), Conventions::default()).unwrap();
    check_twin(
        &viewsynth::pass::Device::gl(&gpu()).unwrap(),
        "edge-list-beyond-the-group-limit",
        &frame,
        &mid,
        0.001,
    );
}
