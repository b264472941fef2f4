//! Error measures shared by tests, reports and benchmarks.

/// Peak signal-to-noise ratio in dB for 8-bit data from a mean squared error.
/// Identical images give +inf.
pub fn psnr_from_mse(mse: f64) -> f64 {
    if mse <= 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0 * 255.0 / mse).log10()
    }
}

/// Intersection over union of two masks; two empty masks agree perfectly (1.0).
pub fn mask_iou(a: &[bool], b: &[bool]) -> f64 {
    let (mut inter, mut union) = (0usize, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        inter += (x && y) as usize;
        union += (x || y) as usize;
    }
    if union == 0 {
        1.0
    } else {
        inter as f64 / union as f64
    }
}

// The coverage formula lives with the image types it measures (the files layer, below this one).
pub use crate::io::valid_fraction;

/// Rounds a 0..=255 f64 colour channel the way a UNORM8 render target stores it.
pub fn quantize_u8(v: f64) -> u8 {
    v.round().clamp(0.0, 255.0) as u8
}

/// Half-level window around which rounding is a tie. Bilinear weights of 0.5 (focal scales
/// 0.5, 0.75, 2, ...) put many exact values on k + 0.5, where f32 and f64 arithmetic land on
/// either side; f32 sample positions (error <= ~2e-5 px on a 16k image) times the steepest
/// possible gradient (255 levels/px) stay within this window, so either neighbour is correct.
pub const ROUNDING_TIE_WINDOW: f64 = 5e-3;

/// Level difference between an 8-bit value and the exact value it should be a rounding of:
/// 0 when it is the nearest integer, or either neighbour of a tie.
pub fn quantization_error(stored: u8, exact: f64) -> u32 {
    // Distance to the nearest acceptable value, in whole levels.
    ((stored as f64 - exact).abs() - 0.5 - ROUNDING_TIE_WINDOW)
        .max(0.0)
        .ceil() as u32
}

/// GPU output against a reference, over the pixels both mark valid.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Agreement {
    /// Pixels valid in both.
    pub common: usize,
    /// Pixels valid in exactly one.
    pub mask_mismatch: usize,
    /// Intersection over union of the two masks.
    pub mask_iou: f64,
    /// Colour PSNR (dB) on the common pixels, against the reference rounded to 8 bits (either
    /// neighbour of an exact tie counts as right: [`quantization_error`]).
    pub psnr_db: f64,
    /// Largest absolute depth difference on the common pixels.
    pub max_abs_depth: f64,
    /// Largest relative depth difference on the common pixels.
    pub max_rel_depth: f64,
    /// Largest colour difference in 8-bit levels on the common pixels.
    pub max_color_diff: u8,
}

/// Compare (rgb, depth, mask) against reference arrays of the same size. Any of the GPU
/// outputs may be absent; the corresponding fields stay at their neutral values.
pub fn agreement(
    rgb: Option<&[u8]>,
    depth: Option<&[f32]>,
    mask: &[bool],
    ref_rgb: &[[f64; 3]],
    ref_depth: &[f64],
    ref_mask: &[bool],
) -> Agreement {
    let mut a = Agreement {
        mask_iou: mask_iou(mask, ref_mask),
        ..Default::default()
    };
    let mut sq = 0.0;
    for i in 0..mask.len() {
        if mask[i] != ref_mask[i] {
            a.mask_mismatch += 1;
            continue;
        }
        if !mask[i] {
            continue;
        }
        a.common += 1;
        if let Some(rgb) = rgb {
            for c in 0..3 {
                let d = quantization_error(rgb[i * 3 + c], ref_rgb[i][c]);
                sq += (d * d) as f64;
                a.max_color_diff = a.max_color_diff.max(d as u8);
            }
        }
        if let Some(depth) = depth {
            let e = (depth[i] as f64 - ref_depth[i]).abs();
            a.max_abs_depth = a.max_abs_depth.max(e);
            a.max_rel_depth = a.max_rel_depth.max(e / ref_depth[i].abs());
        }
    }
    a.psnr_db = if a.common == 0 {
        f64::INFINITY
    } else {
        psnr_from_mse(sq / (3 * a.common) as f64)
    };
    a
}

#[cfg(test)]
mod tests {
    #[test]
    fn valid_fraction_counts_the_valid_share() {
        assert_eq!(super::valid_fraction(&[0u8, 255, 1, 0], |m| *m != 0), 0.5);
        assert_eq!(super::valid_fraction(&[true, true, true], |m| *m), 1.0);
        // An empty image covers nothing (never NaN).
        assert_eq!(super::valid_fraction::<f32>(&[], |z| *z > 0.0), 0.0);
    }

    use super::*;

    #[test]
    fn psnr_and_iou_known_values() {
        assert!((psnr_from_mse(1.0) - 48.1308).abs() < 1e-3);
        assert_eq!(psnr_from_mse(0.0), f64::INFINITY);
        assert_eq!(
            mask_iou(&[true, true, false, false], &[true, false, true, false]),
            1.0 / 3.0
        );
        assert_eq!(mask_iou(&[false], &[false]), 1.0);
    }

    #[test]
    fn ties_accept_either_neighbour_and_nothing_else() {
        assert_eq!(quantization_error(204, 204.5), 0);
        assert_eq!(quantization_error(205, 204.4999999), 0);
        assert_eq!(quantization_error(205, 204.4), 1);
        assert_eq!(quantization_error(203, 204.5), 1);
        assert_eq!(quantization_error(0, 3.0), 3);
    }

    #[test]
    fn agreement_counts_only_common_pixels() {
        let mask = [true, true, false];
        let ref_mask = [true, false, false];
        let a = agreement(
            Some(&[10, 10, 10, 0, 0, 0, 0, 0, 0]),
            Some(&[2.0, 9.0, 0.0]),
            &mask,
            &[[10.4, 10.0, 11.0], [0.0; 3], [0.0; 3]],
            &[2.5, 0.0, 0.0],
            &ref_mask,
        );
        assert_eq!((a.common, a.mask_mismatch), (1, 1));
        assert_eq!(a.max_color_diff, 1);
        assert!((a.max_abs_depth - 0.5).abs() < 1e-12 && (a.max_rel_depth - 0.2).abs() < 1e-12);
        assert!((a.psnr_db - psnr_from_mse(1.0 / 3.0)).abs() < 1e-9);
    }
}
