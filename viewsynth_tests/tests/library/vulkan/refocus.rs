//! GL against a real Vulkan run of the same refocus shaders (Mesa lavapipe in CI): for every
//! convention combination, both paths, the real TUM frame and the synthetic scene at five focal
//! scales, the outputs agree: mask identical, colour within one 8-bit level, depth within
//! DEPTH_REL_BOUND. A missing Vulkan loader or driver fails these tests, never skips them.
//!
//! Why those bounds. Both backends run the same GLSL on the same inputs: the per-column/row
//! lookups are computed in f64 on the CPU and uploaded as the same f32 values, texel fetches and
//! gathers return the stored texels exactly, the clip matrix and depth coefficients are the same
//! f32 numbers. Coverage is decided by comparisons of those values against the same constants, so
//! the mask is identical. What may differ is how each compiler (Mesa's GLSL front end vs glslang +
//! SPIR-V to NIR) orders or fuses f32 arithmetic:
//! - depth: tri_depth is 1 / dot(w, 1 / z). The three reciprocals and the final one are within
//!   2.5 ulp each (GLSL 4.50 precision of 1/x); the weights (1 - a, a - b, b) carry at most 1 ulp
//!   of 1 each, which weighs on the dot at most by z_max / z_min <= 1.1 (a kept triangle's edges
//!   pass the 5 % break rule, two edges compound to 1.1025) times 3 terms; the dot's two adds and
//!   three products (fused or not) add 5 ulp. Per backend: 2.5 + 2.5 + 3.3 + 5 = 13.3 ulp; two
//!   backends apart: 26.6 ulp; rounded up to 32 ulp = 32 x 2^-24 = 1.9e-6 relative. The border
//!   branch (1 / mix of two reciprocals) is within the same count.
//! - colour: the bilinear mix is f32 in both; only values within an f32 rounding of a k + 0.5
//!   tie may round to different bytes: one level.

use viewsynth::convention::Conventions;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusOutput, RefocusSource, Refocuser};
use viewsynth::vulkan::VkExecutor;
use viewsynth_tests::*;

/// 32 ulp of f32 relative (derivation above).
const DEPTH_REL_BOUND: f32 = 32.0 / (1u32 << 24) as f32;

/// Largest differences of one GL/Vulkan pair.
#[derive(Default, Debug, Clone, Copy)]
struct Diff {
    mask_mismatches: usize,
    valid: usize,
    worst_colour_levels: i32,
    colour_off_by_one: usize,
    worst_depth_rel: f32,
}

fn diff(gl: &RefocusOutput, vk: &RefocusOutput) -> Diff {
    let (mg, mv) = (&gl.mask.as_ref().unwrap().data, &vk.mask.as_ref().unwrap().data);
    let (zg, zv) = (&gl.depth.as_ref().unwrap().data, &vk.depth.as_ref().unwrap().data);
    let (cg, cv) = (&gl.rgb.as_ref().unwrap().data, &vk.rgb.as_ref().unwrap().data);
    let mut d = Diff::default();
    for i in 0..mg.len() {
        if mg[i] != mv[i] {
            d.mask_mismatches += 1;
            continue;
        }
        if mg[i] == 0 {
            // Invalid pixels are zero in every output under both backends.
            assert_eq!((zg[i], zv[i]), (0.0, 0.0), "invalid pixel {i} has a depth");
            continue;
        }
        d.valid += 1;
        let rel = (zg[i] - zv[i]).abs() / zg[i].abs();
        d.worst_depth_rel = d.worst_depth_rel.max(rel);
        for c in 0..3 {
            let l = (cg[3 * i + c] as i32 - cv[3 * i + c] as i32).abs();
            d.worst_colour_levels = d.worst_colour_levels.max(l);
            d.colour_off_by_one += (l == 1) as usize;
        }
    }
    d
}

fn sources() -> Vec<(&'static str, RefocusSource)> {
    vec![("TUM", real_frame("TUM")), ("synthetic", synthetic(320, 240))]
}

/// GL and Vulkan under every convention for `method`; returns one row per convention (the
/// worst over sources and scales) after asserting the bounds.
fn gl_and_vulkan_agree(method: Method) {
    let (g, v) = (gpu(), vulkan());
    let device = VkExecutor::device(&v).unwrap();
    eprintln!(
        "GL '{}' vs Vulkan '{}' ({}), {method:?}",
        g.info().renderer,
        v.info().name,
        v.info().device_type
    );
    eprintln!("| conventions | valid px | mask mismatches | worst colour (levels) | colour values off by 1 | worst depth rel |");
    eprintln!("|---|---|---|---|---|---|");
    for conv in Conventions::all() {
        let mut row = Diff::default();
        for (name, src) in sources() {
            let targets = TargetSpec {
                // 0.01: below MIN_INTERIOR_SCALE, the mesh pass pulls every triangle.
                scales: vec![0.01, 0.5, 1.0, 1.5, 3.0],
                size: None,
                principal: None,
            }
            .targets(&src.camera())
            .unwrap();
            let rule = BreakRule::default();
            let mut gl = Refocuser::new(&g, &src, &rule, method, OutputSet::default(), conv).unwrap();
            let mut vk = Refocuser::new(&device, &src, &rule, method, OutputSet::default(), conv).unwrap();
            for (ti, t) in targets.iter().enumerate() {
                let d = diff(&gl.render(t).unwrap(), &vk.render(t).unwrap());
                let tag = format!("{name} {method:?} {} scale#{ti}", conv.label());
                assert_eq!(d.mask_mismatches, 0, "{tag}: masks differ");
                assert!(d.valid > 0, "{tag}: nothing rendered");
                assert!(
                    d.worst_colour_levels <= 1,
                    "{tag}: colour differs by {} levels",
                    d.worst_colour_levels
                );
                assert!(
                    d.worst_depth_rel <= DEPTH_REL_BOUND,
                    "{tag}: depth differs by {:e} relative (bound {DEPTH_REL_BOUND:e})",
                    d.worst_depth_rel
                );
                row.valid += d.valid;
                row.colour_off_by_one += d.colour_off_by_one;
                row.worst_colour_levels = row.worst_colour_levels.max(d.worst_colour_levels);
                row.worst_depth_rel = row.worst_depth_rel.max(d.worst_depth_rel);
            }
        }
        eprintln!(
            "| {} | {} | {} | {} | {} | {:.2e} |",
            conv.label(),
            row.valid,
            row.mask_mismatches,
            row.worst_colour_levels,
            row.colour_off_by_one,
            row.worst_depth_rel
        );
    }
}

#[test]
fn fullscreen_pass_gl_and_vulkan_agree_under_every_convention() {
    gl_and_vulkan_agree(Method::Fullscreen);
}

#[test]
fn mesh_pass_gl_and_vulkan_agree_under_every_convention() {
    gl_and_vulkan_agree(Method::Mesh);
}

/// The report's device table (`gl_vs_vulkan.md`): every pass of the lab run on GL and on Vulkan
/// under the 8 conventions, one row each, every row within the one agreement rule; refocus and
/// the cyclopean gather also within their own tighter bounds (no mask or source-bit mismatch,
/// colour within one level, depth within `DEPTH_REL_BOUND` and 4e-5 as derived above and in
/// vulkan_cyclopean.rs), both devices timed.
#[test]
fn device_table_runs_every_pass_on_both_devices_within_the_rule() {
    use viewsynth_lab::passes::PassCase;
    let devices = [
        viewsynth::pass::Device::gl(&gpu()).unwrap(),
        viewsynth::vulkan::VkExecutor::device(&vulkan()).unwrap(),
    ];
    let rows = viewsynth_lab::eval::backends::device_rows(&devices, 64, 48, &Conventions::all()).unwrap();
    assert_eq!(rows.len(), PassCase::all().len());
    for r in &rows {
        assert!(r.agrees, "{r:?}");
        assert!(r.ms[0] > 0.0 && r.ms[1] > 0.0, "{r:?}");
        assert!(r.worst.pixels > 0, "{r:?}");
        let bound = if r.pass.starts_with("refocus") {
            Some(DEPTH_REL_BOUND as f64)
        } else if r.pass == "cyclopean seed" || r.pass.starts_with("cyclopean refine") {
            Some(4e-5)
        } else {
            None
        };
        if let Some(bound) = bound {
            assert_eq!(r.worst.mask_mismatches, 0, "{r:?}");
            assert!(r.worst.colour_worst <= 1, "{r:?}");
            assert!(r.worst.depth_worst_rel <= bound, "{r:?}");
        }
    }
}

/// The outputs' bytes, for exact comparisons.
fn bytes(o: &RefocusOutput) -> (Vec<u8>, Vec<u32>, Vec<u8>) {
    (
        o.rgb.as_ref().unwrap().data.clone(),
        o.depth.as_ref().unwrap().data.iter().map(|z| z.to_bits()).collect(),
        o.mask.as_ref().unwrap().data.clone(),
    )
}

/// The batch's pattern on Vulkan: every target of frame A queued, frame B (same size) uploaded
/// while they are in flight, B's targets queued, then everything waited for. Each run must see
/// exactly its own frame and lookups: the outputs are bit-identical to rendering one target at a
/// time. Frame B differs from A everywhere (colour inverted, depth x 1.5), so a run that read
/// the other frame's texels, or another target's lookups, would differ.
#[test]
fn runs_in_flight_on_vulkan_equal_runs_one_at_a_time() {
    let v = vulkan();
    let device = VkExecutor::device(&v).unwrap();
    let a = real_frame("TUM");
    let b = RefocusSource::new(
        RgbImage::new(a.rgb.width, a.rgb.height, a.rgb.data.iter().map(|c| 255 - c).collect()).unwrap(),
        DepthMap::new(
            a.depth.width,
            a.depth.height,
            a.depth.data.iter().map(|z| z * 1.5).collect(),
        )
        .unwrap(),
        a.k,
    )
    .unwrap();
    let targets = TargetSpec {
        scales: vec![0.5, 1.0, 2.0],
        size: None,
        principal: None,
    }
    .targets(&a.camera())
    .unwrap();
    let rule = BreakRule::default();
    let conv = Conventions::all()[3];
    for method in [Method::Fullscreen, Method::Mesh] {
        let mut one = Refocuser::new(&device, &a, &rule, method, OutputSet::default(), conv).unwrap();
        let mut expected: Vec<_> = targets.iter().map(|t| bytes(&one.render(t).unwrap())).collect();
        one.set_source(&b).unwrap();
        expected.extend(targets.iter().map(|t| bytes(&one.render(t).unwrap())));
        drop(one);

        let mut r = Refocuser::new(&device, &a, &rule, method, OutputSet::default(), conv).unwrap();
        let mut pending: Vec<_> = targets.iter().map(|t| r.submit(t).unwrap()).collect();
        r.set_source(&b).unwrap();
        pending.extend(targets.iter().map(|t| r.submit(t).unwrap()));
        for (k, p) in pending.into_iter().enumerate() {
            let got = bytes(&p.wait().unwrap());
            assert!(
                got == expected[k],
                "{method:?} run {k}: in flight differs from one at a time"
            );
        }
        assert_ne!(
            expected[0], expected[3],
            "frames A and B must differ for this test to mean anything"
        );
    }
}
