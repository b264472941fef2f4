//! A rectified pair with one eye's disparity (Middlebury 2014 ships the left only): the other
//! eye's map derived by forward-warping the given one, so that the other eye contributes colour
//! exactly where the given eye's geometry says it sees the surface.
//!
//! The rule, per row: each known disparity d at x moves to x - d (left given; x_right = x_left -
//! d) or x + d (right given; x_left = x_right + d) and keeps its value. Neighbours whose
//! disparities differ by at most [`SAME_SURFACE_PX`] are one surface: the pixel centres between
//! their targets take the linearly interpolated disparity, so a slanted surface that widens in
//! the other view leaves no cracks. Where two surfaces land on one pixel the larger disparity
//! (the nearer surface) wins: the left-right consistency rule, which drops what the other eye
//! cannot see. Pixels nothing lands on (what only the other eye sees) stay 0 = unknown.

use super::Eye;
use crate::io::DepthMap;

/// Largest disparity step, pixels, between neighbours of one surface; a larger step is a depth
/// edge, whose gap in the other view is a disocclusion left unknown.
pub const SAME_SURFACE_PX: f32 = 1.0;

/// The other eye's disparity (pixels, 0 = unknown) from `given`, the disparity of eye `eye`.
pub fn other_eye_disparity(given: &DepthMap, eye: Eye) -> DepthMap {
    let (w, h) = (given.width as usize, given.height as usize);
    let sign = match eye {
        Eye::Left => -1.0,
        Eye::Right => 1.0,
    };
    let mut out = vec![0.0f32; w * h];
    let known = |d: f32| d.is_finite() && d != 0.0;
    for y in 0..h {
        let row = &given.data[y * w..(y + 1) * w];
        let dst = &mut out[y * w..(y + 1) * w];
        let mut keep = |x: i64, d: f32| {
            if (0..w as i64).contains(&x) {
                let slot = &mut dst[x as usize];
                if *slot == 0.0 || d > *slot {
                    *slot = d;
                }
            }
        };
        for x in 0..w {
            let d = row[x];
            if !known(d) {
                continue;
            }
            let t = x as f64 + sign * f64::from(d);
            keep(t.round() as i64, d);
            let Some(&next) = row.get(x + 1) else { continue };
            if !known(next) || (next - d).abs() > SAME_SURFACE_PX {
                continue;
            }
            let t1 = (x + 1) as f64 + sign * f64::from(next);
            let (lo, hi) = if t <= t1 { (t, t1) } else { (t1, t) };
            let mut c = lo.ceil();
            while c <= hi {
                let f = if hi > lo { (c - t) / (t1 - t) } else { 0.0 };
                keep(c as i64, (f64::from(d) + f * f64::from(next - d)) as f32);
                c += 1.0;
            }
        }
    }
    DepthMap {
        width: given.width,
        height: given.height,
        data: out,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(data: Vec<f32>) -> DepthMap {
        DepthMap {
            width: data.len() as u32,
            height: 1,
            data,
        }
    }

    #[test]
    fn a_constant_plane_moves_by_its_disparity() {
        let left = row(vec![2.0; 8]);
        let right = other_eye_disparity(&left, Eye::Left);
        assert_eq!(right.data, [2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 0.0, 0.0]);
        let back = other_eye_disparity(&right, Eye::Right);
        assert_eq!(back.data, [0.0, 0.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0]);
    }

    #[test]
    fn the_nearer_surface_wins_and_the_disocclusion_stays_unknown() {
        // Background d = 1 with a foreground block d = 4 at x = 5..8 (left eye).
        let mut d = vec![1.0; 12];
        d[5..8].fill(4.0);
        let right = other_eye_disparity(&row(d), Eye::Left);
        // Foreground lands on 1..4 over the background that was there; the background left
        // of the block (x = 4 -> 3) is hidden behind it, and 4..=6 only the right eye sees.
        assert_eq!(&right.data[1..4], &[4.0, 4.0, 4.0]);
        assert_eq!(&right.data[4..7], &[0.0, 0.0, 0.0]);
        assert_eq!(&right.data[7..11], &[1.0, 1.0, 1.0, 1.0]);
    }

    #[test]
    fn a_slanted_surface_that_widens_leaves_no_crack() {
        // Right disparity rising by 0.5 px a pixel: the surface spans 1.5x the pixels in the
        // left view (x_left = 1 + 1.5 x), and the forward splat alone would skip one in three.
        let d: Vec<f32> = (0..10).map(|x| 1.0 + 0.5 * x as f32).collect();
        let mut wide = d.clone();
        wide.resize(20, 0.0);
        let left = other_eye_disparity(&row(wide), Eye::Right);
        let covered: Vec<usize> = (0..left.data.len()).filter(|&x| left.data[x] != 0.0).collect();
        let first = covered[0];
        assert_eq!(covered, (first..first + covered.len()).collect::<Vec<_>>());
        assert!(covered.len() > d.len());
        // Unknown stays unknown: a map of zeros gives zeros.
        assert!(other_eye_disparity(&row(vec![0.0; 5]), Eye::Left)
            .data
            .iter()
            .all(|&v| v == 0.0));
    }
}
