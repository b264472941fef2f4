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

impl Flip {
    /// FLIP of `test` against `reference` (both top-down sRGB, the same size: the caller checks).
    pub fn of(reference: &RgbImage, test: &RgbImage) -> Self {
        let (w, h) = (reference.width, reference.height);
        let r = nv_flip::FlipImageRgb8::with_data(w, h, &reference.data);
        let t = nv_flip::FlipImageRgb8::with_data(w, h, &test.data);
        let error = nv_flip::flip(r, t, PIXELS_PER_DEGREE).to_vec();
        Flip {
            error,
            width: w,
            height: h,
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
