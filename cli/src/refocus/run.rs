//! `viewsynth refocus`: runs the checked job and prints what it wrote.

use crate::host::CliHost;
use anyhow::Result;
use viewsynth::job::refocus::{RefocusBatchJob, RefocusCommand, RefocusJob};
use viewsynth::refocus::manifest::scale_label;

pub(crate) fn refocus(command: RefocusCommand) -> Result<()> {
    match command {
        RefocusCommand::Frame(job) => frame(&job),
        RefocusCommand::Batch(job) => batch(&job),
    }
}

fn frame(job: &RefocusJob) -> Result<()> {
    let report = job.run(&CliHost::default())?;
    for e in &report.manifest.outputs {
        outln!(
            "s={:<6} fx'={:<9.3} {}x{} coverage {:>6.2}%  render {:>7.2} ms",
            scale_label(e.scale),
            e.intrinsics.fx,
            e.width,
            e.height,
            e.files.coverage.unwrap_or(f64::NAN) * 100.0,
            e.render_ms
        );
        if let (Some(n @ 1..), Some(units)) = (e.files.depth_png16_clipped, e.files.depth_png16_units_per_metre) {
            // Written as invalid (0), never as a wrong depth; said here so it is not only in the manifest.
            errln!(
                "warning: s={}: {n} valid pixels lie beyond {:.3} m, the most png16 holds at --depth-png-scale {units}: \
                 written as 0 (invalid); a smaller --depth-png-scale keeps them",
                scale_label(e.scale),
                f64::from(u16::MAX) / units
            );
        }
    }
    outln!(
        "wrote {} targets; manifest {}",
        report.manifest.outputs.len(),
        report.manifest_path.display()
    );
    Ok(())
}

fn batch(job: &RefocusBatchJob) -> Result<()> {
    let report = job.run(&CliHost::default())?;
    let summary = &report.summary;
    let shard_note = match report.shard {
        Some(s) => format!(
            " (shard {}/{}: {} frames belong to other shards)",
            s.index, s.count, summary.other_shards
        ),
        None => String::new(),
    };
    outln!(
        "{} frames{shard_note}: {} rendered, {} already done (resume), {} failed; {:.1} s, {:.2} frames/s",
        report.frames,
        summary.rendered,
        summary.skipped,
        summary.failed.len(),
        summary.wall_s,
        summary.rendered as f64 / summary.wall_s.max(1e-9)
    );
    match &summary.index {
        Some(p) => println!("index: {}", p.display()),
        None => println!("index: this shard's part written; the last shard (or `viewsynth index`) joins them"),
    }
    for (name, w) in &summary.depth_warnings {
        errln!("warning: frame {name}: depth {w}; check its depth_scale (or --depth-scale) and sun_bit_rotate");
    }
    let warned: std::collections::BTreeSet<&str> =
        summary.depth_warnings.iter().map(|(name, _)| name.as_str()).collect();
    if !warned.is_empty() {
        errln!(
            "warning: {} of {} frames rendered or tried have depth that looks wrongly decoded (listed above)",
            warned.len(),
            summary.rendered + summary.failed.len()
        );
    }
    for (name, e) in &summary.failed {
        errln!("failed: {name}: {e}");
    }
    Ok(report.outcome()?)
}
