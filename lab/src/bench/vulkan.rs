//! `viewsynth bench --with-vulkan`: the refocus timings of `bench.rs` (built-in scene, 5 focal
//! scales, render + readback, medians) on the Vulkan device, and every pass on both APIs from
//! one run, for the GL-vs-Vulkan comparison.

use super::BenchCase;
use crate::bench::batch::median;
use viewsynth::convention::Conventions;
use viewsynth::cyclopean::render::CyclopeanRenderer;
use viewsynth::error::Result;
use viewsynth::pass::Device;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::Refocuser;
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusSource};
use viewsynth::scene;
use viewsynth::vulkan::{Vk, VkExecutor};
use std::fmt::Write as _;
use std::time::Instant;

const SCALES: [f64; 5] = viewsynth::refocus::manifest::DEFAULT_SCALES;

/// One Markdown table; every case also goes to `cases` (as `vulkan-fullscreen`, `vulkan-mesh`).
pub fn refocus_bench(vk: &Vk, sizes: &[(u32, u32)], repeats: usize, cases: &mut Vec<BenchCase>) -> Result<String> {
    let info = vk.info();
    let mut t = format!(
        "refocus benchmark on Vulkan device '{}' ({}, {}), {repeats} repeats, medians\n\n\
         | size | path | setup ms | ms / frame (5 scales) | ms / scale |\n|---|---|---|---|---|\n",
        info.name,
        info.device_type,
        if info.software { "software" } else { "hardware" }
    );
    for &(w, h) in sizes {
        let cam = scene::demo_camera(w, h);
        let (rgb, depth) = scene::render(&cam);
        let src = RefocusSource::new(rgb, depth, cam.k)?;
        let targets = TargetSpec {
            scales: SCALES.to_vec(),
            size: None,
            principal: None,
        }
        .targets(&cam)?;
        for method in [Method::Fullscreen, Method::Mesh] {
            let t0 = Instant::now();
            let mut r = Refocuser::new(
                &VkExecutor::device(vk)?,
                &src,
                &BreakRule::default(),
                method,
                OutputSet::default(),
                Conventions::default(),
            )?;
            r.render(&targets[0])?; // warm-up: pipeline compile on first use, target allocation
            let setup = t0.elapsed().as_secs_f64() * 1e3;
            let mut frame = Vec::new();
            for _ in 0..repeats.max(1) {
                let t0 = Instant::now();
                for target in &targets {
                    r.render(target)?;
                }
                frame.push(t0.elapsed().as_secs_f64() * 1e3);
            }
            let m = median(frame);
            let case = match method {
                Method::Mesh => "vulkan-mesh",
                Method::Fullscreen => "vulkan-fullscreen",
            };
            cases.push(BenchCase::new("refocus", case, format!("{w}x{h}"), Some(setup), m));
            writeln!(t, "| {w}x{h} | {case} | {setup:.1} | {m:.2} | {:.2} |", m / 5.0).expect("write to String");
        }
    }
    Ok(t)
}

/// A renderer's one frame, as a closure over its renderer.
type Frame<'a> = Box<dyn FnMut() -> Result<()> + 'a>;

/// Median ms of `repeats` frames after a warm-up (pipelines compile on first use, targets are
/// allocated).
fn time(repeats: usize, frame: Result<Frame>) -> Result<f64> {
    let mut frame = frame?;
    frame()?;
    let mut runs = Vec::new();
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        frame()?;
        runs.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(runs))
}

/// [`time`] of the frame `make` gives on each device.
fn both<'a>(
    devices: &'a [Device; 2],
    repeats: usize,
    make: impl Fn(&'a Device) -> Result<Frame<'a>>,
) -> Result<[f64; 2]> {
    Ok([time(repeats, make(&devices[0]))?, time(repeats, make(&devices[1]))?])
}

/// Every pass on both APIs from one run, same inputs, render + readback, medians of `repeats`
/// after a warm-up (pipelines, targets): refocus (5 focal scales a frame), cyclopean seed,
/// refine, splat-gather and forward warp, the census stereo matcher (both eyes), reproject
/// shift, shift-scan and 3-D gather, stitch's three methods (one stereo equirect) and the scene
/// ray tracer, at `width` x `height`. One Markdown table;
/// every case also goes to `cases` (`gl-<pass>`, `vulkan-<pass>`).
pub fn passes_bench(
    gpu: &viewsynth::gpu::Gpu,
    vk: &Vk,
    width: u32,
    height: u32,
    repeats: usize,
    cases: &mut Vec<BenchCase>,
) -> Result<String> {
    use viewsynth::cyclopean::scene_frame::{scene_frame, StereoRig};
    use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
    use viewsynth::cyclopean::{CyclopeanOutputs, CyclopeanParams, FrameDepth, Method as Cm};
    use viewsynth::reproject::render::Reprojector;
    use viewsynth::scene::gpu::{GlCamera, SceneRenderer};
    use viewsynth::stitch::render::StitchRenderer;
    use viewsynth::stitch::{faces::scene_faces, Method as Sm, OdsRig, Side, StitchParams};

    let devices = [Device::gl(gpu)?, VkExecutor::device(vk)?];
    let (frame, mid, _) = scene_frame(
        &StereoRig::demo(width, height),
        Conventions::default(),
        FrameDepth::Device,
    );
    let cam = scene::demo_camera(width, height);
    let (rgb, depth) = scene::render(&cam);
    let src = RefocusSource::new(rgb, depth, cam.k)?;
    let targets = TargetSpec {
        scales: SCALES.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&cam)?;
    let reproject_case =
        crate::eval::reproject::scene_cases(width, height, 0.064, Conventions::default(), FrameDepth::Device)?
            .into_iter()
            .next()
            .ok_or_else(|| viewsynth::Error::param("bench", "no reprojection case"))?;
    let rig = OdsRig::demo();
    let face = (width / 4).max(16);
    let faces = [Side::Left, Side::Right].map(|side| scene_faces(&rig, side, face, 110.0));
    let [left, right] = faces;
    let (left, right) = (left?, right?);
    let scene = viewsynth::scene::builtin("demo")?;
    let gl_cam = GlCamera {
        view: frame.left.view,
        proj: frame.left.proj,
        width,
        height,
        conv: Conventions::default(),
    };
    let seed = CyclopeanParams::seed(3.0);
    let refine = CyclopeanParams {
        method: Cm::Refine { steps: 3 },
        ..seed
    };

    let mut t = format!(
        "every pass, GL against Vulkan: {width}x{height} (refocus: 5 focal scales a frame; stitch: \
         {0}x{1} per eye from {face} px faces), render + readback, {repeats} repeats, medians; \
         Vulkan device '{2}'\n\n| pass | GL ms | Vulkan ms | Vulkan / GL |\n|---|---|---|---|\n",
        2 * width,
        width,
        vk.info().name
    );
    let mut row = |name: &str, ms: [f64; 2], cases: &mut Vec<BenchCase>| {
        writeln!(t, "| {name} | {:.2} | {:.2} | {:.2} |", ms[0], ms[1], ms[1] / ms[0]).expect("write to String");
        for (api, m) in ["gl", "vulkan"].iter().zip(ms) {
            cases.push(BenchCase::new(
                "passes",
                &format!("{api}-{name}"),
                format!("{width}x{height}"),
                None,
                m,
            ));
        }
    };
    for method in [Method::Fullscreen, Method::Mesh] {
        let rule = BreakRule::default();
        let ms = both(&devices, repeats, |d| {
            let mut r = Refocuser::new(d, &src, &rule, method, OutputSet::default(), Conventions::default())?;
            let targets = &targets;
            Ok(Box::new(move || targets.iter().try_for_each(|c| r.render(c).map(drop))) as Frame)
        })?;
        let name = match method {
            Method::Fullscreen => "refocus fullscreen",
            Method::Mesh => "refocus mesh",
        };
        row(name, ms, cases);
    }
    for (name, params) in [("cyclopean seed", seed), ("cyclopean refine 3", refine)] {
        let ms = both(&devices, repeats, |d| {
            let mut r = CyclopeanRenderer::new(d, &frame, params)?;
            let mid = &mid;
            Ok(Box::new(move || r.render(mid).map(drop)) as Frame)
        })?;
        row(name, ms, cases);
    }
    let ms = both(&devices, repeats, |d| {
        let mut r = SplatRenderer::new(d, &frame, SplatParams::default(), CyclopeanOutputs::default())?;
        let mid = &mid;
        Ok(Box::new(move || r.render(mid).map(drop)) as Frame)
    })?;
    row("cyclopean splat-gather", ms, cases);
    let ms = both(&devices, repeats, |d| {
        let mut r = viewsynth::cyclopean::forward::ForwardWarp::new(d, &frame, &BreakRule::default())?;
        let mid = &mid;
        Ok(Box::new(move || r.render(mid).map(drop)) as Frame)
    })?;
    row("cyclopean forward", ms, cases);
    // The stereo matcher a user without disparities runs first (both eyes, search 0-64 px).
    let (pair_l, pair_r, _) = crate::bench::matcher::synthetic_pair(width, height)?;
    let ms = both(&devices, repeats, |d| {
        let mut m = viewsynth::cyclopean::matcher::Matcher::new(d, width, height, 64)?;
        let (l, r) = (&pair_l, &pair_r);
        Ok(Box::new(move || m.estimate(l, r).map(drop)) as Frame)
    })?;
    row("census stereo matcher (0-64 px)", ms, cases);
    for params in crate::eval::reproject::methods() {
        let ms = both(&devices, repeats, |d| {
            let mut r = Reprojector::new(d, &reproject_case.source, &reproject_case.geometry, params)?;
            Ok(Box::new(move || r.render().map(drop)) as Frame)
        })?;
        row(&format!("reproject {}", params.method.label()), ms, cases);
    }
    for method in Sm::ALL {
        let params = StitchParams {
            method,
            overlap_deg: 10.0,
            width: 2 * width,
            height: width,
        };
        let ms = both(&devices, repeats, |d| {
            let mut r = StitchRenderer::new(d, &left, &right)?;
            Ok(Box::new(move || r.render(&params).map(drop)) as Frame)
        })?;
        row(&format!("stitch {}", method.label()), ms, cases);
    }
    let ms = both(&devices, repeats, |d| {
        let mut r = SceneRenderer::new(d, &scene)?;
        let cam = &gl_cam;
        Ok(Box::new(move || r.render(cam).map(drop)) as Frame)
    })?;
    row("scene ray tracer", ms, cases);
    Ok(t)
}
