//! `viewsynth report`: measures, prints a summary per method (the whole report with --verbose)
//! and lists the files.

use crate::host::CliHost;
use anyhow::Result;
use viewsynth_lab::job::report::ReportJob;
use viewsynth_lab::report::WrittenReport;

pub(crate) fn report(job: &ReportJob, verbose: bool) -> Result<()> {
    let written = job.run(&CliHost::default())?;
    print_report(&written, verbose)
}

/// The summary (or, verbose, the Markdown file as written) and the files. The full table is
/// hundreds of lines: a terminal gets the medians, the file gets everything.
pub(crate) fn print_report(written: &WrittenReport, verbose: bool) -> Result<()> {
    match written.markdown() {
        Some(md) if verbose => outln!("{}", std::fs::read_to_string(md)?),
        _ => out!("{}", written.report.summary()),
    }
    let names = crate::text::file_names(&written.files);
    match written.files.first().and_then(|f| f.parent()) {
        Some(dir) if !verbose => outln!(
            "wrote {names} in {} (the full table: report.md, or --verbose)",
            dir.display()
        ),
        Some(dir) => outln!("wrote {names} in {}", dir.display()),
        None => {}
    }
    Ok(())
}
