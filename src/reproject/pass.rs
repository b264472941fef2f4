//! The reprojection pass/twin contract: one [`ReprojectInput`] (source view, target geometry,
//! parameters), and [`gpu()`] and [`reference()`] over it, both returning a [`ViewOutput`]. Thin over
//! [`Reprojector`] and [`reproject_reference`]: no numerics of its own, so the views are exactly
//! what those return.

use super::reference::reproject_reference;
use super::render::Reprojector;
use super::{Geometry, ReprojectParams, ReprojectSource};
use crate::error::Result;
use crate::pass::ToDevice;
use crate::view::ViewOutput;

/// Everything a reprojection needs, GPU and f64 twin alike.
#[derive(Clone, Copy)]
pub struct ReprojectInput<'a> {
    /// Colour and depth of the source view, with their encoding and conventions.
    pub source: &'a ReprojectSource,
    /// Where the target view is (and its size).
    pub geometry: &'a Geometry,
    /// Method, outputs and hole threshold; both sides leave out the outputs not asked for.
    pub params: ReprojectParams,
}

/// Width and height of the target `geometry` renders.
pub fn target_size(geometry: &Geometry) -> (u32, u32) {
    match geometry {
        Geometry::Rig { camera, .. } => (camera.width, camera.height),
        Geometry::Matrices { target, .. } => (target.width, target.height),
    }
}

/// The GPU reprojection of `input` on `device` (GL or Vulkan), with its times (one [`Reprojector`], one render).
pub fn gpu(device: impl ToDevice, input: &ReprojectInput) -> Result<ViewOutput> {
    let (out, timing) = Reprojector::new(device, input.source, input.geometry, input.params)?.render()?;
    let (w, h) = target_size(input.geometry);
    Ok(ViewOutput::from_reproject(&out, w, h, Some(timing)))
}

/// The float64 twin of `input`, with the planes `input.params.outputs` leaves out removed.
pub fn reference(input: &ReprojectInput) -> Result<ViewOutput> {
    let r = reproject_reference(input.source, input.geometry, &input.params)?;
    let mut view = ViewOutput::from_reproject_reference(&r);
    if !input.params.outputs.color {
        view.color = None;
    }
    if !input.params.outputs.depth {
        view.depth = None;
    }
    Ok(view)
}

impl super::ReprojectOutput {
    /// [`crate::view::clear_non_finite`] on the planes read back.
    pub fn finite(mut self) -> Self {
        crate::view::clear_non_finite(self.depth.as_mut().map(|d| d.data.as_mut_slice()), Some(&mut self.mask));
        self
    }
}

impl ViewOutput {
    /// A reprojection GPU output of a `width` x `height` target.
    pub fn from_reproject(
        out: &super::ReprojectOutput,
        width: u32,
        height: u32,
        timing: Option<crate::pass::Timing>,
    ) -> Self {
        Self::from_gpu(
            width,
            height,
            out.color.clone(),
            out.depth.clone(),
            out.mask.clone(),
            timing,
        )
    }

    /// The reprojection f64 twin; the mask is 255 where valid, as the GPU writes it.
    pub fn from_reproject_reference(r: &super::reference::ReprojectReference) -> Self {
        Self::from_f64_twin(r.width, r.height, &r.color, &r.depth, &r.mask)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reproject::reference::ReprojectReference;

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
