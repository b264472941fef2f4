//! `viewsynth bench`: measures and prints the tables or one JSON object.

use crate::host::CliHost;
use anyhow::Result;
use viewsynth_lab::job::bench::{BenchJob, BenchReport};

pub(crate) fn bench(job: &BenchJob, json: bool) -> Result<()> {
    match job.run(&CliHost::default())? {
        BenchReport::Batch(report) if json => outln!("{}", serde_json::to_string_pretty(&report)?),
        BenchReport::Batch(report) => outln!("{}", report.table()),
        BenchReport::Frames {
            renderer,
            cases,
            vulkan_device,
            ..
        } if json => {
            let report = serde_json::json!({ "renderer": renderer, "vulkan_device": vulkan_device, "cases": cases });
            outln!("{}", serde_json::to_string_pretty(&report)?);
        }
        BenchReport::Frames { tables, .. } => {
            for t in tables {
                outln!("{t}");
            }
        }
    }
    Ok(())
}
