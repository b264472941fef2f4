//! Report rows and the benchmark of the stitch: error against the ray-traced ODS truth over the
//! seam band and the whole image, per method and overlap, with run times.

use super::faces::scene_faces;
use super::render::StitchRenderer;
use super::truth::{ods_truth, OdsTruth};
use super::{seam_band_mask, Method, OdsRig, Side, StitchParams};
use crate::error::Result;
use crate::gpu::Gpu;
use crate::io::RgbImage;
use crate::metrics;
use crate::report::ReportRow;
use std::fmt::Write as _;
use std::time::Instant;

/// Overlap widths (deg) evaluated; faces have FOV = 90 + 2 overlap.
pub const OVERLAPS_DEG: [f64; 3] = [5.0, 10.0, 20.0];

/// Colour error of a stereo equirect against the truth of both eyes.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct StitchScore {
    pub seam_psnr_db: f64,
    pub seam_mae: f64,
    pub whole_psnr_db: f64,
    pub whole_mae: f64,
    pub seam_pixels: usize,
}

/// Score eye images (colour per pixel, 0..255) against the truth; `band` is one eye's mask.
pub fn score_eyes(eyes: [&[[f64; 3]]; 2], truth: [&OdsTruth; 2], band: &[bool]) -> StitchScore {
    let (mut sq, mut ab, mut n) = ([0.0; 2], [0.0; 2], [0usize; 2]);
    for (eye, t) in eyes.iter().zip(truth) {
        for (i, (c, tc)) in eye.iter().zip(&t.color).enumerate() {
            let (mut s, mut a) = (0.0, 0.0);
            for k in 0..3 {
                let d = c[k] - tc[k];
                s += d * d;
                a += d.abs();
            }
            for (r, inside) in [(0, band[i]), (1, true)] {
                if inside {
                    sq[r] += s;
                    ab[r] += a;
                    n[r] += 1;
                }
            }
        }
    }
    let mse = |r: usize| sq[r] / (3 * n[r].max(1)) as f64;
    let mae = |r: usize| ab[r] / (3 * n[r].max(1)) as f64;
    StitchScore {
        seam_psnr_db: metrics::psnr_from_mse(mse(0)),
        seam_mae: mae(0),
        whole_psnr_db: metrics::psnr_from_mse(mse(1)),
        whole_mae: mae(1),
        seam_pixels: n[0] / 2,
    }
}

/// Split a top-bottom 8-bit stereo equirect into per-eye colour lists.
pub fn split_top_bottom(tb: &RgbImage) -> [Vec<[f64; 3]>; 2] {
    let half = (tb.width * tb.height / 2) as usize;
    let px: Vec<[f64; 3]> = tb
        .data
        .chunks_exact(3)
        .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64])
        .collect();
    [px[..half].to_vec(), px[half..].to_vec()]
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Rows for `viewsynth report`: per overlap (5, 10, 20 deg) and method, one row over the seam
/// band and one over the whole image (PSNR against the ray-traced ODS truth, both eyes), with
/// the GPU time of the stereo stitch (median of `repeats` after a warm-up, readback included).
/// Faces 256 x 256, equirect 1024 x 512 per eye. Notes carry a Markdown table with MAE.
pub fn stitch_rows(gpu: &Gpu, repeats: usize) -> Result<(Vec<ReportRow>, Vec<String>)> {
    let rig = OdsRig::demo();
    let (n, w, h) = (256, 1024, 512);
    let truth = [ods_truth(&rig, Side::Left, w, h)?, ods_truth(&rig, Side::Right, w, h)?];
    let mut rows = Vec::new();
    let mut table = String::from(
        "stitch (ODS, IPD 0.064, faces 256^2, equirect 1024x512 per eye, both eyes)\n\n\
         | overlap | method | seam PSNR dB | seam MAE | whole PSNR dB | whole MAE | ms |\n|---|---|---|---|---|---|---|\n",
    );
    for overlap in OVERLAPS_DEG {
        let fov = 90.0 + 2.0 * overlap;
        let left = scene_faces(&rig, Side::Left, n, fov)?;
        let right = scene_faces(&rig, Side::Right, n, fov)?;
        let mut r = StitchRenderer::new(gpu, &left, &right)?;
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
            for (region, psnr) in [("seam", s.seam_psnr_db), ("whole", s.whole_psnr_db)] {
                let mut row = ReportRow::new(
                    "stitch",
                    "builtin:ods 1024x512",
                    method.label(),
                    format!("overlap={overlap}deg {region}"),
                    ms,
                );
                row.psnr_db = Some(psnr);
                rows.push(row);
            }
            let _ = writeln!(
                table,
                "| {overlap} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {ms:.1} |",
                method.label(),
                s.seam_psnr_db,
                s.seam_mae,
                s.whole_psnr_db,
                s.whole_mae
            );
        }
    }
    Ok((rows, vec![table]))
}

/// Benchmark: ms per 4096 x 2048 stereo equirect (both eyes, readback included) from 6 faces
/// of 1024 x 1024 per eye, overlap 10 deg, per method (median of 5 after a warm-up). Not asserted.
pub fn stitch_bench(gpu: &Gpu) -> Result<String> {
    let rig = OdsRig::demo();
    let (n, overlap) = (1024, 10.0);
    let t0 = Instant::now();
    let left = scene_faces(&rig, Side::Left, n, 90.0 + 2.0 * overlap)?;
    let right = scene_faces(&rig, Side::Right, n, 90.0 + 2.0 * overlap)?;
    let trace_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t0 = Instant::now();
    let mut r = StitchRenderer::new(gpu, &left, &right)?;
    let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut t = format!(
        "stitch benchmark on {} (6 faces 1024^2 per eye, overlap 10 deg, 4096x2048 per eye, top-bottom)\n\
         face ray tracing {trace_ms:.0} ms (CPU), upload + shader compile {setup_ms:.0} ms\n\n\
         | method | ms / stereo equirect (median of 5) |\n|---|---|\n",
        gpu.info().renderer
    );
    for method in Method::ALL {
        let params = StitchParams {
            method,
            overlap_deg: overlap,
            width: 4096,
            height: 2048,
        };
        r.render(&params)?;
        let mut times = Vec::new();
        for _ in 0..5 {
            times.push(r.render(&params)?.1.wall_ms);
        }
        let _ = writeln!(t, "| {} | {:.1} |", method.label(), median(times));
    }
    Ok(t)
}
