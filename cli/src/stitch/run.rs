//! `viewsynth stitch`: runs the checked job and prints what it did.

use crate::host::CliHost;
use crate::text::ms_text;
use anyhow::Result;
use viewsynth::job::stitch::StitchJob;

pub(crate) fn stitch(job: &StitchJob) -> Result<()> {
    let r = job.run(&CliHost::default())?;
    outln!("faces: {}, FOV {} deg, in {:.0} ms", r.source, r.fov, r.faces_ms);
    outln!("upload + shader compile {:.1} ms", r.setup_ms);
    outln!(
        "stitch ({}, overlap {} deg, IPD {} m): {}x{} per eye, top-bottom {}x{}, render {}",
        r.params.method.label(),
        r.params.overlap_deg,
        r.rig.ipd,
        r.params.width,
        r.params.height,
        r.image_size.0,
        r.image_size.1,
        ms_text(&r.timing)
    );
    if let Some(t) = &r.truth {
        let s = &t.score;
        outln!(
            "vs ODS ground truth (ray-traced in {:.0} ms): seam band PSNR {:.2} dB (MAE {:.2}, {} px per eye), whole image PSNR {:.2} dB (MAE {:.2})",
            t.truth_ms, s.seam_psnr_db, s.seam_mae, s.seam_pixels, s.whole_psnr_db, s.whole_mae
        );
    }
    for p in &r.written {
        outln!("wrote {}", p.display());
    }
    Ok(())
}
