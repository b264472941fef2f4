//! `viewsynth cyclopean`: runs the checked job and prints what it wrote.

use super::args::CyclopeanRun;
use crate::host::CliHost;
use crate::text::file_names;
use anyhow::Result;

pub(crate) fn cyclopean(job: &CyclopeanRun) -> Result<()> {
    let host = CliHost::default();
    let (r, out_dir) = match job {
        CyclopeanRun::Pair(job) => (job.run(&host)?, job.out_dir()),
        CyclopeanRun::Sequence(job) => (job.run(&host)?, job.out_dir()),
    };
    if r.frames > 1 {
        outln!(
            "{} views {}x{}: {:.1} % valid on average, render {:.1} ms in all; wrote {} files in {}",
            r.frames,
            r.width,
            r.height,
            r.valid_fraction * 100.0,
            r.render_ms,
            r.written.len(),
            out_dir.display()
        );
        return Ok(());
    }
    outln!(
        "view {}x{}: {:.1} % valid, render {:.1} ms; wrote {} in {}",
        r.width,
        r.height,
        r.valid_fraction * 100.0,
        r.render_ms,
        file_names(&r.written),
        out_dir.display()
    );
    Ok(())
}
