//! A stitched stereo equirect scored against the ray-traced ODS truth of both eyes: what
//! `viewsynth stitch --scene` prints and the report's stitch rows are built from.

use crate::io::RgbImage;
use crate::metrics;
use crate::stitch::truth::OdsTruth;

/// Truth ray distance (m) below which a seam pixel counts as near in [`StitchScore`].
pub const NEAR_DISTANCE: f64 = 3.0;

/// Colour error of a stereo equirect against the truth of both eyes (all averaged over both).
///
/// Besides PSNR and MAE: SSIM (Wang et al. 2004 on BT.601 luma, [`viewsynth::ssim`], windows
/// centred in the region, unrounded colour); `edge_mae`, the mean absolute difference of the luma
/// gradients (central differences, longitude wrapping), which a misplaced or doubled edge raises;
/// and `sharpness`, the summed luma gradient magnitude over the truth's (1 = as crisp as the
/// truth; an average of two displaced images, the "double image" of a plain blend, is below 1).
/// The seam band is also split by the truth's ray distance: near (a hit closer than
/// [`NEAR_DISTANCE`]) and far (farther hits and background).
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct StitchScore {
    /// Colour PSNR over the seam band, dB.
    pub seam_psnr_db: f64,
    /// Mean absolute colour error over the seam band, 8-bit levels.
    pub seam_mae: f64,
    /// Colour PSNR over the whole equirect, dB.
    pub whole_psnr_db: f64,
    /// Mean absolute colour error over the whole equirect, 8-bit levels.
    pub whole_mae: f64,
    /// Pixels in the seam band of one eye.
    pub seam_pixels: usize,
    /// Luma SSIM over the seam band (NaN when no window fits).
    pub seam_ssim: f64,
    /// Luma SSIM over the whole equirect (NaN when no window fits).
    pub whole_ssim: f64,
    /// Mean absolute luma-gradient difference over the seam band (raised by misplaced or doubled edges).
    pub seam_edge_mae: f64,
    /// Summed luma-gradient magnitude over the seam band, relative to the truth's (1 = as crisp).
    pub seam_sharpness: f64,
    /// Colour PSNR over the seam pixels whose truth hit is nearer than [`NEAR_DISTANCE`], dB.
    pub seam_near_psnr_db: f64,
    /// Colour PSNR over the remaining seam pixels (farther hits and background), dB.
    pub seam_far_psnr_db: f64,
    /// Near seam pixels of one eye.
    pub seam_near_pixels: usize,
}

fn luma(c: &[f64; 3]) -> f64 {
    0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]
}

/// Luma gradient (d/du with longitude wrap, d/dv clamped) at pixel i of a w x h plane.
fn gradient(y: &[f64], w: usize, h: usize, i: usize) -> [f64; 2] {
    let (u, v) = (i % w, i / w);
    let (l, r) = (v * w + (u + w - 1) % w, v * w + (u + 1) % w);
    let (t, b) = (v.saturating_sub(1) * w + u, (v + 1).min(h - 1) * w + u);
    [0.5 * (y[r] - y[l]), 0.5 * (y[b] - y[t])]
}

/// Score eye images (colour per pixel, 0..255) against the truth; `band` is one eye's mask.
pub fn score_eyes(eyes: [&[[f64; 3]]; 2], truth: [&OdsTruth; 2], band: &[bool]) -> StitchScore {
    // Regions: 0 seam, 1 whole, 2 seam near, 3 seam far.
    let (mut sq, mut ab, mut n) = ([0.0; 4], [0.0; 4], [0usize; 4]);
    let (mut edge, mut grad_out, mut grad_truth) = (0.0, 0.0, 0.0);
    let (mut ssim, mut n_ssim) = ([0.0; 2], [0usize; 2]);
    for (eye, t) in eyes.iter().zip(truth) {
        let (w, h) = (t.width as usize, t.height as usize);
        for (i, (c, tc)) in eye.iter().zip(&t.color).enumerate() {
            let (mut s, mut a) = (0.0, 0.0);
            for k in 0..3 {
                let d = c[k] - tc[k];
                s += d * d;
                a += d.abs();
            }
            let near = t.distance[i] > 0.0 && t.distance[i] < NEAR_DISTANCE;
            for (r, inside) in [(0, band[i]), (1, true), (2, band[i] && near), (3, band[i] && !near)] {
                if inside {
                    sq[r] += s;
                    ab[r] += a;
                    n[r] += 1;
                }
            }
        }
        let (yo, yt): (Vec<f64>, Vec<f64>) = eye.iter().zip(&t.color).map(|(c, tc)| (luma(c), luma(tc))).unzip();
        for i in (0..w * h).filter(|&i| band[i]) {
            let (go, gt) = (gradient(&yo, w, h, i), gradient(&yt, w, h, i));
            edge += 0.5 * ((go[0] - gt[0]).abs() + (go[1] - gt[1]).abs());
            grad_out += go[0].hypot(go[1]);
            grad_truth += gt[0].hypot(gt[1]);
        }
        for (r, mask) in [(0, Some(band)), (1, None)] {
            if let Some(v) = crate::ssim::ssim_luma_planes(&yo, &yt, w, h, mask) {
                ssim[r] += v;
                n_ssim[r] += 1;
            }
        }
    }
    let mse = |r: usize| sq[r] / (3 * n[r].max(1)) as f64;
    let mae = |r: usize| ab[r] / (3 * n[r].max(1)) as f64;
    let ssim_mean = |r: usize| {
        if n_ssim[r] > 0 {
            ssim[r] / n_ssim[r] as f64
        } else {
            f64::NAN
        }
    };
    StitchScore {
        seam_psnr_db: metrics::psnr_from_mse(mse(0)),
        seam_mae: mae(0),
        whole_psnr_db: metrics::psnr_from_mse(mse(1)),
        whole_mae: mae(1),
        seam_pixels: n[0] / 2,
        seam_ssim: ssim_mean(0),
        whole_ssim: ssim_mean(1),
        seam_edge_mae: edge / n[0].max(1) as f64,
        seam_sharpness: grad_out / grad_truth.max(1e-30),
        seam_near_psnr_db: metrics::psnr_from_mse(mse(2)),
        seam_far_psnr_db: metrics::psnr_from_mse(mse(3)),
        seam_near_pixels: n[2] / 2,
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
