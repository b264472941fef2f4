//! Degenerate and extreme inputs: every output finite, and a stated rule for each.

use viewsynth::camera::{Intrinsics, PinholeCamera};
use viewsynth::convention::Conventions;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusSource, Refocuser};
use viewsynth_tests::*;

fn source(w: u32, h: u32, depth: Vec<f32>) -> RefocusSource {
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i * 53 % 256) as u8).collect();
    let k = Intrinsics {
        fx: 0.8 * w as f64,
        fy: 0.8 * w as f64,
        cx: (w as f64 - 1.0) / 2.0,
        cy: (h as f64 - 1.0) / 2.0,
    };
    RefocusSource::new(
        RgbImage::new(w, h, rgb).unwrap(),
        DepthMap::new(w, h, depth).unwrap(),
        k,
    )
    .unwrap()
}

fn each_method(
    src: &RefocusSource,
    scales: &[f64],
    check: impl Fn(&str, &viewsynth::refocus::RefocusOutput, &PinholeCamera),
) {
    let g = gpu();
    let targets = TargetSpec {
        scales: scales.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&src.camera())
    .unwrap();
    for method in [Method::Fullscreen, Method::Mesh] {
        for conv in [Conventions::default(), Conventions::all()[7]] {
            let mut r = Refocuser::new(&g, src, &BreakRule::default(), method, OutputSet::default(), conv).unwrap();
            for t in &targets {
                let out = r.render(t).unwrap();
                check(&format!("{method:?} {} fx'={}", conv.label(), t.k.fx), &out, t);
            }
        }
    }
}

#[test]
fn all_invalid_depth_gives_an_all_zero_mask_not_an_error() {
    let src = source(32, 24, vec![0.0; 32 * 24]);
    each_method(&src, &[0.5, 1.0, 2.0], |tag, out, _| {
        assert!(out.mask.as_ref().unwrap().data.iter().all(|m| *m == 0), "{tag}");
        assert!(out.depth.as_ref().unwrap().data.iter().all(|z| *z == 0.0), "{tag}");
        assert!(out.rgb.as_ref().unwrap().data.iter().all(|c| *c == 0), "{tag}");
    });
}

#[test]
fn one_pixel_image_is_a_valid_mesh_of_two_half_cells() {
    // The half-pixel border ring makes a 1x1 depth map a square of 4 triangles around its
    // pixel: at s = 1 its one pixel comes back, at s = 0.5 it covers the middle of 1 pixel too.
    let src = source(1, 1, vec![2.5]);
    each_method(&src, &[1.0, 0.5], |tag, out, _| {
        assert_eq!(out.mask.as_ref().unwrap().data, vec![1], "{tag}");
        assert_eq!(out.depth.as_ref().unwrap().data, vec![2.5], "{tag}");
        assert_eq!(out.rgb.as_ref().unwrap().data, src.rgb.data, "{tag}");
    });
}

#[test]
fn nan_inf_negative_and_zero_depth_are_holes_and_never_reach_the_output() {
    let (w, h) = (48, 40);
    let mut depth: Vec<f32> = (0..w * h).map(|i| 1.0 + 0.001 * (i % w) as f32).collect();
    for (i, bad) in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 0.0, -0.0]
        .into_iter()
        .enumerate()
    {
        for y in 0..4 {
            for x in 0..4 {
                depth[(5 + 6 * i / 2 + y) * w as usize + 4 + 20 * (i % 2) + x] = bad;
            }
        }
    }
    let src = source(w, h, depth);
    each_method(&src, &[0.7, 1.0, 1.9], |tag, out, t| {
        let z = &out.depth.as_ref().unwrap().data;
        assert!(z.iter().all(|v| v.is_finite() && *v >= 0.0), "{tag}");
        let reference = reference(&src, t);
        let a = compare(out, &reference);
        // Colour within 1 level of the reference on every common pixel (refocus_accuracy.rs).
        assert!(
            a.mask_iou >= 0.999 && a.max_abs_depth <= 1e-5 && a.max_color_diff <= 1,
            "{tag}: {a:?}"
        );
        assert!(reference.mask.iter().any(|m| !m), "{tag}: holes stay holes");
    });
}

#[test]
fn depth_from_millimetres_to_a_hundred_kilometres_in_one_frame() {
    // Left half 1 mm .. right half 100 km, each half a smooth ramp: near/far ratio 1e8.
    let (w, h) = (64, 32);
    let depth: Vec<f32> = (0..w * h)
        .map(|i| {
            if i % w < w / 2 {
                0.001 * (1.0 + 0.002 * (i % w) as f32)
            } else {
                1e5 * (1.0 + 0.001 * (i % w) as f32)
            }
        })
        .collect();
    let src = source(w, h, depth);
    each_method(&src, &[0.05, 0.5, 1.0, 2.0, 20.0], |tag, out, t| {
        let reference = reference(&src, t);
        let a = compare(out, &reference);
        // Relative: metres-level absolute error at 100 km is f32's 1e-7 relative.
        assert!(
            a.max_rel_depth <= 1e-6 && a.mask_iou >= 0.999 && a.max_color_diff <= 1,
            "{tag}: {a:?}"
        );
        assert!(out.depth.as_ref().unwrap().data.iter().all(|z| z.is_finite()), "{tag}");
    });
}

#[test]
fn extreme_focal_scales_match_the_reference() {
    let src = synthetic(160, 120);
    each_method(&src, &[0.05, 0.1, 10.0, 20.0], |tag, out, t| {
        let a = compare(out, &reference(&src, t));
        assert!(
            // Colour within 1 level everywhere (refocus_accuracy.rs), not only on average.
            a.max_abs_depth <= 1e-5 && a.mask_iou >= 0.999 && a.psnr_db >= 60.0 && a.max_color_diff <= 1,
            "{tag}: {a:?}"
        );
    });
}

#[test]
fn only_requested_outputs_are_produced() {
    let g = gpu();
    let src = synthetic(64, 48);
    let cam = src.camera();
    for list in ["rgb", "depth", "mask", "depth,mask"] {
        let set = OutputSet::parse(list).unwrap();
        for method in [Method::Fullscreen, Method::Mesh] {
            let mut r = Refocuser::new(&g, &src, &BreakRule::default(), method, set, Conventions::default()).unwrap();
            let out = r.render(&cam).unwrap();
            assert_eq!(
                (out.rgb.is_some(), out.depth.is_some(), out.mask.is_some()),
                (set.rgb, set.depth, set.mask),
                "{list}"
            );
        }
    }
    assert!(OutputSet::parse("").is_err() && OutputSet::parse("rgb,normals").is_err());
    // Last (each new context becomes current on this thread, so `g` is not used after):
    // counted on a fresh context per choice, renderer alive after one render, every output
    // left out costs exactly one render-target texture and one readback (pixel-pack buffer)
    // less than all three (colour also its source upload). An attachment, upload or read made
    // and thrown away shows here.
    let census = |set: OutputSet, method: Method| {
        let g = gpu();
        let mut r = Refocuser::new(&g, &src, &BreakRule::default(), method, set, Conventions::default()).unwrap();
        r.render(&cam).unwrap();
        (g.live_objects(), g.readback_buffers_created())
    };
    for method in [Method::Fullscreen, Method::Mesh] {
        let (all, all_reads) = census(OutputSet::parse("rgb,depth,mask").unwrap(), method);
        for list in ["rgb", "depth", "mask", "rgb,depth", "rgb,mask", "depth,mask"] {
            let set = OutputSet::parse(list).unwrap();
            let (live, reads) = census(set, method);
            let left_out = usize::from(!set.rgb) + usize::from(!set.depth) + usize::from(!set.mask);
            // Without colour the source colour is not uploaded either: one texture more.
            let textures_saved = left_out + usize::from(!set.rgb);
            let tag = format!("{method:?} {list}: {live:?}, {reads} readbacks; all {all:?}, {all_reads}");
            assert_eq!(live.textures + textures_saved, all.textures, "{tag}");
            assert_eq!(reads + left_out, all_reads, "{tag}");
            assert_eq!(
                (live.framebuffers, live.programs, live.vertex_arrays),
                (all.framebuffers, all.programs, all.vertex_arrays),
                "{tag}"
            );
        }
    }
}
