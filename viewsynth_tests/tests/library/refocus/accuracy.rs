//! GPU refocus against the float64 reference on real RGB-D frames and the synthetic scene.
//!
//! Tolerances, from the numerics:
//! - depth: both GPU paths evaluate 1/Z interpolation (full-screen) or perspective-correct
//!   interpolation (mesh) in f32: a few ulps relative (~3e-7), i.e. ~3e-6 m at 10 m < 1e-5 m.
//! - colour: bilinear weights in f32 against f64 (relative error ~1e-7 on values <= 255, i.e.
//!   < 1e-4 level); [`viewsynth::metrics::quantization_error`] already forgives either neighbour
//!   of a rounding tie, so every pixel must be within 1 level of the reference
//!   (`max_color_diff <= 1`): one pixel 2 levels off fails, at any scale and output size. The
//!   PSNR floor (60 dB) is kept beside it: it bounds how many pixels may sit 1 level off.
//! - mask: the GPU coverage test is closed with a tolerance of 1e-5 cell (CELL_EPS), the
//!   reference is exactly closed, so they differ only where a pixel centre falls within 1e-5
//!   of a kept edge from outside: IoU >= 0.999 (lowest measured on llvmpipe over 7 scales x 3
//!   sizes: SUN 0.999425, TUM 0.999648, synthetic 0.999852, NYU 1.0).

use viewsynth::camera::PinholeCamera;
use viewsynth::convention::Conventions;
use viewsynth::pass::Device;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::{pass, BreakRule, Method, OutputSet, RefocusInput, RefocusSource, Refocuser};
use viewsynth_lab::eval::image_check;
use viewsynth_tests::*;

const SCALES: [f64; 7] = [0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0];

/// Every target through the pass/twin contract: [`pass::gpu`] against [`pass::reference`], on
/// GL (llvmpipe) unless a device is given.
fn check_source(name: &str, src: &RefocusSource) {
    check_source_on(name, src, &Device::gl(&gpu()).unwrap());
}

/// [`check_source`] on `device`, with the same bounds whatever its API (both run the same GLSL
/// on the same f32 inputs; the derivation above holds for either compiler).
fn check_source_on(name: &str, src: &RefocusSource, device: &Device) {
    let cam = src.camera();
    let sizes = [
        None,
        Some((cam.width * 4 / 5, cam.height * 5 / 6)),
        Some((cam.width + 160, cam.height + 120)),
    ];
    for method in [Method::Fullscreen, Method::Mesh] {
        let (mut worst_depth, mut worst_psnr, mut worst_iou, mut worst_level) = (0f64, f64::INFINITY, 1f64, 0u8);
        for size in sizes {
            let targets = TargetSpec {
                scales: SCALES.to_vec(),
                size,
                principal: None,
            }
            .targets(&cam)
            .unwrap();
            for (s, target) in SCALES.iter().zip(&targets) {
                let input = RefocusInput {
                    source: src,
                    target,
                    rule: BreakRule::default(),
                    method,
                    outputs: OutputSet::default(),
                    rgb_everywhere: false,
                    conv: Conventions::default(),
                };
                let out = pass::gpu(device, &input).expect("render");
                let reference = pass::reference(&input).expect("reference");
                let a = compare_views(&out, &reference);
                let tag = format!("{name}_{method:?}_{}x{}_s{s}", target.width, target.height);
                let ok = a.max_abs_depth <= 1e-5 && a.psnr_db >= 60.0 && a.max_color_diff <= 1 && a.mask_iou >= 0.999;
                image_check::ensure_views(ok, &format!("refocus {tag}"), &out, &reference, format!("{tag}: {a:?}"));
                worst_depth = worst_depth.max(a.max_abs_depth);
                worst_psnr = worst_psnr.min(a.psnr_db);
                worst_iou = worst_iou.min(a.mask_iou);
                worst_level = worst_level.max(a.max_color_diff);
                let covered = reference.valid().unwrap().iter().filter(|m| **m).count();
                assert!(a.common > 0 || covered == 0, "{tag}: nothing in common");
                assert!(
                    out.depth.as_ref().unwrap().data.iter().all(|z| z.is_finite()),
                    "{tag}: non-finite depth"
                );
            }
        }
        // Shown with --nocapture: the worst case over 7 scales x 3 output sizes.
        eprintln!("{name} {method:?}: max depth error {worst_depth:.2e} m, min PSNR {worst_psnr:.1} dB, min IoU {worst_iou:.6}, max colour diff {worst_level} level(s)");
    }
}

#[test]
fn tum_frame_matches_reference() {
    check_source("TUM", &real_frame("TUM"));
}

/// The Vulkan executor (lavapipe in CI) against the f64 twin with the GL bounds: the refocus
/// pass description run by the other API.
#[cfg(feature = "vulkan")]
#[test]
fn tum_frame_on_vulkan_matches_reference() {
    let device = viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap();
    check_source_on("TUM on Vulkan", &real_frame("TUM"), &device);
    check_source_on("synthetic on Vulkan", &synthetic(320, 240), &device);
}

#[test]
fn sun_frame_matches_reference() {
    check_source("SUN", &real_frame("SUN"));
}

#[test]
fn nyu_frame_matches_reference() {
    check_source("NYU", &real_frame("NYU"));
}

#[test]
fn synthetic_scene_matches_reference() {
    check_source("synthetic", &synthetic(640, 480));
}

#[test]
fn scale_one_reproduces_the_input_on_every_pixel_of_a_kept_triangle() {
    let g = gpu();
    for name in ["TUM", "SUN"] {
        let src = real_frame(name);
        let cam: PinholeCamera = src.camera();
        let reference = reference(&src, &cam);
        for method in [Method::Fullscreen, Method::Mesh] {
            let mut r = Refocuser::new(
                &g,
                &src,
                &BreakRule::default(),
                method,
                OutputSet::default(),
                Conventions::default(),
            )
            .unwrap();
            let out = r.render(&cam).unwrap();
            let mask = mask_bools(&out);
            let rgb = &out.rgb.as_ref().unwrap().data;
            let depth = &out.depth.as_ref().unwrap().data;
            let mut kept = 0;
            for i in 0..mask.len() {
                // Reference coverage at s = 1 is exactly "corner of a kept triangle".
                assert_eq!(mask[i], reference.mask[i], "{name} {method:?} pixel {i}");
                if reference.mask[i] {
                    kept += 1;
                    assert_eq!(
                        &rgb[i * 3..i * 3 + 3],
                        &src.rgb.data[i * 3..i * 3 + 3],
                        "{name} {method:?} colour {i}"
                    );
                    let (z, z0) = (depth[i], src.depth.data[i]);
                    // f32 interpolation at a vertex: within a few ulps of the input.
                    assert!(
                        (z - z0).abs() <= 4.0 * f32::EPSILON * z0,
                        "{name} {method:?} depth {i}: {z} vs {z0}"
                    );
                }
            }
            assert!(kept > mask.len() / 2, "{name}: most pixels belong to kept triangles");
        }
    }
}

#[test]
fn fullscreen_and_mesh_paths_agree() {
    let g = gpu();
    let src = real_frame("TUM");
    let targets = TargetSpec {
        scales: vec![0.6, 1.0, 1.7],
        size: None,
        principal: None,
    }
    .targets(&src.camera())
    .unwrap();
    let mut fast = Refocuser::new(
        &g,
        &src,
        &BreakRule::default(),
        Method::Fullscreen,
        OutputSet::default(),
        Conventions::default(),
    )
    .unwrap();
    let mut mesh = Refocuser::new(
        &g,
        &src,
        &BreakRule::default(),
        Method::Mesh,
        OutputSet::default(),
        Conventions::default(),
    )
    .unwrap();
    for t in &targets {
        let (a, b) = (fast.render(t).unwrap(), mesh.render(t).unwrap());
        let (ma, mb) = (mask_bools(&a), mask_bools(&b));
        let iou = viewsynth::metrics::mask_iou(&ma, &mb);
        assert!(iou >= 0.999, "IoU {iou}");
        let (za, zb) = (&a.depth.as_ref().unwrap().data, &b.depth.as_ref().unwrap().data);
        for i in 0..ma.len() {
            if ma[i] && mb[i] {
                assert!((za[i] - zb[i]).abs() <= 1e-5, "pixel {i}: {} vs {}", za[i], zb[i]);
            }
        }
    }
}
