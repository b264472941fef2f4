//! The middle-ray walk of a stereo frame to any camera (seed 000): for each pixel of the view
//! the ray is walked to the surface each eye saw, and the eyes are combined. Cyclopean's
//! seed/refine methods and reproject's 3-D gather both render with it.
//!
//! - [`reference`](mod@reference): the f64 CPU twin; [`gpu`]: the GPU pass
//!   (shaders/cyclopean/gather.frag); [`ambiguity`]: the f32 error bounds the GPU-vs-twin
//!   tests excuse.

pub mod ambiguity;
pub mod gpu;
pub mod reference;

use super::Eye;
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use serde::{Deserialize, Serialize};

/// How the middle ray is walked to the surface each eye saw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// One step per eye (seed 000's rule): the point of the middle pixel's ray at the fixation
    /// distance is projected into the eye; the eye's depth at the texel it lands in, unprojected
    /// at that landing position, is the surface point, and the eye's bilinear colour there its
    /// colour (no edge-aware filter). Nothing checks that the point lies on the middle ray, so
    /// it is exact only near the fixation distance; the eyes merge by [`Blend`].
    Seed,
    /// The seed's step followed by `steps` refinement steps (each re-reads the eye's depth where
    /// the last estimate projects), then a check that the surface found projects onto this
    /// middle pixel (within `REFINE_TOLERANCE_PX`); eyes failing it are dropped. Colour is
    /// filtered edge-aware: texels at another depth (beyond `z_threshold`) get no weight.
    /// The seed is refine 0: its one step reads the texel where the fixation guess projects,
    /// which lies on the surface only near the fixation, so the check needs at least one
    /// refinement to pass elsewhere.
    Refine {
        /// Refinement steps after the seed's step, 1..=16.
        steps: u32,
    },
}

/// How the two eyes are combined where both see a surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Blend {
    /// Depth disagreement above the threshold takes the nearer eye, else the mean (seed 5.3).
    Hard,
    /// mix(nearer eye, mean, saturate(1 - dz / threshold)) (seed 8).
    Soft,
}

/// The settings of one cyclopean rendering.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CyclopeanParams {
    /// The surface walk: the seed's single step or refined.
    pub method: Method,
    /// Hard or soft combination of the eyes.
    pub blend: Blend,
    /// Middle-space depth disagreement (metres) above which the eyes are treated as seeing
    /// different surfaces. The seed suggests clamp(0.02 |zFix|, 0.02, 0.25).
    pub z_threshold: f64,
    /// Weight of the dominant eye where both are blended (0.5 each when None).
    pub dominant: Option<(Eye, f64)>,
    /// Initial depth guess: the fixation point's distance along the middle view axis (> 0).
    pub fixation_distance: f64,
}

impl CyclopeanParams {
    /// The weight of the left eye where both are blended: the dominant eye's weight, else even
    /// (one rule for the gather shader's block and the f64 twin).
    pub fn left_eye_weight(&self) -> f64 {
        match self.dominant {
            Some((Eye::Left, w)) => w,
            Some((Eye::Right, w)) => 1.0 - w,
            None => 0.5,
        }
    }

    /// The seed's settings: one step, hard blend, threshold clamp(0.02 d, 0.02, 0.25) m at fixation distance `d`.
    pub fn seed(fixation_distance: f64) -> Self {
        CyclopeanParams {
            method: Method::Seed,
            blend: Blend::Hard,
            z_threshold: (0.02 * fixation_distance).clamp(0.02, 0.25),
            dominant: None,
            fixation_distance,
        }
    }

    /// Refuses a non-positive or non-finite fixation distance or threshold, a dominant-eye weight outside [0, 1] and refine steps outside 1..=16, naming the parameter.
    pub fn validate(&self) -> Result<()> {
        if !(self.fixation_distance.is_finite() && self.fixation_distance > 0.0) {
            return Err(Error::param(
                "fixation distance",
                format!("{} must be finite and > 0", self.fixation_distance),
            ));
        }
        if !(self.z_threshold.is_finite() && self.z_threshold > 0.0) {
            return Err(Error::param(
                "z-threshold",
                format!("{} must be finite and > 0", self.z_threshold),
            ));
        }
        if let Some((_, w)) = self.dominant {
            if !(0.0..=1.0).contains(&w) {
                return Err(Error::param("dominant eye weight", format!("{w} outside [0, 1]")));
            }
        }
        if let Method::Refine { steps } = self.method {
            if steps == 0 || steps > 16 {
                return Err(Error::param("refine steps", format!("{steps} outside 1..=16")));
            }
        }
        Ok(())
    }

    /// Depth reads of the walk: the seed's step plus the refinements.
    pub(crate) fn steps(&self) -> u32 {
        match self.method {
            Method::Seed => 1,
            Method::Refine { steps } => steps + 1,
        }
    }
}

/// Which middle-view images to produce. The source bits always are (they are the validity of
/// the others and cost one byte per pixel); colour and depth not requested get no attachment and
/// no readback.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CyclopeanOutputs {
    /// Produce the colour image.
    pub color: bool,
    /// Produce the middle depth.
    pub depth: bool,
}

impl Default for CyclopeanOutputs {
    fn default() -> Self {
        CyclopeanOutputs {
            color: true,
            depth: true,
        }
    }
}

/// The middle view. Rows top-down.
#[derive(Debug, Clone)]
pub struct CyclopeanOutput {
    /// None when not requested.
    pub color: Option<RgbImage>,
    /// Middle view-space distance (metres) of the surface shown; 0 where no eye had one. None
    /// when not requested.
    pub depth: Option<DepthMap>,
    /// Per pixel, bit 0: the left eye contributed, bit 1: the right eye. 0 = invalid (the seed's
    /// fallback colour, the mean of both eyes at the same uv, is still written).
    pub sources: Vec<u8>,
}

impl CyclopeanOutput {
    /// The colour image; an error when it was not requested.
    pub fn color(&self) -> Result<&RgbImage> {
        self.color
            .as_ref()
            .ok_or_else(|| Error::param("outputs", "the middle view's colour was not requested"))
    }

    /// The middle depth; an error when it was not requested.
    pub fn depth(&self) -> Result<&DepthMap> {
        self.depth
            .as_ref()
            .ok_or_else(|| Error::param("outputs", "the middle view's depth was not requested"))
    }
}
