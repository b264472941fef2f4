//! The refocus pass/twin contract: one [`RefocusInput`] (source, target camera, settings), and
//! [`gpu()`] and [`reference()`] over it, both returning a [`ViewOutput`]. Thin over
//! [`Refocuser`] and [`super::reference::refocus_reference_with`]: no numerics of its own, so the views are exactly
//! what those return. A caller refocusing many targets of one source keeps a [`Refocuser`]
//! (programs and uploads are per renderer); this is the shape the tests hold both sides to.

use super::reference::refocus_reference_with;
use super::{BreakRule, Method, OutputSet, RefocusSource, Refocuser};
use crate::camera::PinholeCamera;
use crate::convention::Conventions;
use crate::error::Result;
use crate::pass::ToDevice;
use crate::view::ViewOutput;

/// Everything a refocus needs, GPU and f64 twin alike.
#[derive(Clone, Copy)]
pub struct RefocusInput<'a> {
    /// Colour, depth and intrinsics of the source.
    pub source: &'a RefocusSource,
    /// The camera to render (same pose, other intrinsics and size).
    pub target: &'a PinholeCamera,
    /// Which grid edges break the mesh.
    pub rule: BreakRule,
    /// How the GPU rasterises (the twin is exact either way).
    pub method: Method,
    /// Which planes to produce; both sides leave out the others.
    pub outputs: OutputSet,
    /// Colour every pixel inside the source frame, covered or not (`--rgb-everywhere`).
    pub rgb_everywhere: bool,
    /// GPU conventions; the outputs are top-down view Z whatever they are, so the twin has no use
    /// for them.
    pub conv: Conventions,
}

/// The GPU refocus of `input` (one [`Refocuser`], one target) on `device`: a GL context or
/// either executor's [`crate::pass::Device`].
pub fn gpu(device: impl ToDevice, input: &RefocusInput) -> Result<ViewOutput> {
    let mut r = Refocuser::new(
        device,
        input.source,
        &input.rule,
        input.method,
        input.outputs,
        input.conv,
    )?;
    r.set_rgb_everywhere(input.rgb_everywhere);
    let out = r.render(input.target)?;
    Ok(ViewOutput::from_refocus(&out))
}

/// The float64 twin of `input`, with the planes `input.outputs` leaves out removed.
pub fn reference(input: &RefocusInput) -> Result<ViewOutput> {
    input.rule.validate()?;
    input.source.validate()?;
    // As the renderer does: the twin refuses what the GPU refuses.
    input.target.validate("target camera")?;
    let r = refocus_reference_with(input.source, &input.rule, input.target, input.rgb_everywhere);
    let mut view = ViewOutput::from_refocus_reference(&r);
    let o = input.outputs;
    if !o.rgb {
        view.color = None;
    }
    if !o.depth {
        view.depth = None;
    }
    if !o.mask {
        view.mask = None;
    }
    Ok(view)
}

impl super::RefocusOutput {
    /// [`crate::view::clear_non_finite`] on the planes read back.
    pub fn finite(mut self) -> Self {
        let mask = self.mask.as_mut().map(|m| m.data.as_mut_slice());
        crate::view::clear_non_finite(self.depth.as_mut().map(|d| d.data.as_mut_slice()), mask);
        self
    }
}

impl ViewOutput {
    /// A refocus GPU output.
    pub fn from_refocus(out: &super::RefocusOutput) -> Self {
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
    pub fn from_refocus_reference(r: &super::reference::ReferenceImage) -> Self {
        Self::from_f64_twin(r.width, r.height, &r.rgb, &r.depth, &r.mask)
    }
}
