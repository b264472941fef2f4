//! stitch: ODS equirect from over-wide cube faces of the built-in scene. Quality of the three
//! methods against the ray-traced ODS truth, GPU against the f64 twin, bad input.
//!
//! GPU tolerance: the pass is f32. Sample positions are off by ~1e-5 face px (f32 of angles and
//! of f ~ 50..100 px scales), so bilinear colour moves by < 0.01 level except where f32 and f64
//! land on different sides of a discrete choice: the nearest depth texel (a half-pixel tie), the
//! band edge, the on-ray tolerance of `reproject`, the surface-agreement test, and the seed
//! method's interpolation towards a point 500 m away (f32 ulp there is 3e-5 m, ~1e-7 rad, far
//! below a texel). Such pixels take another texel's colour, so they are counted, not bounded:
//! at most 0.5 % of pixels may be off by more than 1 level; the rest must round the same.
//!
//! The ray distance (the depth plane) is `t = (e + z r - o) . d`: face eye e and ODS origin o
//! within 1.7 m of the world origin (the rig centre is 1.6 m out), r = R ((uv - c) / f, 1) of
//! length <= 1 / cos(65 deg) = 2.4 on the widest faces here, z the face texel's own f32. Each
//! f32 rounding of an operand is at most 2^-24 (1.7 + 2.4 z), and t >= z / 2.4 (the ray leaves
//! the face axis by at most 65 deg), so per rounding at most 2^-24 (1.7 / z + 2.4) 2.4 relative
//! = 2^-24 x 10 for the scene's z >= 0.5 m; ~12 roundings (unproject 6, difference 3, dot 3)
//! give 7.2e-6, and the ~1e-5 px sample position moves t by < 1e-7 relative: [`DISTANCE_REL`]
//! = 1e-5. A distance past it, or on one side only, is a discrete choice taken the other way
//! (another texel, the other face): counted with the colour's 0.5 %.

use viewsynth::convention::Conventions;
use viewsynth::output::OutputSet;
use viewsynth::pass::Device;
use viewsynth::stitch::faces::{faces_from_images, scene_faces};
use viewsynth::stitch::reference::{stitch_reference, stitch_reference_eye};
use viewsynth::stitch::render::StitchRenderer;
use viewsynth::stitch::score::{score_eyes, split_top_bottom, StitchScore};
use viewsynth::stitch::truth::ods_truth;
use viewsynth::stitch::{pass, seam_band_mask, top_bottom, FaceSet, Method, OdsRig, Side, StitchInput, StitchParams};
use viewsynth::{metrics, Error};
use viewsynth_lab::eval::image_check;
use viewsynth_tests::gpu;

/// Ray distance agreement, GPU against twin (module docs).
const DISTANCE_REL: f64 = 1e-5;

const N: u32 = 128;
const W: u32 = 512;
const H: u32 = 256;

fn faces(overlap: f64) -> (FaceSet, FaceSet) {
    let rig = OdsRig::demo();
    let fov = 90.0 + 2.0 * overlap;
    (
        scene_faces(&rig, Side::Left, N, fov).unwrap(),
        scene_faces(&rig, Side::Right, N, fov).unwrap(),
    )
}

fn params(method: Method, overlap: f64) -> StitchParams {
    StitchParams {
        method,
        overlap_deg: overlap,
        width: W,
        height: H,
    }
}

/// IPD of the wide rig: parallax between neighbouring face eyes ~4x the demo rig's, so double
/// images are several equirect pixels wide at the sphere and plate (1-2 m).
const WIDE_IPD: f64 = 0.25;

/// Seam-band and whole-image scores of the three methods (f64 reference) at one overlap.
fn method_scores_on(rig: &OdsRig, overlap: f64) -> Vec<StitchScore> {
    let truth = [
        ods_truth(rig, Side::Left, W, H).unwrap(),
        ods_truth(rig, Side::Right, W, H).unwrap(),
    ];
    let fov = 90.0 + 2.0 * overlap;
    let (l, r) = (
        scene_faces(rig, Side::Left, N, fov).unwrap(),
        scene_faces(rig, Side::Right, N, fov).unwrap(),
    );
    let band = seam_band_mask(W, H, overlap);
    Method::ALL
        .iter()
        .map(|&m| {
            let el = stitch_reference(&l, &params(m, overlap)).unwrap();
            let er = stitch_reference(&r, &params(m, overlap)).unwrap();
            assert!(el.iter().chain(&er).flatten().all(|v| v.is_finite()), "{m:?}: NaN");
            let s = score_eyes([&el, &er], [&truth[0], &truth[1]], &band);
            println!("ipd {} overlap {overlap}: {m:?} {s:?}", rig.ipd);
            s
        })
        .collect()
}

fn method_scores(overlap: f64) -> Vec<StitchScore> {
    method_scores_on(&OdsRig::demo(), overlap)
}

/// The issue asked for "seam band error of (b) below (a)'s". That does not hold for the seed as
/// written (src/stitch/mod.rs, "Measured"): on the seam band the seed's border weight scores
/// 0.16-0.38 dB below the plain blend here (faces 128^2, equirect 512x256, IPD 0.064). What
/// holds is that it stays close: the bound 0.5 dB is the largest measured deficit (0.38 dB at
/// 5 deg) plus ~0.1 dB, so a change that makes (b) clearly worse than now fails here.
#[test]
fn border_weight_stays_within_half_a_db_of_plain_blend_on_the_seam_band() {
    for overlap in [5.0, 10.0, 20.0] {
        let s = method_scores(overlap);
        assert!(
            s[1].seam_psnr_db > s[0].seam_psnr_db - 0.5,
            "overlap {overlap}: border weight {} dB vs blend {} dB on the seam band",
            s[1].seam_psnr_db,
            s[0].seam_psnr_db
        );
    }
}

/// What the seed claims and what it costs, on the demo rig and on a wide rig where parallax is
/// larger. The claim, held as a one-sided bound: (b) is crisper than (a) on the seam band
/// (summed luma gradient closer to the truth's: less of the blend's doubled, averaged image); on
/// the wide rig the gain is measured at 0.015-0.025 and 0.01 is asserted. The cost: its content
/// is displaced (its effective eye runs back towards the +Z face's for w > 0.5, mod.rs), so SSIM,
/// the gradient error and the PSNR over near surfaces (< 3 m) come out below the blend's. Those
/// are bounded from one side only, so a fix that removes the cost passes and a change that
/// makes it larger fails. Largest measured deficit against the blend over overlaps 5/10/20
/// (print_stitch_measurements):
///
/// | rig | SSIM | gradient error | near PSNR |
/// |---|---|---|---|
/// | IPD 0.064 | 0.0020 | 0.028 | 0.60 dB |
/// | IPD 0.25 | 0.0133 | 0.110 | 1.14 dB |
///
/// The displacement grows with the parallax between neighbouring face eyes, i.e. linearly with
/// the IPD; each bound is the rig's largest measured deficit x 1.5 (room for llvmpipe/f64
/// differences and overlap-to-overlap spread, well below the 4x that a doubling of the
/// displacement on the wide rig would show).
#[test]
fn border_weight_is_crisper_than_plain_blend_and_its_displacement_cost_is_bounded() {
    for (ipd, min_gain, ssim, edge, near_db) in
        [(0.064, 0.0, 0.0030, 0.042, 0.90), (WIDE_IPD, 0.01, 0.020, 0.165, 1.71)]
    {
        let rig = OdsRig { ipd, ..OdsRig::demo() };
        for overlap in [5.0, 10.0, 20.0] {
            let s = method_scores_on(&rig, overlap);
            let (a, b) = (&s[0], &s[1]);
            let at = format!("ipd {ipd} overlap {overlap}: blend {a:?} border weight {b:?}");
            assert!(b.seam_sharpness > a.seam_sharpness + min_gain, "{at}");
            assert!(b.seam_ssim > a.seam_ssim - ssim, "{at}");
            assert!(b.seam_edge_mae < a.seam_edge_mae + edge, "{at}");
            assert!(b.seam_near_psnr_db > a.seam_near_psnr_db - near_db, "{at}");
        }
    }
}

#[test]
fn depth_aware_reprojection_beats_both_on_the_seam_band_and_the_whole_image() {
    for overlap in [5.0, 10.0, 20.0] {
        let s = method_scores(overlap);
        for other in [0, 1] {
            assert!(
                s[2].seam_psnr_db > s[other].seam_psnr_db + 0.5
                    && s[2].whole_psnr_db > s[other].whole_psnr_db
                    && s[2].seam_ssim > s[other].seam_ssim
                    && s[2].seam_edge_mae < s[other].seam_edge_mae,
                "overlap {overlap}: reproject {:?} vs {:?}",
                s[2],
                s[other]
            );
        }
    }
}

/// The depth panorama is the ODS truth's distance: along each pixel's own ODS ray, from its
/// origin on the viewing circle. Measured on the f64 twin (the GPU matches it to 1e-5 above),
/// faces 64^2, 256x128 per eye, overlap 10. Reproject's walk converges onto the surface the
/// truth hits (median 4e-8: a distance from the circle's centre would be off by up to
/// IPD/2 = 3.2 cm, 1e-3..1e-2 at 1-10 m); blend and border weight read the nearest face texel
/// along d (median 1.4e-4 .. 1.7e-4; at grazing floor texels a few %, measured p95 3 %).
/// Coverage (sky against surface) differs at silhouettes only: 98..168 of 32768 pixels.
#[test]
fn the_depth_panorama_is_the_distance_along_each_ods_ray() {
    let rig = OdsRig::demo();
    let (w, h) = (256, 128);
    for side in [Side::Left, Side::Right] {
        let set = scene_faces(&rig, side, 64, 110.0).unwrap();
        let truth = ods_truth(&rig, side, w, h).unwrap();
        for m in Method::ALL {
            let p = StitchParams {
                method: m,
                overlap_deg: 10.0,
                width: w,
                height: h,
            };
            let got = stitch_reference_eye(&set, &p).unwrap().distance;
            let (mut rel, mut coverage) = (Vec::new(), 0);
            for (t, want) in got.iter().zip(&truth.distance) {
                coverage += ((*t > 0.0) != (*want > 0.0)) as usize;
                if *t > 0.0 && *want > 0.0 {
                    rel.push((t - want).abs() / want);
                }
            }
            rel.sort_by(f64::total_cmp);
            let (median, p95) = (rel[rel.len() / 2], rel[rel.len() * 95 / 100]);
            println!("{side:?} {m:?}: median {median:.2e}, p95 {p95:.2e}, coverage differs on {coverage}");
            let bound = if m == Method::Reproject { 1e-6 } else { 1e-3 };
            assert!(
                median < bound && p95 < 0.05,
                "{side:?} {m:?}: median {median:.2e}, p95 {p95:.2e}"
            );
            assert!(
                coverage * 100 <= (w * h) as usize,
                "{side:?} {m:?}: coverage differs on {coverage}"
            );
        }
    }
}

/// The measurement table of src/stitch/mod.rs ("Measured"), printed (`--ignored --nocapture`).
#[test]
#[ignore = "prints the table of src/stitch/mod.rs (\"Measured\") to regenerate it; asserts nothing"]
fn print_stitch_measurements() {
    println!("| IPD | overlap | method | seam PSNR | seam MAE | whole PSNR | seam SSIM | whole SSIM | seam edge MAE | seam sharpness | seam near PSNR | seam far PSNR |");
    for ipd in [0.064, WIDE_IPD] {
        let rig = OdsRig { ipd, ..OdsRig::demo() };
        for overlap in [5.0, 10.0, 20.0] {
            for (m, s) in Method::ALL.iter().zip(method_scores_on(&rig, overlap)) {
                println!(
                    "| {ipd} | {overlap} | {} | {:.2} | {:.3} | {:.2} | {:.4} | {:.4} | {:.3} | {:.3} | {:.2} | {:.2} |",
                    m.label(),
                    s.seam_psnr_db,
                    s.seam_mae,
                    s.whole_psnr_db,
                    s.seam_ssim,
                    s.whole_ssim,
                    s.seam_edge_mae,
                    s.seam_sharpness,
                    s.seam_near_psnr_db,
                    s.seam_far_psnr_db
                );
            }
        }
    }
}

/// Through the pass/twin contract: [`pass::gpu`] against [`pass::reference`].
#[test]
fn gpu_matches_the_f64_reference_for_every_method() {
    twin_for_every_method(&Device::gl(&gpu()).unwrap());
}

/// The Vulkan executor running the same pass description meets the GL bound above, under every
/// row order (the only convention that reaches this pass).
#[test]
#[cfg(feature = "vulkan")]
fn vulkan_matches_the_f64_reference_for_every_method() {
    twin_for_every_method(&viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap());
}

fn twin_for_every_method(g: &Device) {
    eprintln!("stitch twin check on {:?}", g.api());
    for overlap in [5.0, 20.0] {
        let (l, r) = faces(overlap);
        for m in Method::ALL {
            // The row order is the one convention this pass sees: both, by overlap.
            let conv = Conventions::all()[if overlap > 10.0 { 4 } else { 0 }];
            let input = StitchInput {
                left: &l,
                right: &r,
                params: params(m, overlap),
                outputs: OutputSet::RGB_DEPTH,
                conv,
            };
            let out = pass::gpu(g, &input).unwrap();
            assert_eq!((out.width, out.height), (W, 2 * H));
            let twin = pass::reference(&input).unwrap();
            let exact = twin.exact.as_ref().expect("an f64 twin's view");
            let (reference, distance) = (&exact.color, exact.depth.as_ref().expect("the twin's distance"));
            let color = &out.color.as_ref().unwrap().data;
            let gpu_distance = &out.depth.as_ref().expect("the distance asked for").data;
            let (mut off, mut worst, mut far, mut worst_rel, mut surface) = (0, 0, 0, 0f64, 0);
            for (i, c) in reference.iter().enumerate() {
                let e = (0..3)
                    .map(|k| metrics::quantization_error(color[i * 3 + k], c[k]))
                    .max()
                    .unwrap();
                let (t, want) = (gpu_distance[i] as f64, distance[i]);
                let rel = match (t > 0.0, want > 0.0) {
                    (true, true) => (t - want).abs() / want,
                    (false, false) => 0.0,
                    _ => f64::INFINITY,
                };
                surface += (want > 0.0) as usize;
                far += (rel > DISTANCE_REL) as usize;
                off += (e > 1 || rel > DISTANCE_REL) as usize;
                worst = worst.max(e);
                if rel.is_finite() {
                    worst_rel = worst_rel.max(rel);
                }
            }
            println!(
                "overlap {overlap} {m:?}: {off} pixels off (colour > 1 level, worst {worst}; {far} distances \
                 beyond {DISTANCE_REL:e}, worst finite {worst_rel:.1e}; {surface} with a surface)"
            );
            // Not a plane of zeros: the demo scene's surfaces fill 46 % of the 360 (sky above).
            assert!(surface * 5 > reference.len() * 2, "{surface} pixels with a distance");
            image_check::ensure_views(
                off * 200 <= reference.len(),
                &format!("stitch overlap {overlap} {m:?}"),
                &out,
                &twin,
                format!("overlap {overlap} {m:?}: {off} pixels off"),
            );
        }
    }
}

#[test]
fn stereo_output_is_top_bottom_with_the_left_eye_on_top() {
    let g = gpu();
    let (l, r) = faces(10.0);
    let p = params(Method::Blend, 10.0);
    let (out, _) = StitchRenderer::new(&g, &l, &r).unwrap().render(&p).unwrap();
    let [top, bottom] = split_top_bottom(&out);
    let el = stitch_reference(&l, &p).unwrap();
    let er = stitch_reference(&r, &p).unwrap();
    let err = |a: &[[f64; 3]], b: &[[f64; 3]]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (0..3).map(|k| (x[k] - y[k]).abs()).sum::<f64>())
            .sum::<f64>()
    };
    assert!(err(&top, &el) < err(&top, &er) && err(&bottom, &er) < err(&bottom, &el));
    let tb = top_bottom(
        &viewsynth::io::RgbImage::new(W, H, out.data[..(W * H * 3) as usize].to_vec()).unwrap(),
        &viewsynth::io::RgbImage::new(W, H, out.data[(W * H * 3) as usize..].to_vec()).unwrap(),
    )
    .unwrap();
    assert_eq!(tb, out);
}

#[test]
fn background_nan_depth_and_poles_give_finite_output() {
    let g = gpu();
    let (mut l, mut r) = faces(10.0);
    // Background written as NaN and +Inf instead of 0: same meaning.
    for (set, bad) in [(&mut l, f32::NAN), (&mut r, f32::INFINITY)] {
        for f in &mut set.faces {
            for z in &mut f.depth.data {
                if *z == 0.0 {
                    *z = bad;
                }
            }
        }
    }
    let mut renderer = StitchRenderer::new(&g, &l, &r).unwrap();
    let (l0, r0) = faces(10.0);
    let mut clean = StitchRenderer::new(&g, &l0, &r0).unwrap();
    for m in Method::ALL {
        let p = params(m, 10.0);
        let reference = stitch_reference(&l, &p).unwrap();
        assert!(reference.iter().flatten().all(|v| v.is_finite()), "{m:?}");
        assert_eq!(
            reference,
            stitch_reference(&l0, &p).unwrap(),
            "{m:?}: NaN = 0 = background"
        );
        assert_eq!(renderer.render(&p).unwrap().0, clean.render(&p).unwrap().0, "{m:?}");
    }
    // Pole rows of the truth and the reference are finite and mono (left = right at the pole).
    let rig = OdsRig::demo();
    let (tl, tr) = (
        ods_truth(&rig, Side::Left, 64, 1024).unwrap(),
        ods_truth(&rig, Side::Right, 64, 1024).unwrap(),
    );
    assert!(tl.color.iter().chain(&tr.color).flatten().all(|v| v.is_finite()));
    for row in [0usize, 1023] {
        let (a, b) = (&tl.color[row * 64..row * 64 + 64], &tr.color[row * 64..row * 64 + 64]);
        // r = IPD/2 (1 - smoothstep) ~ 1.5e-6 m on the pole rows: colour moves by << 0.1 level.
        let diff = a
            .iter()
            .zip(b)
            .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()));
        assert!(
            diff.fold(0.0, f64::max) < 0.1,
            "row {row}: the pole rule makes both eyes see the same"
        );
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let g = gpu();
    let (l, r) = faces(5.0);
    // Overlap beyond what the faces cover.
    let e = stitch_reference(&l, &params(Method::Blend, 6.0)).unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
    let mut renderer = StitchRenderer::new(&g, &l, &r).unwrap();
    for p in [
        params(Method::Reproject, 0.0),
        params(Method::Reproject, f64::NAN),
        StitchParams {
            width: 0,
            ..params(Method::Blend, 5.0)
        },
    ] {
        assert!(matches!(renderer.render(&p), Err(Error::InvalidParameter { .. })));
    }
    // Sides swapped, faces missing, sizes mismatched, bad rig.
    assert!(StitchRenderer::new(&g, &r, &l).is_err());
    let mut five = l.clone();
    five.faces.pop();
    assert!(matches!(five.validate(), Err(Error::InvalidParameter { .. })));
    let mut odd = l.clone();
    odd.faces[3].depth = viewsynth::io::DepthMap::new(N, N - 1, vec![0.0; (N * (N - 1)) as usize]).unwrap();
    assert!(matches!(odd.validate(), Err(Error::SizeMismatch { .. })));
    let images: Vec<_> = l.faces.iter().map(|f| (f.color.clone(), f.depth.clone())).collect();
    assert!(faces_from_images(&l.rig, Side::Left, 100.0, images.clone()).is_ok());
    assert!(faces_from_images(&l.rig, Side::Left, 90.0, images.clone()).is_err());
    let bad_rig = OdsRig { ipd: f64::NAN, ..l.rig };
    assert!(faces_from_images(&bad_rig, Side::Left, 100.0, images).is_err());
    assert!(scene_faces(&l.rig, Side::Left, 1, 100.0).is_err());
    assert!(ods_truth(&l.rig, Side::Left, 0, 10).is_err());
}

#[test]
fn output_does_not_depend_on_the_row_order_or_depth_conventions() {
    // The pass stores faces and the equirect in each convention's memory order; after readback
    // the images must be identical (row flips are exact; NDC range and reversed-Z do not reach
    // this pass).
    let g = gpu();
    let (l, r) = faces(10.0);
    let reference: Vec<_> = Method::ALL
        .iter()
        .map(|&m| {
            StitchRenderer::with_conventions(&g, &l, &r, Conventions::all()[0])
                .unwrap()
                .render(&params(m, 10.0))
                .unwrap()
                .0
        })
        .collect();
    for conv in Conventions::all() {
        let mut renderer = StitchRenderer::with_conventions(&g, &l, &r, conv).unwrap();
        for (m, want) in Method::ALL.iter().zip(&reference) {
            let (img, _) = renderer.render(&params(*m, 10.0)).unwrap();
            assert!(
                img == *want,
                "{} {m:?}: differs from {}",
                conv.label(),
                Conventions::all()[0].label()
            );
        }
    }
}

#[test]
fn device_depth_faces_convert_to_view_z_and_stitch_alike() {
    // Faces whose depth is stored as f32 window depth: converted back to view Z the relative
    // error is ~eps under reversed-Z [0,1] and ~eps Z / near otherwise (<= 8 eps (1 + 10 / 0.05)
    // = 1e-4 for the scene's <= 10 m at near 0.05), so the stitched image may differ only where
    // a depth lands on the other side of a discrete choice (the 0.5 % of the GPU-vs-f64 test).
    use viewsynth::convention::DepthPlanes;
    use viewsynth::depth::DepthEncoding;
    use viewsynth::io::DepthMap;
    use viewsynth::stitch::faces::view_z_of;
    let g = gpu();
    let (l, r) = faces(10.0);
    let planes = DepthPlanes { near: 0.05, far: 100.0 };
    let kind = DepthEncoding::Device { planes };
    let (want, _) = StitchRenderer::new(&g, &l, &r)
        .unwrap()
        .render(&params(Method::Reproject, 10.0))
        .unwrap();
    for conv in [Conventions::default(), Conventions::all()[7]] {
        let convert = |set: &FaceSet| -> FaceSet {
            let mut out = set.clone();
            for face in &mut out.faces {
                let device: Vec<f32> = face
                    .depth
                    .data
                    .iter()
                    .map(|&z| {
                        if z > 0.0 {
                            let ndc = planes.ndc_z_of_view_z(&conv, z as f64);
                            DepthPlanes::window_depth_of_ndc_z(&conv, ndc) as f32
                        } else {
                            conv.clear_depth() as f32
                        }
                    })
                    .collect();
                let stored = DepthMap::new(face.depth.width, face.depth.height, device).unwrap();
                let back = view_z_of(&stored, &kind, &conv).unwrap();
                for (a, b) in face.depth.data.iter().zip(&back.data) {
                    if *a > 0.0 {
                        assert!(((b - a) / a).abs() <= 1e-4, "{}: {a} -> {b}", conv.label());
                    } else {
                        assert_eq!(*b, 0.0, "{}: background must stay background", conv.label());
                    }
                }
                face.depth = back;
            }
            out
        };
        let (img, _) = StitchRenderer::new(&g, &convert(&l), &convert(&r))
            .unwrap()
            .render(&params(Method::Reproject, 10.0))
            .unwrap();
        let off = img
            .data
            .chunks_exact(3)
            .zip(want.data.chunks_exact(3))
            .filter(|(p, q)| p.iter().zip(q.iter()).any(|(u, v)| u.abs_diff(*v) > 1))
            .count();
        assert!(
            off * 200 <= (W * H * 2) as usize,
            "{}: {off} pixels differ",
            conv.label()
        );
    }
    let disparity = DepthEncoding::Disparity {
        focal_px: 100.0,
        baseline: 0.1,
        doffs: 0.0,
    };
    assert!(view_z_of(&l.faces[0].depth, &disparity, &Conventions::default()).is_err());
}
