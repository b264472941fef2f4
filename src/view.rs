//! [`ViewOutput`]: the one output shape shared by every capability's GPU pass and its f64 twin
//! (colour, view-Z depth, validity mask, timings), so the two are compared by one function
//! (the lab's `eval::image_check::ensure_views`) and the report and tests read every capability
//! alike.
//!
//! Each capability keeps its own richer output (cyclopean's per-eye source bits, refocus's
//! target camera); the conversions here take what the comparison needs. The f64 twins are
//! rounded to the output types the GPU writes (colour to the nearest 8-bit level, depth to f32)
//! and keep their unrounded values in [`ExactView`], which the tests measure the GPU against (a
//! rounding tie may go either way).
//!
//! Each capability's `pass` module (`refocus::pass`, `cyclopean::pass`, `reproject::pass`,
//! `stitch::pass`) holds the contract: one input type and `gpu(device, &input)` /
//! `reference(&input)`, both returning a `ViewOutput`, and the conversions from its own output
//! types (`ViewOutput::from_refocus`, ...), so this module imports no capability.

use crate::io::{DepthMap, Mask, RgbImage};
use crate::metrics::quantize_u8;
use crate::pass::Timing;

/// The output rule of every pass, applied once after readback (and to the f64 twins when they
/// are rounded to f32): a pixel whose depth is not finite is invalid, mask 0 and depth 0, so
/// that no caller sees NaN or Inf where the mask says valid, whatever the inputs did inside
/// the pass. Colour is 8-bit and always finite. Returns how many pixels it invalidated. A
/// plane that was not requested is left alone (without depth there is nothing to test).
pub fn clear_non_finite(depth: Option<&mut [f32]>, mut mask: Option<&mut [u8]>) -> usize {
    let Some(depth) = depth else { return 0 };
    let mut n = 0;
    for (i, z) in depth.iter_mut().enumerate().filter(|(_, z)| !z.is_finite()) {
        *z = 0.0;
        if let Some(m) = mask.as_deref_mut().and_then(|m| m.get_mut(i)) {
            n += usize::from(*m != 0);
            *m = 0;
        }
    }
    n
}

/// A synthesised view, rows top-down; every plane is `width` x `height` when present.
#[derive(Debug, Clone)]
pub struct ViewOutput {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// 8-bit colour; None when the pass writes none.
    pub color: Option<RgbImage>,
    /// View Z in metres, 0 where invalid (stitch: the distance along each pixel's ODS ray,
    /// 0 = sky; an equirect has no view axis).
    pub depth: Option<DepthMap>,
    /// Nonzero where the pixel is valid (cyclopean: its source-eye bits).
    pub mask: Option<Mask>,
    /// Wall (and GPU) time of the pass; None for the CPU twins.
    pub timing: Option<Timing>,
    /// The f64 twin's values before rounding; None for GPU passes.
    pub exact: Option<ExactView>,
}

/// An f64 twin's colour and depth before rounding to the GPU's output types, rows top-down.
#[derive(Debug, Clone)]
pub struct ExactView {
    /// RGB in 0..=255, not rounded.
    pub color: Vec<[f64; 3]>,
    /// View Z in metres (stitch: ray distance), 0 where invalid; None when the twin's depth
    /// was not asked for.
    pub depth: Option<Vec<f64>>,
}

fn rounded_color(width: u32, height: u32, color: &[[f64; 3]]) -> Option<RgbImage> {
    RgbImage::new(width, height, color.iter().flat_map(|c| c.map(quantize_u8)).collect()).ok()
}

fn f32_depth(width: u32, height: u32, depth: &[f64]) -> Option<DepthMap> {
    DepthMap::new(width, height, depth.iter().map(|&z| z as f32).collect()).ok()
}

impl ViewOutput {
    /// Per pixel, whether the mask marks it valid (nonzero); None when the view has no mask.
    pub fn valid(&self) -> Option<Vec<bool>> {
        self.mask.as_ref().map(|m| m.data.iter().map(|&v| v != 0).collect())
    }

    /// Whether every pixel the mask marks valid has a finite depth (true without depth or mask).
    pub fn finite_where_valid(&self) -> bool {
        match (&self.depth, &self.mask) {
            (Some(d), Some(m)) => d.data.iter().zip(&m.data).all(|(z, &v)| v == 0 || z.is_finite()),
            _ => true,
        }
    }

    /// [`clear_non_finite`] on this view's depth and mask.
    fn finite(mut self) -> Self {
        let mask = self.mask.as_mut().map(|m| m.data.as_mut_slice());
        clear_non_finite(self.depth.as_mut().map(|d| d.data.as_mut_slice()), mask);
        self
    }

    /// A colour-only view (the stitch's equirect).
    pub fn color_only(color: RgbImage, timing: Option<Timing>) -> Self {
        ViewOutput {
            width: color.width,
            height: color.height,
            color: Some(color),
            depth: None,
            mask: None,
            timing,
            exact: None,
        }
    }

    /// The stitch's f64 twin (rows top-down, `width` x `height`), rounded to 8 bits.
    pub fn from_color_f64(width: u32, height: u32, color: &[[f64; 3]]) -> Self {
        ViewOutput {
            width,
            height,
            color: rounded_color(width, height, color),
            depth: None,
            mask: None,
            timing: None,
            exact: Some(ExactView {
                color: color.to_vec(),
                depth: None,
            }),
        }
    }

    /// The stitch's GPU output: colour and ray distance as asked for, no mask.
    pub fn from_stitch(color: Option<RgbImage>, distance: Option<DepthMap>, timing: Option<Timing>) -> Self {
        let (width, height) = match (&color, &distance) {
            (Some(c), _) => (c.width, c.height),
            (None, Some(d)) => (d.width, d.height),
            (None, None) => (0, 0),
        };
        ViewOutput {
            width,
            height,
            color,
            depth: distance,
            mask: None,
            timing,
            exact: None,
        }
    }

    /// The stitch's f64 twin (rows top-down): colour rounded to 8 bits, ray distance to f32.
    pub fn from_stitch_f64(width: u32, height: u32, color: &[[f64; 3]], distance: &[f64]) -> Self {
        ViewOutput {
            width,
            height,
            color: rounded_color(width, height, color),
            depth: f32_depth(width, height, distance),
            mask: None,
            timing: None,
            exact: Some(ExactView {
                color: color.to_vec(),
                depth: Some(distance.to_vec()),
            }),
        }
        .finite()
    }

    /// A GPU output: planes as the pass read them back, `mask` nonzero where valid.
    pub fn from_gpu(
        width: u32,
        height: u32,
        color: Option<RgbImage>,
        depth: Option<DepthMap>,
        mask: Vec<u8>,
        timing: Option<Timing>,
    ) -> Self {
        ViewOutput {
            width,
            height,
            color,
            depth,
            mask: Mask::new(width, height, mask).ok(),
            timing,
            exact: None,
        }
    }

    /// An f64 twin's colour, depth and validity rounded to the GPU's output types; the mask is
    /// 255 where valid, as the GPU writes it.
    pub fn from_f64_twin(width: u32, height: u32, color: &[[f64; 3]], depth: &[f64], mask: &[bool]) -> Self {
        Self::from_f64_twin_mask(
            width,
            height,
            color,
            depth,
            mask.iter().map(|&m| if m { 255 } else { 0 }).collect(),
        )
    }

    /// As [`Self::from_f64_twin`] with the mask bytes given (cyclopean: the source-eye bits).
    pub fn from_f64_twin_mask(width: u32, height: u32, color: &[[f64; 3]], depth: &[f64], mask: Vec<u8>) -> Self {
        ViewOutput {
            width,
            height,
            color: rounded_color(width, height, color),
            depth: f32_depth(width, height, depth),
            mask: Mask::new(width, height, mask).ok(),
            timing: None,
            exact: Some(ExactView {
                color: color.to_vec(),
                depth: Some(depth.to_vec()),
            }),
        }
        .finite()
    }
}
