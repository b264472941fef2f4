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
