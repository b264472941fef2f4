//! `viewsynth reproject`: runs the checked job and prints what it wrote.

use crate::host::CliHost;
use crate::text::{file_names, ms_text};
use anyhow::Result;
use viewsynth::job::reproject::{view_name, ReprojectJob};

pub(crate) fn reproject(job: &ReprojectJob) -> Result<()> {
    let r = job.run(&CliHost::default())?;
    for t in &r.targets {
        outln!(
            "{} -> {} ({}): {}x{}, coverage {:.2} %, render {} (setup + shader compile {:.1} ms)",
            view_name(r.from),
            view_name(t.to),
            r.method,
            r.width,
            r.height,
            t.coverage * 100.0,
            ms_text(&t.timing),
            t.setup_ms,
        );
    }
    outln!("wrote {} in {}", file_names(&r.written), job.out_dir().display());
    Ok(())
}
