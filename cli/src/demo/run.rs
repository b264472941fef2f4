//! `viewsynth demo`: renders everything and prints a summary (the whole report with --verbose).

use crate::host::CliHost;
use anyhow::Result;
use viewsynth_lab::job::report::DemoJob;

pub(crate) fn demo(job: &DemoJob, verbose: bool) -> Result<()> {
    let written = job.run(&CliHost::default())?;
    crate::report::run::print_report(&written, verbose)?;
    outln!(
        "demo outputs in {}: fullscreen/ and mesh/ (refocus at 5 scales, refocus_check.md), \
         cyclopean/, reproject/, stitch/",
        job.out_dir.display()
    );
    Ok(())
}
