//! `viewsynth manifest`: writes the manifest and says what was paired.

use anyhow::Result;
use viewsynth::job::manifest::TumManifestJob;

pub(crate) fn manifest(job: &TumManifestJob) -> Result<()> {
    let r = job.run()?;
    let (rgb, depth) = r.listed;
    outln!(
        "{} colour, {} depth frames listed; paired {} within {} s; wrote {}",
        rgb,
        depth,
        r.frames,
        job.max_difference,
        job.out.display()
    );
    Ok(())
}
