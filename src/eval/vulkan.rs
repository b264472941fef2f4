//! The demo report's "GL vs Vulkan" section: one refocus target of the demo source rendered by
//! both backends under every convention combination and both paths, with the differences the
//! integration tests bound (mask identical, colour within one level, depth within 32 f32 ulp;
//! derived in tests/integration/vulkan_refocus.rs) and both render times; then the cyclopean
//! gather pass (refine, 3 steps) on the built-in scene's stereo frame under every convention,
//! with its bounds (source bits identical, colour within one level, depth within 4e-5;
//! derived in tests/integration/vulkan_cyclopean.rs).

use crate::camera::PinholeCamera;
use crate::convention::Conventions;
use crate::cyclopean::render::CyclopeanRenderer;
use crate::cyclopean::scene_frame::{scene_frame, StereoRig};
use crate::cyclopean::{CyclopeanOutput, CyclopeanParams, FrameDepth, Method as CyclopeanMethod};
use crate::error::Result;
use crate::gpu::{Gpu, GpuPolicy};
use crate::refocus::{BreakRule, Method, OutputSet, RefocusOutput, RefocusSource, Refocuser};
use crate::vulkan::{Vk, VkExecutor, VkRefocuser, VulkanContext, VulkanDeviceChoice};
use std::fmt::Write as _;

/// Differences between a GL and a Vulkan output of the same target.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BackendDiff {
    /// Pixels valid in one output and not the other.
    pub mask_mismatches: usize,
    /// Largest colour difference over pixels valid in both, 8-bit levels.
    pub worst_colour_levels: u8,
    /// Largest |Z_gl - Z_vk| / Z_gl over pixels valid in both.
    pub worst_depth_rel: f64,
}

/// Compare two outputs holding every output (rgb, depth, mask).
pub fn backend_diff(gl: &RefocusOutput, vk: &RefocusOutput) -> BackendDiff {
    let mut d = BackendDiff::default();
    let (Some(mg), Some(mv)) = (&gl.mask, &vk.mask) else {
        return d;
    };
    let (Some(zg), Some(zv)) = (&gl.depth, &vk.depth) else {
        return d;
    };
    let (Some(cg), Some(cv)) = (&gl.rgb, &vk.rgb) else {
        return d;
    };
    for i in 0..mg.data.len() {
        if mg.data[i] != mv.data[i] {
            d.mask_mismatches += 1;
        } else if mg.data[i] != 0 {
            let rel = ((zg.data[i] as f64 - zv.data[i] as f64) / zg.data[i] as f64).abs();
            d.worst_depth_rel = d.worst_depth_rel.max(rel);
            for c in 3 * i..3 * i + 3 {
                d.worst_colour_levels = d.worst_colour_levels.max(cg.data[c].abs_diff(cv.data[c]));
            }
        }
    }
    d
}

/// The section as Markdown; when no Vulkan device opens, a line saying why (the demo goes on).
pub fn gl_vs_vulkan_section(gpu: &Gpu, src: &RefocusSource, target: &PinholeCamera) -> String {
    let mut s = String::from("\n## GL vs Vulkan\n\n");
    match table(gpu, src, target, &mut s) {
        Ok(()) => s,
        Err(e) => format!("{s}Vulkan not run: {e}\n"),
    }
}

fn table(gpu: &Gpu, src: &RefocusSource, target: &PinholeCamera, s: &mut String) -> Result<()> {
    let vk = VulkanContext::open(VulkanDeviceChoice::Auto, GpuPolicy::default())?;
    writeln!(
        s,
        "The same GLSL on OpenGL ({}) and on Vulkan ({}, {}), fx' = {:.1} px, {}x{}. Bounds (tests): \
         mask identical, colour <= 1 level, depth <= 1.9e-6 relative.\n\n\
         | method | conventions | mask mismatches | worst colour (levels) | worst depth rel | GL ms | Vulkan ms |\n\
         |---|---|---|---|---|---|---|",
        gpu.info().renderer,
        vk.info().name,
        vk.info().device_type,
        target.k.fx,
        target.width,
        target.height
    )
    .expect("write to String");
    let rule = BreakRule::default();
    for method in [Method::Fullscreen, Method::Mesh] {
        for conv in Conventions::all() {
            let mut gl = Refocuser::new(gpu, src, &rule, method, OutputSet::default(), conv)?;
            let mut v = VkRefocuser::new(&vk, src, &rule, method, OutputSet::default(), conv)?;
            let (a, b) = (gl.render(target)?, v.render(target)?);
            let d = backend_diff(&a, &b);
            writeln!(
                s,
                "| {method:?} | {} | {} | {} | {:.2e} | {:.1} | {:.1} |",
                conv.label(),
                d.mask_mismatches,
                d.worst_colour_levels,
                d.worst_depth_rel,
                a.render.wall_ms + a.readback_ms,
                b.render.wall_ms + b.readback_ms
            )
            .expect("write to String");
        }
    }
    cyclopean_table(gpu, &vk, s)
}

/// Differences between a GL and a Vulkan middle view (every output present).
pub fn cyclopean_diff(gl: &CyclopeanOutput, vk: &CyclopeanOutput) -> BackendDiff {
    let mut d = BackendDiff::default();
    let (Some(zg), Some(zv), Some(cg), Some(cv)) = (&gl.depth, &vk.depth, &gl.color, &vk.color) else {
        return d;
    };
    for i in 0..gl.sources.len() {
        if gl.sources[i] != vk.sources[i] {
            d.mask_mismatches += 1;
            continue;
        }
        if gl.sources[i] != 0 {
            let rel = ((zg.data[i] as f64 - zv.data[i] as f64) / zg.data[i] as f64).abs();
            d.worst_depth_rel = d.worst_depth_rel.max(rel);
        }
        for c in 3 * i..3 * i + 3 {
            d.worst_colour_levels = d.worst_colour_levels.max(cg.data[c].abs_diff(cv.data[c]));
        }
    }
    d
}

/// The cyclopean gather rows: 160x120 eyes 0.2 m apart (as the tests), device depth, refine 3.
fn cyclopean_table(gpu: &Gpu, vk: &Vk, s: &mut String) -> Result<()> {
    let mut rig = StereoRig::demo(160, 120);
    rig.ipd = 0.2;
    let params = CyclopeanParams {
        method: CyclopeanMethod::Refine { steps: 3 },
        ..CyclopeanParams::seed(3.0)
    };
    writeln!(
        s,
        "\nCyclopean gather (refine, 3 steps), built-in scene, eyes 160x120 0.2 m apart, device depth. \
         Bounds (tests): source bits identical, colour <= 1 level, depth <= 4e-5 relative.\n\n\
         | pass | conventions | source mismatches | worst colour (levels) | worst depth rel | GL ms | Vulkan ms |\n\
         |---|---|---|---|---|---|---|"
    )
    .expect("write to String");
    for conv in Conventions::all() {
        let (frame, mid, _) = scene_frame(&rig, conv, FrameDepth::Device);
        let (a, ta) = CyclopeanRenderer::new(gpu, &frame, params)?.render(&mid)?;
        let (b, tb) = CyclopeanRenderer::new(&VkExecutor::device(vk)?, &frame, params)?.render(&mid)?;
        let d = cyclopean_diff(&a, &b);
        writeln!(
            s,
            "| Cyclopean | {} | {} | {} | {:.2e} | {:.1} | {:.1} |",
            conv.label(),
            d.mask_mismatches,
            d.worst_colour_levels,
            d.worst_depth_rel,
            ta.wall_ms,
            tb.wall_ms
        )
        .expect("write to String");
    }
    Ok(())
}
