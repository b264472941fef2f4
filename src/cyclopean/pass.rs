//! The cyclopean pass/twin contract: one [`CyclopeanInput`] (stereo frame, middle camera, which
//! pass with its parameters, outputs), and [`gpu()`] and [`reference()`] over it, both returning a
//! [`ViewOutput`] whose mask holds the source-eye bits. Thin over the renderers
//! ([`CyclopeanRenderer`], [`SplatRenderer`]) and their f64 twins ([`cyclopean_reference`],
//! [`splat_reference`]): no numerics of its own, so the views are exactly what those return.

use super::splat::{SplatParams, SplatRenderer};
use super::splat_reference::splat_reference;
use crate::error::Result;
use crate::stereo::gather::gpu::CyclopeanRenderer;
use crate::stereo::gather::reference::cyclopean_reference;
use crate::stereo::gather::{CyclopeanOutputs, CyclopeanParams};
use crate::stereo::{MiddleCamera, StereoFrame};
use crate::view::ViewOutput;

/// Which middle-view pass, with its parameters.
#[derive(Debug, Clone, Copy)]
pub enum CyclopeanPass {
    /// The per-pixel gather (walk the middle ray to each eye's surface).
    Gather(CyclopeanParams),
    /// The forward splat of both eyes' meshes.
    Splat(SplatParams),
}

/// Everything a middle view needs, GPU and f64 twin alike.
#[derive(Clone, Copy)]
pub struct CyclopeanInput<'a> {
    /// Both eyes' colour, depth and cameras, with their conventions.
    pub frame: &'a StereoFrame,
    /// The middle camera to render.
    pub mid: &'a MiddleCamera,
    /// The pass and its parameters.
    pub pass: CyclopeanPass,
    /// Colour and depth wanted (the source bits always); both sides leave out the others.
    pub outputs: CyclopeanOutputs,
}

/// The GPU middle view of `input`, with its times (one renderer, one middle camera).
pub fn gpu(gpu: impl crate::pass::ToDevice, input: &CyclopeanInput) -> Result<ViewOutput> {
    let (out, timing) = match input.pass {
        CyclopeanPass::Gather(params) => {
            CyclopeanRenderer::with_outputs(gpu, input.frame, params, input.outputs)?.render(input.mid)?
        }
        CyclopeanPass::Splat(params) => {
            SplatRenderer::new(gpu, input.frame, params, input.outputs)?.render(input.mid)?
        }
    };
    Ok(ViewOutput::from_cyclopean(
        &out,
        input.mid.width,
        input.mid.height,
        Some(timing),
    ))
}

/// The float64 twin of `input`, with the planes `input.outputs` leaves out removed.
pub fn reference(input: &CyclopeanInput) -> Result<ViewOutput> {
    let r = match &input.pass {
        CyclopeanPass::Gather(params) => cyclopean_reference(input.frame, input.mid, params)?,
        CyclopeanPass::Splat(params) => splat_reference(input.frame, input.mid, params)?,
    };
    let mut view = ViewOutput::from_cyclopean_reference(&r, input.mid.width, input.mid.height);
    if !input.outputs.color {
        view.color = None;
    }
    if !input.outputs.depth {
        view.depth = None;
    }
    Ok(view)
}

impl crate::stereo::gather::CyclopeanOutput {
    /// [`crate::view::clear_non_finite`] on the planes read back (the source bits are the mask).
    pub fn finite(mut self) -> Self {
        crate::view::clear_non_finite(
            self.depth.as_mut().map(|d| d.data.as_mut_slice()),
            Some(&mut self.sources),
        );
        self
    }
}

impl ViewOutput {
    /// A cyclopean GPU output of a `width` x `height` middle camera (mask: the source bits).
    pub fn from_cyclopean(
        out: &crate::stereo::gather::CyclopeanOutput,
        width: u32,
        height: u32,
        timing: Option<crate::pass::Timing>,
    ) -> Self {
        Self::from_gpu(
            width,
            height,
            out.color.clone(),
            out.depth.clone(),
            out.sources.clone(),
            timing,
        )
    }

    /// The cyclopean f64 twin of a `width` x `height` middle camera.
    pub fn from_cyclopean_reference(
        r: &crate::stereo::gather::reference::CyclopeanReference,
        width: u32,
        height: u32,
    ) -> Self {
        Self::from_f64_twin_mask(width, height, &r.color, &r.depth, r.sources.clone())
    }
}
