//! `viewsynth stress`: sweeps, prints the table, writes the JSON rows, fails on a failing case.

use crate::host::CliHost;
use anyhow::Result;
use viewsynth_lab::job::stress::StressJob;

pub(crate) fn stress(job: &StressJob) -> Result<()> {
    let rows = job.run(&CliHost::default())?;
    outln!("{}", viewsynth_lab::stress::table(&rows));
    job.write_json(&rows)?;
    Ok(StressJob::outcome(&rows)?)
}
