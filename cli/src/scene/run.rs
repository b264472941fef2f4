//! `viewsynth scene`: runs the checked job and prints what it wrote.

use crate::host::CliHost;
use anyhow::Result;
use viewsynth::job::scene::SceneJob;

pub(crate) fn scene(job: &SceneJob) -> Result<()> {
    let r = job.run(&CliHost::default())?;
    let (width, height) = r.size;
    for (eye, ms) in &r.eyes {
        outln!("{eye}: {width}x{height} in {ms:.1} ms");
    }
    if let Some((n, fov, ms)) = r.faces {
        outln!(
            "cube faces: 12 of {n}x{n}, fov {fov} deg, ray-traced in {ms:.0} ms (read by `viewsynth stitch --faces {} --fov {fov}`)",
            job.out_dir().display()
        );
    }
    if r.frames > 1 {
        outln!(
            "scene '{}': {} frames written to {} (sequence.json feeds `viewsynth cyclopean --sequence`)",
            r.name,
            r.frames,
            job.out_dir().display()
        );
        return Ok(());
    }
    outln!(
        "scene '{}' written to {} (cameras.json feeds `viewsynth cyclopean`)",
        r.name,
        job.out_dir().display()
    );
    Ok(())
}
