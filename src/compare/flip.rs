//! FLIP (Andersson et al. 2020, NVIDIA's perceptual difference of rendered images), through the
//! `nv-flip` crate, which builds NVIDIA's own C++ implementation: the per-pixel error in [0, 1],
//! its mean (the figure FLIP's authors recommend when one number is wanted) and the error map
//! coloured with FLIP's magma map, as graphics engineers read it. LDR FLIP on 8-bit sRGB colour.

use crate::io::RgbImage;

/// Pixels per degree of visual angle FLIP's filters are sized for: FLIP's default (a 0.7 m
/// wide 4K monitor seen from 0.7 m).
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// FLIP of a test image against a reference.
#[derive(Debug, Clone)]
pub struct Flip {
    /// Per-pixel FLIP error in [0, 1], rows top-down.
    pub error: Vec<f32>,
    /// Width of the error map.
    pub width: u32,
    /// Height of the error map.
    pub height: u32,
}

/// Pixels of one strip FLIP runs on at most (about 91 bytes a pixel of working memory inside
/// FLIP: about 48 MB a strip, whatever the image's size).
pub const STRIP_PIXELS: usize = 1 << 19;

/// Rows of a strip at least (the halo is recomputed for each strip).
const MIN_STRIP_ROWS: usize = 64;

/// Rows above and below a strip that FLIP reads to compute the strip's own rows exactly: the
/// larger of its filters' radii, ceil(3 sqrt(b / (2 pi^2)) ppd) for the spatial filter (largest
/// scale parameter b = 0.04) and ceil(3 * 0.5 * 0.082 ppd) for the feature filters (FLIP's
/// sharedflip.h). Every other step of LDR FLIP is per pixel, and its filters clamp at the
/// image's edges only, so the strips' rows are the whole image's, bit for bit (a test holds it).
fn halo_rows(ppd: f32) -> usize {
    let spatial = (3.0 * (0.04f32 / (2.0 * std::f32::consts::PI.powi(2))).sqrt() * ppd).ceil();
    let feature = (3.0 * 0.5 * 0.082 * ppd).ceil();
    spatial.max(feature) as usize + 1
}

impl Flip {
    /// FLIP of `test` against `reference` (both top-down sRGB, the same size: the caller checks),
    /// run in strips of [`STRIP_PIXELS`] so that its working memory does not grow with the image.
    pub fn of(reference: &RgbImage, test: &RgbImage) -> Self {
        Self::in_strips(
            reference,
            test,
            (STRIP_PIXELS / reference.width.max(1) as usize).max(MIN_STRIP_ROWS),
        )
    }

    /// [`Flip::of`] in strips of `rows` rows (and the halo above and below each).
    fn in_strips(reference: &RgbImage, test: &RgbImage, rows: usize) -> Self {
        let (w, h) = (reference.width as usize, reference.height as usize);
        let halo = halo_rows(PIXELS_PER_DEGREE);
        let mut error = Vec::with_capacity(w * h);
        let mut top = 0;
        while top < h {
            let bottom = (top + rows).min(h);
            let (from, to) = (top.saturating_sub(halo), (bottom + halo).min(h));
            let strip = |img: &RgbImage| {
                nv_flip::FlipImageRgb8::with_data(w as u32, (to - from) as u32, &img.data[from * w * 3..to * w * 3])
            };
            let e = nv_flip::flip(strip(reference), strip(test), PIXELS_PER_DEGREE).to_vec();
            error.extend_from_slice(&e[(top - from) * w..(bottom - from) * w]);
            top = bottom;
        }
        Flip {
            error,
            width: w as u32,
            height: h as u32,
        }
    }

    /// The mean error over the selected pixels (all: the reference's own mean), summed in f64.
    pub fn mean(&self, selected: &[bool]) -> f64 {
        let (sum, n) = self
            .error
            .iter()
            .zip(selected)
            .filter(|(_, s)| **s)
            .fold((0.0, 0usize), |(sum, n), (e, _)| (sum + f64::from(*e), n + 1));
        sum / n.max(1) as f64
    }

    /// The error map through FLIP's magma colour map (black: no visible difference, pale
    /// yellow: the largest); unselected pixels black.
    pub fn magma_map(&self, selected: &[bool]) -> RgbImage {
        let lut = nv_flip::magma_lut().to_vec();
        let data = self
            .error
            .iter()
            .zip(selected)
            .flat_map(|(e, s)| {
                if *s {
                    // The reference's mapping: index round(e * 255).
                    let i = ((e.clamp(0.0, 1.0) * 255.0).round() as usize).min(255) * 3;
                    [lut[i], lut[i + 1], lut[i + 2]]
                } else {
                    [0, 0, 0]
                }
            })
            .collect();
        RgbImage {
            width: self.width,
            height: self.height,
            data,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Strips with their halo give the whole image's FLIP bit for bit (on a random image, where
    /// every filter tap matters), including strips shorter than the halo.
    #[test]
    fn strips_give_the_whole_images_flip_exactly() {
        let (w, h) = (40u32, 150u32);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut noise = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 56) as u8
        };
        let mut image = || RgbImage {
            width: w,
            height: h,
            data: (0..w * h * 3).map(|_| noise()).collect(),
        };
        let (a, b) = (image(), image());
        let whole = Flip::in_strips(&a, &b, h as usize);
        for rows in [7, 32, 64] {
            let strips = Flip::in_strips(&a, &b, rows);
            assert!(
                whole
                    .error
                    .iter()
                    .zip(&strips.error)
                    .all(|(x, y)| x.to_bits() == y.to_bits()),
                "strips of {rows} rows differ from the whole image"
            );
            assert_eq!(strips.error.len(), whole.error.len());
        }
    }
}
