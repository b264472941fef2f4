//! Which disparity scale the views agree with. A rectified pair's disparity is right when
//! shifting each view by it reproduces the other: left (x, y) is right (x - d, y), right (x, y)
//! is left (x + d, y). Read with the wrong `--disparity-scale` (Middlebury 2003 stores 4 units a
//! pixel) the shift lands elsewhere and the colours stop matching; at the right one they match
//! several times better than at any power-of-two neighbour (Cones: mean grey difference 6.6 at
//! scale 4, 38.5 at 1; Teddy 5.4 at 4, 30.4 at 2). A subsample of the pixels says as much as all of them.

use crate::io::{DepthMap, RgbImage};

/// Raw units per pixel tried beside the scale given: the powers of two datasets use (Middlebury
/// 2003: 4, KITTI: 256, float maps: 1) and the halves a doubled map would need.
pub const CANDIDATE_SCALES: [f64; 11] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0];

/// Another scale fits only when its error is at most this share of the given scale's:
/// neighbouring wrong scales are 4x worse on Cones and Teddy, so 0.5 leaves room for noise.
pub const CLEARLY_BETTER: f64 = 0.5;

/// A scale is judged only when at least this share of the valid samples lands inside the
/// other view (a too-small scale shifts most pixels out of it).
const MIN_INSIDE: f64 = 0.5;

/// About this many samples per eye (every k-th row and column).
const SAMPLES: usize = 16_384;

/// The photometric check's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleFit {
    /// The scale the maps were decoded with (raw units per pixel).
    pub given: f64,
    /// Mean absolute grey difference (0-255) at the given scale; None when most shifts leave
    /// the other view.
    pub given_error: Option<f64>,
    /// The candidate with the smallest error, and that error.
    pub best: (f64, f64),
}

impl ScaleFit {
    /// The scale that fits clearly better than the given one, if any.
    pub fn better(&self) -> Option<f64> {
        let (scale, error) = self.best;
        let clearly = match self.given_error {
            Some(given) => error <= CLEARLY_BETTER * given,
            None => true,
        };
        (scale != self.given && clearly).then_some(scale)
    }
}

/// Tries the given scale and [`CANDIDATE_SCALES`] on a rectified pair whose disparities were
/// decoded at `given` raw units per pixel. None when the views and maps differ in size or no
/// scale keeps enough samples inside the other view.
pub fn fit_disparity_scale(
    (left, left_d): (&RgbImage, &DepthMap),
    (right, right_d): (&RgbImage, &DepthMap),
    given: f64,
) -> Option<ScaleFit> {
    let (w, h) = (left.width, left.height);
    let same = |img: &RgbImage, d: &DepthMap| (img.width, img.height, d.width, d.height) == (w, h, w, h);
    if !(same(left, left_d) && same(right, right_d)) || w == 0 || h == 0 {
        return None;
    }
    let stride = ((w as usize * h as usize) as f64 / SAMPLES as f64)
        .sqrt()
        .ceil()
        .max(1.0) as usize;
    let error_at = |scale: f64| {
        let factor = given / scale;
        let (a, an, av) = shift_error(left, right, left_d, -factor, stride);
        let (b, bn, bv) = shift_error(right, left, right_d, factor, stride);
        let (n, valid) = (an + bn, av + bv);
        (valid > 0 && n as f64 >= MIN_INSIDE * valid as f64).then(|| (a + b) / n as f64)
    };
    let given_error = error_at(given);
    let best = CANDIDATE_SCALES
        .iter()
        .filter_map(|&s| error_at(s).map(|e| (s, e)))
        .chain(given_error.map(|e| (given, e)))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(ScaleFit {
        given,
        given_error,
        best,
    })
}

/// Grey (mean of R, G, B) at pixel (x, y).
fn grey(img: &RgbImage, x: usize, y: usize) -> f64 {
    let i = 3 * (y * img.width as usize + x);
    let p = &img.data[i..i + 3];
    (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0
}

/// Sum of |grey(from at x) - grey(to at x + sign_factor d)| over the sampled pixels with a
/// valid disparity whose shift stays inside `to` (linear along the row), their count, and the
/// count of sampled valid pixels.
fn shift_error(from: &RgbImage, to: &RgbImage, d: &DepthMap, sign_factor: f64, stride: usize) -> (f64, usize, usize) {
    let (w, h) = (from.width as usize, from.height as usize);
    let (mut sum, mut inside, mut valid) = (0.0, 0, 0);
    for y in (stride / 2..h).step_by(stride) {
        for x in (stride / 2..w).step_by(stride) {
            let disparity = f64::from(d.data[y * w + x]);
            if !(disparity.is_finite() && disparity > 0.0) {
                continue;
            }
            valid += 1;
            let tx = x as f64 + sign_factor * disparity;
            if !(tx >= 0.0 && tx <= (w - 1) as f64) {
                continue;
            }
            let x0 = tx.floor() as usize;
            let x1 = (x0 + 1).min(w - 1);
            let f = tx - x0 as f64;
            let shifted = grey(to, x0, y) * (1.0 - f) + grey(to, x1, y) * f;
            sum += (grey(from, x, y) - shifted).abs();
            inside += 1;
        }
    }
    (sum, inside, valid)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A textured row pair with constant disparity `d` px: right(x) = left(x + d).
    fn pair(d: usize) -> (RgbImage, RgbImage) {
        let (w, h) = (96u32, 8u32);
        let texture = |x: usize| ((x * 37 + (x * x) % 23) % 251) as u8;
        let img = |shift: usize| {
            let data = (0..h as usize)
                .flat_map(|_| (0..w as usize).flat_map(move |x| [texture(x + shift); 3]))
                .collect();
            RgbImage::new(w, h, data).unwrap()
        };
        (img(0), img(d))
    }

    #[test]
    fn the_scale_the_views_agree_with_is_found() {
        let (left, right) = pair(6);
        // Stored at 4 units a pixel (24), decoded at 1: 24 px.
        let stored = DepthMap::new(96, 8, vec![24.0; 96 * 8]).unwrap();
        let fit = fit_disparity_scale((&left, &stored), (&right, &stored), 1.0).unwrap();
        assert_eq!(fit.better(), Some(4.0), "{fit:?}");
        assert_eq!(fit.best, (4.0, 0.0));
        // Decoded at 4 (6 px): nothing fits better.
        let right_scale = DepthMap::new(96, 8, vec![6.0; 96 * 8]).unwrap();
        let fit = fit_disparity_scale((&left, &right_scale), (&right, &right_scale), 4.0).unwrap();
        assert_eq!(fit.better(), None, "{fit:?}");
        assert_eq!(fit.given_error, Some(0.0));
    }
}
