//! The stitch pass/twin contract: one [`StitchInput`] (both eyes' faces, parameters,
//! conventions), and [`gpu()`] and [`reference()`] over it, both returning a [`ViewOutput`]: the
//! top-bottom stereo equirect (left eye on top): colour and, as its depth plane, the distance
//! along each pixel's ODS ray (0 = sky; no mask). Thin over [`StitchRenderer`] and
//! [`stitch_reference_eye`]: no numerics of its own, so the views are exactly what those return.

use super::reference::stitch_reference_eye;
use super::render::StitchRenderer;
use super::{FaceSet, StitchParams};
use crate::convention::Conventions;
use crate::error::Result;
use crate::output::OutputSet;
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
    /// Which planes to produce (rgb, depth: the ray distance); both sides leave out the others.
    pub outputs: OutputSet,
    /// The GPU-side row order; the output is top-down either way, so the twin has no use for
    /// them.
    pub conv: Conventions,
}

/// The GPU stitch of `input` on `device` (GL or Vulkan), with its times (one [`StitchRenderer`], one render).
pub fn gpu(device: impl ToDevice, input: &StitchInput) -> Result<ViewOutput> {
    let out = StitchRenderer::with_conventions(device, input.left, input.right, input.conv)?
        .render_outputs(&input.params, input.outputs)?;
    Ok(ViewOutput::from_stitch(out.color, out.distance, Some(out.timing)))
}

/// The float64 twin of `input`: both eyes' equirects, left on top.
pub fn reference(input: &StitchInput) -> Result<ViewOutput> {
    super::render::check_outputs(input.outputs)?;
    let mut both = stitch_reference_eye(input.left, &input.params)?;
    let right = stitch_reference_eye(input.right, &input.params)?;
    both.color.extend(right.color);
    both.distance.extend(right.distance);
    let p = &input.params;
    let mut view = ViewOutput::from_stitch_f64(p.width, 2 * p.height, &both.color, &both.distance);
    if !input.outputs.rgb {
        view.color = None;
    }
    if !input.outputs.depth {
        view.depth = None;
        if let Some(e) = view.exact.as_mut() {
            e.depth = None;
        }
    }
    Ok(view)
}
