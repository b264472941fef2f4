//! [`ViewOutput`]: the one output shape shared by every capability's GPU pass and its f64 twin
//! (colour, view-Z depth, validity mask, timings), so the two are compared by one function
//! ([`crate::eval::image_check::ensure_views`]) and the report and tests read every capability
//! alike.
//!
//! Each capability keeps its own richer output (cyclopean's per-eye source bits, refocus's
//! target camera); the conversions here take what the comparison needs. The f64 twins are
//! rounded to the output types the GPU writes (colour to the nearest 8-bit level, depth to f32)
//! and keep their unrounded values in [`ExactView`], which the tests measure the GPU against (a
//! rounding tie may go either way).
//!
//! Each capability's `pass` module (`refocus::pass`, `cyclopean::pass`, `reproject::pass`,
//! `stitch::pass`) holds the contract: one input type and `gpu(&Gpu, &input)` /
//! `reference(&input)`, both returning a `ViewOutput`.

use crate::cyclopean::reference::CyclopeanReference;
use crate::cyclopean::CyclopeanOutput;
use crate::gpu::Timing;
use crate::io::{DepthMap, Mask, RgbImage};
use crate::metrics::quantize_u8;
use crate::refocus::reference::ReferenceImage;
use crate::refocus::RefocusOutput;
use crate::reproject::reference::ReprojectReference;
use crate::reproject::ReprojectOutput;

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

impl RefocusOutput {
    /// [`clear_non_finite`] on the planes read back.
    pub fn finite(mut self) -> Self {
        let mask = self.mask.as_mut().map(|m| m.data.as_mut_slice());
        clear_non_finite(self.depth.as_mut().map(|d| d.data.as_mut_slice()), mask);
        self
    }
}

impl CyclopeanOutput {
    /// [`clear_non_finite`] on the planes read back (the source bits are the mask).
    pub fn finite(mut self) -> Self {
        clear_non_finite(
            self.depth.as_mut().map(|d| d.data.as_mut_slice()),
            Some(&mut self.sources),
        );
        self
    }
}

impl ReprojectOutput {
    /// [`clear_non_finite`] on the planes read back.
    pub fn finite(mut self) -> Self {
        clear_non_finite(self.depth.as_mut().map(|d| d.data.as_mut_slice()), Some(&mut self.mask));
        self
    }
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
    /// View Z in metres, 0 where invalid.
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
    /// View Z in metres, 0 where invalid; None when the twin computes no depth (stitch).
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

    /// A refocus GPU output.
    pub fn from_refocus(out: &RefocusOutput) -> Self {
        ViewOutput {
            width: out.camera.width,
            height: out.camera.height,
            color: out.rgb.clone(),
            depth: out.depth.clone(),
            mask: out.mask.clone(),
            timing: Some(out.render),
            exact: None,
        }
    }

    /// The refocus f64 twin; the mask is 255 where covered, as the GPU writes it.
    pub fn from_refocus_reference(r: &ReferenceImage) -> Self {
        Self::from_f64_twin(r.width, r.height, &r.rgb, &r.depth, &r.mask)
    }

    /// An f64 twin's colour, depth and validity rounded to the GPU's output types.
    fn from_f64_twin(width: u32, height: u32, color: &[[f64; 3]], depth: &[f64], mask: &[bool]) -> Self {
        ViewOutput {
            width,
            height,
            color: rounded_color(width, height, color),
            depth: f32_depth(width, height, depth),
            mask: Mask::new(width, height, mask.iter().map(|&m| if m { 255 } else { 0 }).collect()).ok(),
            timing: None,
            exact: Some(ExactView {
                color: color.to_vec(),
                depth: Some(depth.to_vec()),
            }),
        }
        .finite()
    }

    /// A cyclopean GPU output of a `width` x `height` middle camera.
    pub fn from_cyclopean(out: &CyclopeanOutput, width: u32, height: u32, timing: Option<Timing>) -> Self {
        ViewOutput {
            width,
            height,
            color: out.color.clone(),
            depth: out.depth.clone(),
            mask: Mask::new(width, height, out.sources.clone()).ok(),
            timing,
            exact: None,
        }
    }

    /// The cyclopean f64 twin of a `width` x `height` middle camera.
    pub fn from_cyclopean_reference(r: &CyclopeanReference, width: u32, height: u32) -> Self {
        ViewOutput {
            width,
            height,
            color: rounded_color(width, height, &r.color),
            depth: f32_depth(width, height, &r.depth),
            mask: Mask::new(width, height, r.sources.clone()).ok(),
            timing: None,
            exact: Some(ExactView {
                color: r.color.clone(),
                depth: Some(r.depth.clone()),
            }),
        }
        .finite()
    }

    /// A reprojection GPU output of a `width` x `height` target.
    pub fn from_reproject(out: &ReprojectOutput, width: u32, height: u32, timing: Option<Timing>) -> Self {
        ViewOutput {
            width,
            height,
            color: out.color.clone(),
            depth: out.depth.clone(),
            mask: Mask::new(width, height, out.mask.clone()).ok(),
            timing,
            exact: None,
        }
    }

    /// The reprojection f64 twin; the mask is 255 where valid, as the GPU writes it.
    pub fn from_reproject_reference(r: &ReprojectReference) -> Self {
        Self::from_f64_twin(r.width, r.height, &r.color, &r.depth, &r.mask)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_twin_converts_to_what_its_gpu_pass_writes() {
        let r = ReprojectReference {
            width: 2,
            height: 1,
            color: vec![[0.4, 127.5, 254.6], [0.0; 3]],
            depth: vec![1.25, 0.0],
            mask: vec![true, false],
        };
        let twin = ViewOutput::from_reproject_reference(&r);
        // The same rounding as the reference's own conversion to the GPU output types.
        let gpu_shaped = ViewOutput::from_reproject(&r.to_output().unwrap(), 2, 1, None);
        for v in [&twin, &gpu_shaped] {
            assert_eq!(v.color.as_ref().unwrap().data, vec![0, 128, 255, 0, 0, 0]);
            assert_eq!(v.depth.as_ref().unwrap().data, vec![1.25, 0.0]);
            assert_eq!(v.mask.as_ref().unwrap().data, vec![255, 0]);
        }
        let stitch = ViewOutput::from_color_f64(1, 1, &[[1.5, 2.49, -3.0]]);
        assert_eq!(stitch.color.unwrap().data, vec![2, 2, 0]);
        assert!(stitch.depth.is_none() && stitch.mask.is_none() && stitch.timing.is_none());
        assert_eq!(stitch.exact.unwrap().color, vec![[1.5, 2.49, -3.0]]);
        assert_eq!(twin.exact.unwrap().depth, Some(vec![1.25, 0.0]));
        assert!(gpu_shaped.exact.is_none());
    }
}
