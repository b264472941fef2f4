//! Benchmarks behind `viewsynth bench` (timings only; error against truth is in [`crate::eval`]).
//! Refocus: median milliseconds per frame (5 focal scales,
//! render + readback) for each GPU path, the f64 CPU reference as the in-run baseline, and the
//! whole job with file writing. Printed as a Markdown table; nothing here asserts a time.

pub mod batch;
pub mod codecs;
pub mod matcher;
pub mod passes;

use std::fmt::Write as _;
use std::time::Instant;
use viewsynth::convention::Conventions;
use viewsynth::error::Result;
use viewsynth::output::FileFormats;
use viewsynth::pass::Device;
use viewsynth::refocus::manifest::{self as job, TargetSpec};
use viewsynth::refocus::{reference, BreakRule, Method, OutputSet, RefocusSource, Refocuser};
use viewsynth::world;

use crate::stats::median;

/// One measured case, for `bench --json`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BenchCase {
    /// Capability measured (refocus, cyclopean, stitch).
    pub capability: String,
    /// The case within it (path, method, batch or single frame).
    pub case: String,
    /// Image size, `WxH`.
    pub size: String,
    /// Set-up (upload and shader compile) in milliseconds, where measured apart.
    pub setup_ms: Option<f64>,
    /// Median ms per frame (refocus: 5 focal scales; cyclopean: one middle frame; stitch: one
    /// stereo equirect).
    pub median_ms: f64,
}

impl BenchCase {
    /// A case with its measurements.
    pub fn new(capability: &str, case: &str, size: String, setup_ms: Option<f64>, median_ms: f64) -> Self {
        BenchCase {
            capability: capability.into(),
            case: case.into(),
            size,
            setup_ms,
            median_ms,
        }
    }
}

const SCALES: [f64; 5] = viewsynth::refocus::manifest::DEFAULT_SCALES;

/// Times both refocus paths at each size over the five focal scales (`repeats` runs, medians);
/// returns a Markdown table and appends each case to `cases`.
pub fn refocus_bench(
    device: &Device,
    sizes: &[(u32, u32)],
    repeats: usize,
    cases: &mut Vec<BenchCase>,
) -> Result<String> {
    let mut t = format!(
        "refocus benchmark on {} ({} repeats, medians)\n\n\
         | size | path | setup ms | ms / frame (5 scales) | ms / scale | job ms / frame incl. PNG+EXR+mask writes |\n\
         |---|---|---|---|---|---|\n",
        device.renderer(),
        repeats
    );
    let tmp = std::env::temp_dir().join(format!("viewsynth-bench-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).map_err(|e| viewsynth::Error::io(&tmp, e))?;
    for &(w, h) in sizes {
        let cam = world::demo_camera(w, h);
        let (rgb, depth) = world::render(&cam);
        let src = RefocusSource::new(rgb, depth, cam.k)?;
        let rule = BreakRule::default();
        let targets = TargetSpec {
            scales: SCALES.to_vec(),
            size: None,
            principal: None,
        }
        .targets(&cam)?;
        let outputs = OutputSet::default();
        for method in [Method::Fullscreen, Method::Mesh] {
            let t0 = Instant::now();
            let mut r = Refocuser::new(device, &src, &rule, method, outputs, Conventions::default())?;
            r.render(&targets[0])?; // warm-up: shader JIT and framebuffer allocation
            let setup = t0.elapsed().as_secs_f64() * 1e3;
            let mut frame = Vec::new();
            let mut with_io = Vec::new();
            for _ in 0..repeats {
                let t0 = Instant::now();
                for target in &targets {
                    r.render(target)?;
                }
                frame.push(t0.elapsed().as_secs_f64() * 1e3);
                let t0 = Instant::now();
                for (s, target) in SCALES.iter().zip(&targets) {
                    let out = r.render(target)?;
                    job::write_output(
                        &tmp,
                        *s,
                        &out,
                        &FileFormats {
                            outputs,
                            ..Default::default()
                        },
                    )?;
                }
                with_io.push(t0.elapsed().as_secs_f64() * 1e3);
            }
            let m = median(&frame);
            let name = match method {
                Method::Mesh => format!("GPU mesh ({} triangles)", r.triangle_count().unwrap_or(0)),
                Method::Fullscreen => "GPU full-screen".to_string(),
            };
            let case = match method {
                Method::Mesh => "device-mesh",
                Method::Fullscreen => "device-fullscreen",
            };
            cases.push(BenchCase::new("refocus", case, format!("{w}x{h}"), Some(setup), m));
            cases.push(BenchCase::new(
                "refocus",
                &format!("{case}-job-with-writes"),
                format!("{w}x{h}"),
                None,
                median(&with_io),
            ));
            writeln!(
                t,
                "| {w}x{h} | {name} | {setup:.1} | {m:.2} | {:.2} | {:.1} |",
                m / 5.0,
                median(&with_io)
            )
            .expect("write to String");
        }
        let mut cpu = Vec::new();
        for _ in 0..repeats.min(3) {
            let t0 = Instant::now();
            for target in &targets {
                std::hint::black_box(reference::refocus_reference(&src, &rule, target));
            }
            cpu.push(t0.elapsed().as_secs_f64() * 1e3);
        }
        let m = median(&cpu);
        cases.push(BenchCase::new(
            "refocus",
            "cpu-f64-reference",
            format!("{w}x{h}"),
            None,
            m,
        ));
        writeln!(
            t,
            "| {w}x{h} | CPU f64 reference (1 thread, baseline) | - | {m:.1} | {:.1} | - |",
            m / 5.0
        )
        .expect("write to String");
    }
    let _ = std::fs::remove_dir_all(&tmp);
    Ok(t)
}

/// Median ms per middle frame from two eyes of `width` x `height` for each cyclopean method.
pub fn cyclopean_bench(
    device: &Device,
    width: u32,
    height: u32,
    repeats: usize,
    cases: &mut Vec<BenchCase>,
) -> Result<String> {
    use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
    use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
    use viewsynth::stereo::FrameDepth;
    let rig = StereoRig::demo(width, height);
    let (frame, mid, _) = scene_frame(&rig, Conventions::default(), FrameDepth::Device);
    let mut t = format!(
        "cyclopean benchmark on {}: 2 eyes {width}x{height} -> middle {width}x{height} ({repeats} repeats, medians)\n\n\
         | method | setup ms | ms / middle frame (draw + readback) |\n|---|---|---|\n",
        device.renderer()
    );
    let mut record = |name: &str, (setup, m): (f64, f64)| {
        cases.push(BenchCase::new(
            "cyclopean",
            name,
            format!("{width}x{height}"),
            Some(setup),
            m,
        ));
        writeln!(t, "| {name} | {setup:.1} | {m:.1} |").expect("write to String");
    };
    for (name, params) in crate::eval::cyclopean::cyclopean_methods(3.0) {
        let timing = setup_and_median(
            repeats,
            || CyclopeanRenderer::new(device, &frame, params),
            |r| r.render(&mid),
        )?;
        record(name, timing);
    }
    let rule = viewsynth::refocus::BreakRule::default();
    let warp = setup_and_median(
        repeats,
        || viewsynth::cyclopean::forward::ForwardWarp::new(device, &frame, &rule),
        |w| w.render(&mid),
    )?;
    record(crate::eval::cyclopean::FORWARD_NAME, warp);
    let splat = setup_and_median(
        repeats,
        || {
            viewsynth::cyclopean::splat::SplatRenderer::new(
                device,
                &frame,
                viewsynth::cyclopean::splat::SplatParams::default(),
                viewsynth::stereo::gather::CyclopeanOutputs::default(),
            )
        },
        |r| r.render(&mid),
    )?;
    record(crate::eval::cyclopean::SPLAT_NAME, splat);
    // Dense disparities before rendering (what `--left-rgb/--right-rgb` runs between the matcher
    // and the render): both eyes of the synthetic pair, on the GPU matcher's disparities (its
    // occlusions and left-right misses unknown) and with a quarter of each eye cleared in 32 px
    // blocks (the 13-27 % a real pair leaves unknown, in regions as wide as a real pair's).
    let (left, right, _) = matcher::synthetic_pair(width, height)?;
    let (matched_left, matched_right) =
        viewsynth::stereo::matcher::Matcher::new(device, width, height, MATCHER_BENCH_MAX_DISPARITY)?
            .estimate(&left, &right)?;
    let unknown = |maps: [&viewsynth::io::DepthMap; 2]| {
        let n: usize = maps.iter().map(|m| m.data.iter().filter(|d| **d <= 0.0).count()).sum();
        100.0 * n as f64 / (2 * width as usize * height as usize) as f64
    };
    let cleared = |m: &viewsynth::io::DepthMap| {
        let mut m = m.clone();
        for (i, d) in m.data.iter_mut().enumerate() {
            let (bx, by) = ((i % width as usize) / 32, (i / width as usize) / 32);
            // One block in four, in a pattern that shifts per block row (no full columns).
            if (bx + 2 * by) % 4 == 0 {
                *d = 0.0;
            }
        }
        m
    };
    let blocks = [cleared(&matched_left), cleared(&matched_right)];
    for (what, maps) in [
        ("the matcher's disparities", [&matched_left, &matched_right]),
        ("a quarter cleared in 32 px blocks", [&blocks[0], &blocks[1]]),
    ] {
        let share = unknown(maps);
        let timing = setup_and_median(
            repeats,
            || viewsynth::stereo::densify::Densifier::new(device),
            |d| {
                use viewsynth::stereo::{densify::OtherEye, Eye};
                d.densify(maps[0], &left, OtherEye::LEFT)?;
                d.densify(
                    maps[1],
                    &right,
                    OtherEye {
                        eye: Eye::Right,
                        offset: 0,
                    },
                )
            },
        )?;
        record(
            &format!("densify, GPU pass (both eyes, {what}: {share:.1} % unknown)"),
            timing,
        );
    }
    // --fill on the default method's view: what a complete spectator frame adds to it.
    let (view, _) = viewsynth::cyclopean::splat::SplatRenderer::new(
        device,
        &frame,
        viewsynth::cyclopean::splat::SplatParams::default(),
        viewsynth::stereo::gather::CyclopeanOutputs::default(),
    )?
    .render(&mid)?;
    let fill = setup_and_median(
        repeats,
        || viewsynth::cyclopean::fill::Filler::new(device),
        |f| f.fill(&view, mid.width, mid.height),
    )?;
    record("--fill alone (on the splat-gather view; add to its row)", fill);
    // --sequence --fill also reprojects the last frame's view into this one first (the head
    // 3 cm away): the temporal accumulation's two passes and uploads, then its f64 twin.
    let mut moved = rig;
    moved.head.position[0] += 0.03;
    let (last, last_mid, _) = scene_frame(&moved, Conventions::default(), FrameDepth::Device);
    let (last, _) = viewsynth::cyclopean::splat::SplatRenderer::new(
        device,
        &last,
        viewsynth::cyclopean::splat::SplatParams::default(),
        viewsynth::stereo::gather::CyclopeanOutputs::default(),
    )?
    .render(&last_mid)?;
    use viewsynth::cyclopean::temporal::{Accumulator, DEPTH_TOLERANCE, FILL_ONLY};
    use viewsynth::cyclopean::temporal_reference::TemporalAccumulator;
    let conv = Conventions::default();
    // Each timed push reprojects the other frame's view: the two alternate.
    let temporal = setup_and_median(
        repeats,
        || Ok((Accumulator::new(device, FILL_ONLY, DEPTH_TOLERANCE, conv)?, false)),
        |(a, odd)| {
            *odd = !*odd;
            match odd {
                true => a.push(&view, &mid),
                false => a.push(&last, &last_mid),
            }
        },
    )?;
    record(
        "--sequence --fill: temporal accumulation before the fill (add to --fill's row)",
        temporal,
    );
    let twin = setup_and_median(
        repeats.min(3),
        || Ok((TemporalAccumulator::new(FILL_ONLY, DEPTH_TOLERANCE, conv)?, false)),
        |(a, odd)| {
            *odd = !*odd;
            match odd {
                true => a.push(&view, &mid),
                false => a.push(&last, &last_mid),
            }
        },
    )?;
    record("temporal accumulation, f64 twin (CPU, 1 thread)", twin);
    // The census matcher on a pair of this size: what a user without disparities pays before
    // any of the methods above (GPU pass, then its CPU twin as the baseline).
    let max_d = MATCHER_BENCH_MAX_DISPARITY;
    for (stages, confidence) in [(", GPU pass", false), (" + confidence stage, GPU pass", true)] {
        let timing = setup_and_median(
            repeats,
            || viewsynth::stereo::matcher::Matcher::new(device, width, height, max_d),
            |m| match confidence {
                false => m.estimate(&left, &right).map(drop),
                true => m.estimate_with_confidence(&left, &right).map(drop),
            },
        )?;
        record(
            &format!("census matcher{stages} (both eyes, search 0-{max_d} px)"),
            timing,
        );
    }
    let on_cpu = setup_and_median(
        repeats.min(3),
        || Ok(()),
        |_| viewsynth::stereo::matcher::estimate_disparities(&left, &right, max_d),
    )?;
    record(
        &format!("census matcher, CPU twin (1 thread, both eyes, search 0-{max_d} px)"),
        on_cpu,
    );
    // The semi-global matcher (issue 48) on the same pair and search, beside the census one.
    let sgm = viewsynth::stereo::matcher::MatcherMethod::Sgm;
    let timing = setup_and_median(
        repeats,
        || viewsynth::stereo::matcher::Matcher::with_method(device, width, height, max_d, sgm),
        |m| m.estimate(&left, &right).map(drop),
    )?;
    record(
        &format!("semi-global matcher, GPU pass (both eyes, search 0-{max_d} px)"),
        timing,
    );
    // The default two-image estimate: the semi-global disparities split into matched and
    // inferred by the census matcher's (stereo::trust), as cyclopean runs it: both matchers and
    // the trust stage in one run on the same grey levels and census codes (Matcher::checked).
    let timing = setup_and_median(
        repeats,
        || viewsynth::stereo::matcher::Matcher::checked(device, width, height, max_d),
        |m| m.estimate_checked(&left, &right, false).map(drop),
    )?;
    record(
        &format!("semi-global matcher checked by the census one, GPU (the default; both eyes, search 0-{max_d} px)"),
        timing,
    );
    let on_cpu = setup_and_median(
        repeats.min(3),
        || Ok(()),
        |_| sgm.estimate_reference(&left, &right, max_d),
    )?;
    record(
        &format!("semi-global matcher, CPU twin (1 thread, both eyes, search 0-{max_d} px)"),
        on_cpu,
    );
    Ok(t)
}

/// The matcher rows' search range at 720p: a tenth of the row (the report searches 64 px of the
/// 450 px Middlebury rows); the synthetic pair's disparities (20 and 60 px) lie inside.
pub const MATCHER_BENCH_MAX_DISPARITY: u32 = 128;

/// The stitch table's heading, naming the number of timed runs its medians are of.
fn stitch_table_head(renderer: &str, trace_ms: f64, setup_ms: f64, repeats: usize) -> String {
    format!(
        "stitch benchmark on {renderer} (6 faces 1024^2 per eye, overlap 10 deg, 4096x2048 per eye, top-bottom)\n\
         face ray tracing {trace_ms:.0} ms (CPU), upload + shader compile {setup_ms:.0} ms\n\n\
         | method | ms / stereo equirect (median of {repeats}) |\n|---|---|\n"
    )
}

/// (setup ms, median ms) of a pass: setup is `make` plus one warm-up `run` (shader JIT,
/// framebuffer allocation), then the median of `repeats` (at least 1) timed runs.
fn setup_and_median<R, T>(
    repeats: usize,
    make: impl FnOnce() -> Result<R>,
    mut run: impl FnMut(&mut R) -> Result<T>,
) -> Result<(f64, f64)> {
    let t0 = Instant::now();
    let mut r = make()?;
    run(&mut r)?;
    let setup = t0.elapsed().as_secs_f64() * 1e3;
    let mut runs = Vec::new();
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        run(&mut r)?;
        runs.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    Ok((setup, median(&runs)))
}

/// Benchmark: ms per 4096 x 2048 stereo equirect (both eyes, readback included) from 6 faces
/// of 1024 x 1024 per eye, overlap 10 deg, per method (median of `repeats`, at least 1, after a
/// warm-up). Not asserted.
pub fn stitch_bench(device: &Device, repeats: usize, cases: &mut Vec<BenchCase>) -> Result<String> {
    use viewsynth::stitch::faces::scene_faces;
    use viewsynth::stitch::render::StitchRenderer;
    use viewsynth::stitch::{Method, OdsRig, Side, StitchParams};
    let rig = OdsRig::demo();
    let (n, overlap) = (1024, 10.0);
    let t0 = Instant::now();
    let left = scene_faces(&rig, Side::Left, n, 90.0 + 2.0 * overlap)?;
    let right = scene_faces(&rig, Side::Right, n, 90.0 + 2.0 * overlap)?;
    let trace_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t0 = Instant::now();
    let mut r = StitchRenderer::new(device, &left, &right)?;
    let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
    let repeats = repeats.max(1);
    let mut t = stitch_table_head(&device.renderer(), trace_ms, setup_ms, repeats);
    for method in Method::ALL {
        let params = StitchParams {
            method,
            overlap_deg: overlap,
            width: 4096,
            height: 2048,
        };
        r.render(&params)?;
        let mut times = Vec::new();
        for _ in 0..repeats {
            times.push(r.render(&params)?.1.wall_ms);
        }
        let m = median(&times);
        cases.push(BenchCase::new(
            "stitch",
            method.label(),
            "4096x2048".into(),
            Some(setup_ms),
            m,
        ));
        let _ = writeln!(t, "| {} | {m:.1} |", method.label());
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_stitch_table_names_the_repeats_it_ran() {
        let head = super::stitch_table_head("llvmpipe", 1.0, 2.0, 3);
        assert!(head.contains("(median of 3)"), "{head}");
        assert!(!head.contains("median of 5"), "{head}");
    }
}
