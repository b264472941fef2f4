//! Per-pixel confidence of the matcher's disparities (issue 26: robustness to matcher noise),
//! in [0, 1], 0 where a disparity is unknown. From the two final maps alone:
//! - the eyes' disagreement: the other eye's disparity read at the pixel this one points to
//!   (x + sign d, rounded half away from zero as the left-right check does); unknown, or 1 px or
//!   more away, gives 0; otherwise the agreement `1 - |d - e| / LR_TOLERANCE_PX`;
//! - the local spread: the variance of the known disparities of the 3 x 3 neighbourhood (depth
//!   edges and speckle), as `1 / (1 + variance)`.
//!
//! The confidence is their product. [`confidence_reference`] is the twin of the GPU stage
//! (shaders/cyclopean/matcher_confidence.comp, run by
//! [`Matcher::estimate_with_confidence`](super::Matcher::estimate_with_confidence)): its decisions
//! (which pixel is read, whether the eyes agree within the tolerance) are made in f32 as the
//! GPU makes them, the values in f64.

use super::LR_TOLERANCE_PX;
use crate::error::{Error, Result};
use crate::io::DepthMap;

/// Each eye's confidence map from the left and right disparities (0 = unknown) of one pair.
pub fn confidence_reference(left: &DepthMap, right: &DepthMap) -> Result<(DepthMap, DepthMap)> {
    if (left.width, left.height) != (right.width, right.height) {
        return Err(Error::SizeMismatch {
            message: format!(
                "matcher confidence: left disparity {}x{} vs right {}x{}",
                left.width, left.height, right.width, right.height
            ),
        });
    }
    Ok((
        DepthMap::new(left.width, left.height, eye(left, right, -1.0))?,
        DepthMap::new(left.width, left.height, eye(right, left, 1.0))?,
    ))
}

/// One eye's confidence: `own` points to x + `sign` d in `other`.
fn eye(own: &DepthMap, other: &DepthMap, sign: f32) -> Vec<f32> {
    let (w, h) = (own.width as usize, own.height as usize);
    let mut out = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let d = own.data[y * w + x];
            if d <= 0.0 {
                continue;
            }
            let xo = (x as f32 + sign * d).round();
            if xo < 0.0 || xo >= w as f32 {
                continue;
            }
            let e = other.data[y * w + xo as usize];
            if e <= 0.0 || (d - e).abs() >= LR_TOLERANCE_PX {
                continue;
            }
            let agreement = 1.0 - (d as f64 - e as f64).abs() / LR_TOLERANCE_PX as f64;
            let near: Vec<f64> = (y.saturating_sub(1)..=(y + 1).min(h - 1))
                .flat_map(|yy| (x.saturating_sub(1)..=(x + 1).min(w - 1)).map(move |xx| (xx, yy)))
                .map(|(xx, yy)| own.data[yy * w + xx] as f64)
                .filter(|v| *v > 0.0)
                .collect();
            let mean = near.iter().sum::<f64>() / near.len() as f64;
            let variance = near.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / near.len() as f64;
            out[y * w + x] = (agreement / (1.0 + variance)) as f32;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(w: u32, data: Vec<f32>) -> DepthMap {
        DepthMap::new(w, data.len() as u32 / w, data).unwrap()
    }

    #[test]
    fn agreeing_flat_eyes_are_trusted_and_the_rest_less_or_not_at_all() {
        // One row, disparity 2 everywhere in both eyes: left x sees right x - 2.
        let l = map(8, vec![2.0; 8]);
        let r = map(8, vec![2.0; 8]);
        let (cl, cr) = confidence_reference(&l, &r).unwrap();
        // Left pixels 0 and 1 point outside the right image; right pixels 6 and 7 likewise.
        assert_eq!(cl.data, [0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
        assert_eq!(cr.data, [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0]);
        // The right eye 0.5 px off: agreement 0.5; a full pixel off: none.
        let (cl, _) = confidence_reference(&l, &map(8, vec![2.5; 8])).unwrap();
        assert_eq!(cl.data[4], 0.5);
        let (cl, _) = confidence_reference(&l, &map(8, vec![3.0; 8])).unwrap();
        assert!(cl.data.iter().all(|c| *c == 0.0));
        // A spike of 4 beside 2s: the spread lowers its and its neighbours' confidence; an
        // unknown pixel stays 0.
        let mut spiky = vec![2.0; 8];
        spiky[4] = 4.0;
        spiky[6] = 0.0;
        let (cl, _) = confidence_reference(&map(8, spiky), &map(8, vec![2.0; 8])).unwrap();
        assert_eq!(cl.data[6], 0.0);
        // Neighbourhood of 3 (2, 4, 2): variance 8/9.
        assert!((cl.data[3] - 1.0 / (1.0 + 8.0 / 9.0)).abs() < 1e-6, "{:?}", cl.data);
        assert!(cl.data[2] == 1.0 && cl.data[3] < 1.0);
    }
}
