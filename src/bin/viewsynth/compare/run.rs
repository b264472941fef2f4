//! `viewsynth compare`: runs the checked job, prints the summary (text or JSON) and fails with
//! exit 1, without an error line, when a threshold is broken.

use crate::host::CliHost;
use anyhow::Result;
use std::process::ExitCode;
use viewsynth::job::compare::{CompareJob, JsonOutput};

pub(crate) fn compare(job: &CompareJob) -> Result<ExitCode> {
    let r = job.run(&CliHost::default())?;
    let cmp = &r.comparison;
    if job.json() == Some(&JsonOutput::Stdout) {
        outln!("{}", r.json);
    } else {
        let over = if job.masked() { " (in the mask)" } else { "" };
        outln!(
            "colour: PSNR {:.2} dB, RMSE {:.4} levels, max difference {} levels over {} pixels{over}",
            cmp.psnr_db,
            cmp.color_rmse,
            cmp.max_color_diff,
            cmp.pixels
        );
        if let Some(p) = job.diff() {
            outln!(
                "diff: {} = |A - B| x {:.3} (the largest difference is white)",
                p.display(),
                cmp.diff_scale
            );
        }
        if let (Some(abs), Some(rel), Some(d)) = (cmp.depth_max_abs, cmp.depth_max_rel, cmp.mask_disagreement) {
            outln!("depth: max abs {abs:.3e} m, max rel {rel:.3e}; valid in only one: {d} pixels");
        }
        if let Some(s) = &cmp.suspicion {
            outln!("suspicion: {s}");
        }
    }
    if r.broken.is_empty() {
        return Ok(ExitCode::SUCCESS);
    }
    for b in &r.broken {
        eprintln!("threshold broken: {b}");
    }
    // Exit 1 means "A and B differ beyond the limits" for CI, whatever other errors map to.
    Ok(ExitCode::FAILURE)
}
