//! Baselines for in-between views of a rectified pair, on the CPU, for the report and the tests:
//! the forward splat a few lines of numpy would do, and no warp at all.

use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};

/// An in-between view and the pixels it covers (rows top-down).
pub struct BaselineView {
    /// Colour; black where nothing covers the pixel.
    pub color: RgbImage,
    /// Per pixel (row-major), whether the view covers it.
    pub covered: Vec<bool>,
}

/// Forward splat: every left pixel with a known disparity d (> 0, finite) moves to
/// round(x - t d), every right pixel to round(x + (1 - t) d); per pixel the largest disparity
/// (the nearest surface) wins and the colours of all splats within 1 px of disparity of it are
/// averaged. Independent of the order of the splats.
pub fn forward_splat(
    left: (&RgbImage, &DepthMap),
    right: (&RgbImage, &DepthMap),
    position: f64,
) -> Result<BaselineView> {
    forward_splat_offset(left, right, position, [0.0, 0.0])
}

/// [`forward_splat`] into a view whose image is translated by `offset` pixels (x, y): every
/// splat lands at round(x - t d + offset x), round(y + offset y). For measuring a target view
/// that sits off the exact in-between position (Middlebury Cones' im4).
pub fn forward_splat_offset(
    left: (&RgbImage, &DepthMap),
    right: (&RgbImage, &DepthMap),
    position: f64,
    offset: [f64; 2],
) -> Result<BaselineView> {
    forward_splat_rounded(left, right, position, offset, Rounding::HalfAway)
}

/// How a splat's position is rounded to a pixel. With quarter-pixel disparities (Middlebury
/// 2003) half of t d is often exactly k + 1/2, so the rule matters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rounding {
    /// Halves away from zero (`f64::round`; up, for every position inside the image):
    /// neighbours with the same disparity land on neighbouring pixels (the stronger baseline,
    /// the one the report and tests compare against).
    HalfAway,
    /// Half to even, as numpy's `np.round` does (issue 13's 40-line baseline): neighbours k + 1/2
    /// and k + 3/2 both land on the even pixel, leaving a hole and averaging two texels (Cones:
    /// 89.5 % coverage instead of 96.3 %).
    HalfEven,
}

impl Rounding {
    fn apply(self, v: f64) -> f64 {
        match self {
            Rounding::HalfAway => v.round(),
            Rounding::HalfEven => v.round_ties_even(),
        }
    }
}

/// [`forward_splat_offset`] with the rounding rule given.
pub fn forward_splat_rounded(
    left: (&RgbImage, &DepthMap),
    right: (&RgbImage, &DepthMap),
    position: f64,
    offset: [f64; 2],
    rounding: Rounding,
) -> Result<BaselineView> {
    let (w, h) = (left.0.width as usize, left.0.height as usize);
    for (name, (c, d)) in [("left", left), ("right", right)] {
        if (c.width as usize, c.height as usize) != (w, h) || (d.width as usize, d.height as usize) != (w, h) {
            return Err(Error::SizeMismatch {
                message: format!("{name} colour/disparity differ from the left colour's {w}x{h}"),
            });
        }
    }
    // (image, disparity, signed shift per pixel of disparity)
    let eyes = [(left, -position), (right, 1.0 - position)];
    let target = |x: usize, y: usize, d: f32, shift: f64| -> Option<usize> {
        if !(d.is_finite() && d > 0.0) {
            return None;
        }
        let tx = rounding.apply(x as f64 + shift * d as f64 + offset[0]);
        let ty = rounding.apply(y as f64 + offset[1]);
        (tx >= 0.0 && tx < w as f64 && ty >= 0.0 && ty < h as f64).then(|| ty as usize * w + tx as usize)
    };
    let mut best = vec![f32::NEG_INFINITY; w * h];
    for ((_, disp), shift) in eyes {
        for y in 0..h {
            for x in 0..w {
                let d = disp.data[y * w + x];
                if let Some(o) = target(x, y, d, shift) {
                    let b = &mut best[o];
                    *b = b.max(d);
                }
            }
        }
    }
    let mut sum = vec![[0.0f64; 3]; w * h];
    let mut count = vec![0u32; w * h];
    for ((rgb, disp), shift) in eyes {
        for y in 0..h {
            for x in 0..w {
                let d = disp.data[y * w + x];
                let Some(o) = target(x, y, d, shift) else { continue };
                if d >= best[o] - 1.0 {
                    let src = &rgb.data[(y * w + x) * 3..(y * w + x) * 3 + 3];
                    for (acc, v) in sum[o].iter_mut().zip(src) {
                        *acc += *v as f64;
                    }
                    count[o] += 1;
                }
            }
        }
    }
    let data = sum
        .iter()
        .zip(&count)
        .flat_map(|(s, &n)| {
            s.map(|v| {
                if n > 0 {
                    crate::metrics::quantize_u8(v / n as f64)
                } else {
                    0
                }
            })
        })
        .collect();
    Ok(BaselineView {
        color: RgbImage::new(w as u32, h as u32, data)?,
        covered: count.iter().map(|n| *n > 0).collect(),
    })
}

/// No warp: (1 - t) left + t right at the same pixel, everywhere.
pub fn no_warp(left: &RgbImage, right: &RgbImage, position: f64) -> Result<BaselineView> {
    if (left.width, left.height) != (right.width, right.height) {
        return Err(Error::SizeMismatch {
            message: format!(
                "left {}x{} vs right {}x{}",
                left.width, left.height, right.width, right.height
            ),
        });
    }
    let data = left
        .data
        .iter()
        .zip(&right.data)
        .map(|(&a, &b)| crate::metrics::quantize_u8((1.0 - position) * a as f64 + position * b as f64))
        .collect();
    Ok(BaselineView {
        color: RgbImage::new(left.width, left.height, data)?,
        covered: vec![true; left.data.len() / 3],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(colors: &[u8], disparity: &[f32]) -> (RgbImage, DepthMap) {
        let w = disparity.len() as u32;
        let rgb = colors.iter().flat_map(|c| [*c; 3]).collect();
        (
            RgbImage::new(w, 1, rgb).unwrap(),
            DepthMap::new(w, 1, disparity.to_vec()).unwrap(),
        )
    }

    #[test]
    fn splat_moves_by_t_d_nearest_wins_and_agreeing_eyes_average() {
        // Left: a far wall (d = 2) with one near pixel (d = 6) at x = 4; right: the same scene.
        let l = row(
            &[10, 10, 10, 10, 200, 10, 10, 10],
            &[2.0, 2.0, 2.0, 2.0, 6.0, 2.0, 2.0, 2.0],
        );
        let r = row(&[30, 30, 30, 30, 30, 30, 30, 30], &[2.0; 8]);
        let v = forward_splat((&l.0, &l.1), (&r.0, &r.1), 0.5).unwrap();
        let px = |x: usize| v.color.data[x * 3];
        // x = 4 - 3 = 1: the near pixel wins over both eyes' wall.
        assert_eq!(px(1), 200);
        // x = 3: only the right wall (x = 2, moved +1) lands here; the left pixel that would (x = 4)
        // is the near one and went to x = 1.
        assert_eq!(px(3), 30);
        // x = 5: left wall x = 6 (-1) and right wall x = 4 (+1) agree: their mean.
        assert_eq!(px(5), 20);
        // Position 0: the left image itself wherever the left disparity is known.
        let v0 = forward_splat((&l.0, &l.1), (&r.0, &r.1), 0.0).unwrap();
        assert_eq!(v0.color.data[4 * 3], 200);
        // Unknown disparity splats nowhere.
        let none = row(&[50; 8], &[0.0; 8]);
        let v = forward_splat((&none.0, &none.1), (&none.0, &none.1), 0.5).unwrap();
        assert!(v.covered.iter().all(|c| !c));
        // An offset translates the view: (+1, 0) puts the near pixel one column right; (0, 0.4)
        // rounds back onto the same row.
        let v1 = forward_splat_offset((&l.0, &l.1), (&r.0, &r.1), 0.5, [1.0, 0.4]).unwrap();
        assert_eq!(v1.color.data[2 * 3], 200);
        assert_eq!(v1.color.data[6 * 3], 20);
    }

    #[test]
    fn numpy_rounding_doubles_up_half_pixel_splats_and_leaves_holes() {
        // Left only (right disparity unknown), d = 1 at t = 1/2: every splat lands on x - 1/2.
        let l = row(&[0, 10, 20, 30, 40, 50, 60, 70], &[1.0; 8]);
        let none = row(&[0; 8], &[0.0; 8]);
        let splat =
            |rounding| forward_splat_rounded((&l.0, &l.1), (&none.0, &none.1), 0.5, [0.0, 0.0], rounding).unwrap();
        // Halves away from zero: x -> x (x = 0 leaves the image at -1/2 -> -1).
        let away = splat(Rounding::HalfAway);
        assert_eq!(away.covered, [false, true, true, true, true, true, true, true]);
        assert_eq!(away.color.data[3 * 3], 30);
        // Half to even: 1/2 -> 0, 3/2 -> 2, 5/2 -> 2, 7/2 -> 4 ...: odd pixels empty, even ones
        // the mean of two texels.
        let even = splat(Rounding::HalfEven);
        assert_eq!(even.covered, [true, false, true, false, true, false, true, false]);
        assert_eq!(even.color.data[2 * 3], 25);
    }

    #[test]
    fn no_warp_is_the_weighted_mean() {
        let l = row(&[0, 100], &[1.0, 1.0]);
        let r = row(&[100, 200], &[1.0, 1.0]);
        let v = no_warp(&l.0, &r.0, 0.25).unwrap();
        assert_eq!((v.color.data[0], v.color.data[3]), (25, 125));
    }
}
