//! Report rows of the stitch: error against the ray-traced ODS truth over the
//! seam band and the whole image, per method and overlap, with run times.

use crate::report::ReportRow;
use std::fmt::Write as _;
use viewsynth::error::Result;
use viewsynth::pass::Device;
use viewsynth::stitch::faces::scene_faces;
use viewsynth::stitch::render::StitchRenderer;
use viewsynth::stitch::score::{score_eyes, split_top_bottom};
use viewsynth::stitch::truth::ods_truth;
use viewsynth::stitch::{seam_band_mask, Method, OdsRig, Side, StitchParams};

/// Overlap widths (deg) evaluated; faces have FOV = 90 + 2 overlap.
pub const OVERLAPS_DEG: [f64; 3] = [5.0, 10.0, 20.0];

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Rows for `viewsynth report`: per overlap (5, 10, 20 deg) and method, one row over the seam
/// band and one over the whole image (PSNR against the ray-traced ODS truth, both eyes), with
/// the GPU time of the stereo stitch (median of `repeats` after a warm-up, readback included),
/// and SSIM over the same region. Faces 256 x 256, equirect 1024 x 512 per eye. Notes carry a
/// Markdown table with MAE, the seam band's edge error and sharpness ([`StitchScore`]) and its
/// PSNR split by truth distance.
pub fn stitch_rows(device: &Device, repeats: usize) -> Result<(Vec<ReportRow>, Vec<String>)> {
    let rig = OdsRig::demo();
    let (n, w, h) = (256, 1024, 512);
    let truth = [ods_truth(&rig, Side::Left, w, h)?, ods_truth(&rig, Side::Right, w, h)?];
    let mut rows = Vec::new();
    let mut table = String::from(
        "stitch (ODS, IPD 0.064, faces 256^2, equirect 1024x512 per eye, both eyes)\n\n\
         | overlap | method | seam PSNR dB | seam MAE | whole PSNR dB | whole MAE | ms | seam SSIM | whole SSIM | seam edge MAE | seam sharpness | seam near PSNR dB | seam far PSNR dB |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for overlap in OVERLAPS_DEG {
        let fov = 90.0 + 2.0 * overlap;
        let left = scene_faces(&rig, Side::Left, n, fov)?;
        let right = scene_faces(&rig, Side::Right, n, fov)?;
        let mut r = StitchRenderer::new(device, &left, &right)?;
        let band = seam_band_mask(w, h, overlap);
        for method in Method::ALL {
            let params = StitchParams {
                method,
                overlap_deg: overlap,
                width: w,
                height: h,
            };
            let (img, _) = r.render(&params)?;
            let mut times = Vec::new();
            for _ in 0..repeats.max(1) {
                times.push(r.render(&params)?.1.wall_ms);
            }
            let ms = median(times);
            let eyes = split_top_bottom(&img);
            let s = score_eyes([&eyes[0], &eyes[1]], [&truth[0], &truth[1]], &band);
            for (region, psnr, ssim) in [
                ("seam", s.seam_psnr_db, s.seam_ssim),
                ("whole", s.whole_psnr_db, s.whole_ssim),
            ] {
                let mut row = ReportRow::new(
                    "stitch",
                    "builtin:ods 1024x512",
                    method.label(),
                    format!("overlap={overlap}deg {region}"),
                    ms,
                );
                row.psnr_db = Some(psnr);
                row.ssim = Some(ssim);
                rows.push(row);
            }
            let _ = writeln!(
                table,
                "| {overlap} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {ms:.1} | {:.4} | {:.4} | {:.3} | {:.3} | {:.2} | {:.2} |",
                method.label(),
                s.seam_psnr_db,
                s.seam_mae,
                s.whole_psnr_db,
                s.whole_mae,
                s.seam_ssim,
                s.whole_ssim,
                s.seam_edge_mae,
                s.seam_sharpness,
                s.seam_near_psnr_db,
                s.seam_far_psnr_db
            );
        }
    }
    Ok((rows, vec![table]))
}
