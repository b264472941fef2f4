//! `viewsynth bench --with-vulkan`: the refocus timings of `bench.rs` (built-in scene, 5 focal
//! scales, render + readback, medians) and its cyclopean gather timings (seed and refine methods,
//! draw + readback) on the Vulkan device, for the GL-vs-Vulkan comparison.

use super::context::Vk;
use super::executor::VkExecutor;
use super::refocus::VkRefocuser;
use crate::bench::BenchCase;
use crate::bench_batch::median;
use crate::convention::Conventions;
use crate::cyclopean::render::CyclopeanRenderer;
use crate::error::Result;
use crate::refocus::job::TargetSpec;
use crate::refocus::{BreakRule, Method, OutputSet, RefocusSource};
use crate::scene;
use std::fmt::Write as _;
use std::time::Instant;

const SCALES: [f64; 5] = [0.5, 0.75, 1.0, 1.5, 2.0];

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
            let mut r = VkRefocuser::new(
                vk,
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

/// The gather methods of `bench::cyclopean_bench` (two eyes of `width` x `height`, device depth,
/// default conventions) on the Vulkan device: one Markdown table; every case also goes to
/// `cases` as `vulkan-<method>`.
pub fn cyclopean_bench(vk: &Vk, width: u32, height: u32, repeats: usize, cases: &mut Vec<BenchCase>) -> Result<String> {
    use crate::cyclopean::scene_frame::{scene_frame, StereoRig};
    use crate::cyclopean::FrameDepth;
    let (frame, mid, _) = scene_frame(
        &StereoRig::demo(width, height),
        Conventions::default(),
        FrameDepth::Device,
    );
    let mut t = format!(
        "cyclopean benchmark on Vulkan device '{}': 2 eyes {width}x{height} -> middle {width}x{height} \
         ({repeats} repeats, medians)\n\n| method | setup ms | ms / middle frame (draw + readback) |\n|---|---|---|\n",
        vk.info().name
    );
    for (name, params) in crate::eval::cyclopean::cyclopean_methods(3.0) {
        let t0 = Instant::now();
        let mut r = CyclopeanRenderer::new(&VkExecutor::device(vk)?, &frame, params)?;
        r.render(&mid)?; // warm-up: pipeline compile on first use, target allocation
        let setup = t0.elapsed().as_secs_f64() * 1e3;
        let mut runs = Vec::new();
        for _ in 0..repeats.max(1) {
            let t0 = Instant::now();
            r.render(&mid)?;
            runs.push(t0.elapsed().as_secs_f64() * 1e3);
        }
        let m = median(runs);
        let case = format!("vulkan-{name}");
        writeln!(t, "| {case} | {setup:.1} | {m:.1} |").expect("write to String");
        cases.push(BenchCase::new(
            "cyclopean",
            &case,
            format!("{width}x{height}"),
            Some(setup),
            m,
        ));
    }
    Ok(t)
}
