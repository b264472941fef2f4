//! The demo report's "GL vs Vulkan" section: one refocus target of the demo source rendered by
//! both backends under every convention combination and both paths, with the differences the
//! integration tests bound (mask identical, colour within one level, depth within 32 f32 ulp;
//! derived in tests/integration/vulkan_refocus.rs) and both render times; then the cyclopean
//! gather pass (refine, 3 steps) on the built-in scene's stereo frame under every convention,
//! with its bounds (source bits identical, colour within one level, depth within 4e-5;
//! derived in tests/integration/vulkan_cyclopean.rs).

use viewsynth::camera::PinholeCamera;
use viewsynth::convention::Conventions;
use viewsynth::cyclopean::render::CyclopeanRenderer;
use viewsynth::cyclopean::scene_frame::{scene_frame, StereoRig};
use viewsynth::cyclopean::{CyclopeanOutput, CyclopeanParams, FrameDepth, Method as CyclopeanMethod};
use viewsynth::error::Result;
use viewsynth::gpu::{Gpu, GpuPolicy};
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusOutput, RefocusSource, Refocuser};
use viewsynth::vulkan::{Vk, VkExecutor, VulkanContext, VulkanDeviceChoice};
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

/// `gl_vs_vulkan.md` in `out_dir`: [`gl_vs_vulkan_section`] on the built-in scene (refocus at
/// 1.5x of a 160 x 120 view, then every other pass); its path.
pub fn write_section(gpu: &Gpu, out_dir: &std::path::Path) -> Result<std::path::PathBuf> {
    let cam = viewsynth::scene::demo_camera(160, 120);
    let (rgb, depth) = viewsynth::scene::render(&cam);
    let src = RefocusSource::new(rgb, depth, cam.k)?;
    let target = viewsynth::refocus::manifest::TargetSpec {
        scales: vec![1.5],
        size: None,
        principal: None,
    }
    .targets(&cam)?[0];
    let text = format!(
        "# viewsynth: every pass, GL against Vulkan\n\nGL renderer: {}\n{}",
        gpu.info().renderer,
        gl_vs_vulkan_section(gpu, &src, &target)
    );
    let path = out_dir.join("gl_vs_vulkan.md");
    viewsynth::io::atomic_write(&path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| viewsynth::Error::io(&path, e))
    })?;
    Ok(path)
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
            let mut v = Refocuser::new(
                &VkExecutor::device(&vk)?,
                src,
                &rule,
                method,
                OutputSet::default(),
                conv,
            )?;
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
    cyclopean_table(gpu, &vk, s)?;
    pass_rows(gpu, &vk, s)
}

/// Every pass described once and run by both executors (src/pass/), aggregated over the eight
/// conventions: the agreement rule of [`super::backends`] (masks differ on at most 0.5 % of
/// pixels, colour within one level on 99.5 %, depth within 1e-4 relative on 99.5 % of the
/// pixels valid in both), the worst case of each count, and the summed render times.
fn pass_rows(gpu: &Gpu, vk: &Vk, s: &mut String) -> Result<()> {
    use super::backends::{backend_diff, BackendDiff};
    use viewsynth::cyclopean::forward::ForwardWarp;
    use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
    use viewsynth::cyclopean::CyclopeanOutputs;
    use viewsynth::pass::Device;
    use viewsynth::reproject::render::Reprojector;
    use viewsynth::scene::gpu::{GlCamera, SceneRenderer};
    use viewsynth::stitch::render::StitchRenderer;
    use viewsynth::stitch::{faces::scene_faces, Method as Sm, OdsRig, Side, StitchParams};
    use viewsynth::view::ViewOutput;

    writeln!(
        s,
        "\nEvery pass on both APIs, worst over the 8 conventions, built-in scene 96x72 (stitch: 128x64 \
         per eye from 48 px faces). Rule (tests/integration/vulkan_passes.rs): masks differ on at most \
         0.5 % of pixels, colour within 1 level on 99.5 %, depth within 1e-4 relative on 99.5 % of \
         pixels valid in both.\n\n\
         | pass | mask mismatches | pixels > 1 level | worst colour | depth beyond 1e-4 | worst depth rel | \
         agrees | GL ms (8 runs) | Vulkan ms (8 runs) |\n|---|---|---|---|---|---|---|---|---|"
    )
    .expect("write to String");
    let devices = [Device::gl(gpu)?, viewsynth::vulkan::VkExecutor::device(vk)?];
    let rig = StereoRig::demo(96, 72);
    let seed = CyclopeanParams::seed(3.0);
    let refine = CyclopeanParams {
        method: CyclopeanMethod::Refine { steps: 3 },
        ..seed
    };
    let ods = OdsRig::demo();
    let faces = (
        scene_faces(&ods, Side::Left, 48, 110.0)?,
        scene_faces(&ods, Side::Right, 48, 110.0)?,
    );
    let scene = viewsynth::scene::builtin("demo")?;
    let names = [
        "cyclopean seed",
        "cyclopean refine 3",
        "cyclopean splat-gather",
        "cyclopean forward",
        "reproject shift",
        "reproject shift-scan",
        "reproject gather3d",
        "stitch blend",
        "stitch border-weight",
        "stitch reproject",
        "scene ray tracer",
    ];
    for (k, name) in names.iter().enumerate() {
        let mut worst = BackendDiff::default();
        let mut agrees = true;
        let mut ms = [0.0; 2];
        for conv in Conventions::all() {
            let (frame, mid, _) = scene_frame(&rig, conv, FrameDepth::Device);
            let (w, h) = (mid.width, mid.height);
            let mut views = Vec::new();
            for (d, total) in devices.iter().zip(ms.iter_mut()) {
                let cyclopean = |(out, t): (CyclopeanOutput, viewsynth::gpu::Timing)| {
                    (ViewOutput::from_cyclopean(&out, w, h, None), t.wall_ms)
                };
                let (view, t) = match k {
                    0 => cyclopean(CyclopeanRenderer::new(d, &frame, seed)?.render(&mid)?),
                    1 => cyclopean(CyclopeanRenderer::new(d, &frame, refine)?.render(&mid)?),
                    2 => cyclopean(
                        SplatRenderer::new(d, &frame, SplatParams::default(), CyclopeanOutputs::default())?
                            .render(&mid)?,
                    ),
                    3 => cyclopean(ForwardWarp::new(d, &frame, &BreakRule::default())?.render(&mid)?),
                    4..=6 => {
                        let case =
                            crate::eval::reproject::scene_cases(96, 72, 0.2, conv, FrameDepth::Device)?.remove(0);
                        let params = crate::eval::reproject::methods()[k - 4];
                        let (out, t) = Reprojector::new(d, &case.source, &case.geometry, params)?.render()?;
                        (ViewOutput::from_reproject(&out, 96, 72, None), t.wall_ms)
                    }
                    7..=9 => {
                        let params = StitchParams {
                            method: Sm::ALL[k - 7],
                            overlap_deg: 10.0,
                            width: 128,
                            height: 64,
                        };
                        let (img, t) =
                            StitchRenderer::with_conventions(d, &faces.0, &faces.1, conv)?.render(&params)?;
                        (ViewOutput::color_only(img, None), t.wall_ms)
                    }
                    _ => {
                        let cam = GlCamera {
                            view: frame.left.view,
                            proj: frame.left.proj,
                            width: w,
                            height: h,
                            conv,
                        };
                        let (img, t) = SceneRenderer::new(d, &scene)?.render(&cam)?;
                        let view = ViewOutput {
                            width: w,
                            height: h,
                            color: Some(img.color),
                            depth: Some(img.view_z),
                            mask: None,
                            timing: None,
                            exact: None,
                        };
                        (view, t.wall_ms)
                    }
                };
                *total += t;
                views.push(view);
            }
            let d = backend_diff(&views[0], &views[1]);
            agrees &= d.agrees();
            worst.pixels = d.pixels;
            worst.mask_mismatches = worst.mask_mismatches.max(d.mask_mismatches);
            worst.colour_beyond_one = worst.colour_beyond_one.max(d.colour_beyond_one);
            worst.colour_worst = worst.colour_worst.max(d.colour_worst);
            worst.depth_beyond = worst.depth_beyond.max(d.depth_beyond);
            worst.depth_worst_rel = worst.depth_worst_rel.max(d.depth_worst_rel);
        }
        writeln!(
            s,
            "| {name} | {} | {} | {} | {} | {:.1e} | {} | {:.1} | {:.1} |",
            worst.mask_mismatches,
            worst.colour_beyond_one,
            worst.colour_worst,
            worst.depth_beyond,
            worst.depth_worst_rel,
            if agrees { "yes" } else { "NO" },
            ms[0],
            ms[1]
        )
        .expect("write to String");
    }
    Ok(())
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
