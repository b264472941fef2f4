//! The stitch pass/twin contract: one [`StitchInput`] (both eyes' faces, parameters,
//! conventions), and [`gpu()`] and [`reference()`] over it, both returning a [`ViewOutput`]: the
//! top-bottom stereo equirect (left eye on top), colour only. Thin over [`StitchRenderer`] and
//! [`stitch_reference`]: no numerics of its own, so the views are exactly what those return.

use super::reference::stitch_reference;
use super::render::StitchRenderer;
use super::{FaceSet, StitchParams};
use crate::convention::Conventions;
use crate::error::Result;
use crate::pass::ToDevice;
use crate::view::ViewOutput;

/// Everything a stitch needs, GPU and f64 twin alike.
#[derive(Clone, Copy)]
pub struct StitchInput<'a> {
    /// The left eye's cube faces.
    pub left: &'a FaceSet,
    /// The right eye's cube faces (same rig, FOV and face size).
    pub right: &'a FaceSet,
    /// Method, overlap and equirect size per eye.
    pub params: StitchParams,
    /// The GPU-side row order; the output is top-down either way, so the twin has no use for
    /// them.
    pub conv: Conventions,
}

/// The GPU stitch of `input` on `device` (GL or Vulkan), with its times (one [`StitchRenderer`], one render).
pub fn gpu(device: impl ToDevice, input: &StitchInput) -> Result<ViewOutput> {
    let (image, timing) =
        StitchRenderer::with_conventions(device, input.left, input.right, input.conv)?.render(&input.params)?;
    Ok(ViewOutput::color_only(image, Some(timing)))
}

/// The float64 twin of `input`: both eyes' equirects, left on top.
pub fn reference(input: &StitchInput) -> Result<ViewOutput> {
    let mut color = stitch_reference(input.left, &input.params)?;
    color.extend(stitch_reference(input.right, &input.params)?);
    let p = &input.params;
    Ok(ViewOutput::from_color_f64(p.width, 2 * p.height, &color))
}
