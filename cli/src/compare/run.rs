//! `viewsynth compare`: runs the checked job, prints the summary (text or JSON) and fails with
//! exit 1, without an error line, when a threshold is broken.

use crate::host::CliHost;
use anyhow::Result;
use std::process::ExitCode;
use viewsynth::compare::{percent, DepthShare, ErrorDistribution};
use viewsynth::job::compare::{CompareJob, JsonOutput};

/// "median m, p99 a, p99.9 b, max c; over T: s %", values through `fmt`.
fn distribution(d: &ErrorDistribution, threshold: f64, fmt: impl Fn(f64) -> String) -> String {
    format!(
        "median {}, p99 {}, p99.9 {}, max {}; over {}: {}",
        fmt(d.median),
        fmt(d.p99),
        fmt(d.p999),
        fmt(d.max),
        fmt(threshold),
        d.share_over(threshold).map_or("-".into(), percent)
    )
}

/// A level count: whole for 8-bit colour, with the digits deeper colour needs otherwise.
fn levels(v: f64) -> String {
    if v.fract() == 0.0 {
        format!("{v}")
    } else {
        format!("{v:.4}")
    }
}

pub(crate) fn compare(job: &CompareJob) -> Result<ExitCode> {
    let r = job.run(&CliHost::default())?;
    let cmp = &r.comparison;
    if job.json() == Some(&JsonOutput::Stdout) {
        outln!("{}", r.json);
    } else {
        let over = if job.masked() { " (in the mask)" } else { "" };
        let bad = job.thresholds().bad;
        let bits = match cmp.color_bits {
            [8, 8] => String::new(),
            [a, b] => format!(" (compared at A {a}, B {b} bits per sample)"),
        };
        outln!(
            "colour: PSNR {:.2} dB, RMSE {:.4} levels, max difference {} levels over {} pixels{over}{bits}",
            cmp.psnr_db,
            cmp.color_rmse,
            levels(cmp.max_color_diff),
            cmp.pixels
        );
        outln!(
            "colour error (levels): {}",
            distribution(&cmp.color_error, bad.color_levels, levels)
        );
        if let Some(m) = cmp.flip_mean {
            let map = job
                .flip_map()
                .map_or(String::new(), |p| format!(" (map: {})", p.display()));
            let ssim = cmp.ssim.map_or("- (images under 11x11)".into(), |s| format!("{s:.4}"));
            outln!("FLIP: mean {m:.4}{map}; SSIM: {ssim}");
        }
        if let Some(p) = job.diff() {
            outln!(
                "diff: {} = |A - B| x {:.3} (the largest difference is white)",
                p.display(),
                cmp.diff_scale
            );
        }
        if let Some(v) = cmp.depth_valid {
            let errors = match (cmp.depth_max_abs, cmp.depth_max_rel) {
                (Some(abs), Some(rel)) => format!("max abs {abs:.3e} m, max rel {rel:.3e}; "),
                _ => String::new(),
            };
            outln!(
                "depth: {errors}valid in only one: {} pixels (A only {}, B only {}; valid in both {})",
                v.one_side(),
                v.a_only,
                v.b_only,
                v.both
            );
        }
        if let Some(d) = &cmp.depth_rel_error {
            outln!(
                "depth relative error: {}",
                distribution(d, bad.depth_rel, |v| format!("{v:.2e}"))
            );
        }
        // The gate's share: a pixel valid on one side only counts as bad.
        if let Some(d @ DepthShare { share: Some(s), .. }) = cmp.depth_bad {
            outln!(
                "depth bad share: {} ({} over {:.2e} + {} valid in only one, of {} pixels with depth)",
                percent(s),
                d.over_threshold,
                d.threshold,
                d.one_side,
                d.denominator
            );
        }
        for s in &cmp.suspicions {
            outln!("suspicion: {s}");
        }
    }
    if r.broken.is_empty() {
        return Ok(ExitCode::SUCCESS);
    }
    for b in &r.broken {
        errln!("threshold broken: {b}");
    }
    // Exit 1 means "A and B differ beyond the limits" for CI, whatever other errors map to.
    Ok(ExitCode::FAILURE)
}
