//! cyclopean: the middle (spectator) view of a stereo pair from each eye's colour and depth,
//! without rendering a third camera (seed 000).
//!
//! For each middle pixel the middle ray is walked to the surface each eye saw: start at the
//! fixation depth, project into the eye, read its depth there, reconstruct that surface point,
//! and take its middle-view depth as the next guess. The seed stops after one such step
//! ([`Method::Seed`]); [`Method::Refine`] iterates and then checks that the surface found really
//! projects onto this middle pixel, which rejects disoccluded samples the seed would smear.
//! Left/right conflicts are resolved by middle-space depth (hard threshold or soft blend, with an
//! optional dominant eye).
//!
//! - [`reference`](mod@reference): the f64 CPU twin; [`render`]: the GPU pass (shaders/cyclopean/gather.frag).
//! - [`pass`]: the pass/twin contract, [`pass::gpu`] and [`pass::reference`] over one
//!   [`CyclopeanInput`] (gather or splat), both returning a [`crate::view::ViewOutput`].
//! - [`matcher`]: the census stereo matcher (GPU pass and CPU twin), for pairs without
//!   ground-truth disparities.
//! - [`scene_frame`]: a stereo frame of the built-in scene under any conventions, for tests,
//!   the demo and the report.

pub mod ambiguity;
pub mod baseline;
pub mod camera_file;
pub mod camera_spec;
pub mod densify;
pub mod disparity_frame;
pub mod edge_snap;
pub mod fill;
pub mod forward;
pub mod frame_depth;
pub mod matcher;
pub mod one_eye;
pub mod pass;
pub mod reference;
pub mod render;
pub mod scene_frame;
pub mod splat;
pub mod splat_reference;
pub mod temporal;
pub mod walk;

use crate::camera::mat4::{self, Mat4};
use crate::convention::Conventions;
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use serde::{Deserialize, Serialize};

pub use frame_depth::FrameDepth;

/// The ray basis of `m` ([`crate::camera::rays::ray_basis`]: pixel rays the same under every
/// convention) as a std140 mat4 for the shaders' `view_ray`; `what` names `m` in the refusal.
pub(crate) fn ray_basis_std140(m: &Mat4, what: &str) -> Result<[[f32; 4]; 4]> {
    crate::camera::rays::ray_basis(m)
        .map(|b| crate::pass::mat4_std140(&b))
        .ok_or_else(|| Error::param(what.to_string(), "not perspective"))
}
pub use pass::{CyclopeanInput, CyclopeanPass};

/// One eye: colour, depth (rows top-down) and the GL matrices it was rendered with.
#[derive(Debug, Clone)]
pub struct EyeInput {
    /// 8-bit colour, rows top-down.
    pub color: RgbImage,
    /// The eye's depth, as the frame's `depth_kind` says, rows top-down.
    pub depth: DepthMap,
    /// World -> GL eye space.
    pub view: Mat4,
    /// GL eye space -> clip, matching the frame's conventions (y flipped for top-down rows).
    pub proj: Mat4,
}

/// A stereo frame.
#[derive(Debug, Clone)]
pub struct StereoFrame {
    /// The left eye.
    pub left: EyeInput,
    /// The right eye.
    pub right: EyeInput,
    /// What both eyes' depth maps hold.
    pub depth_kind: FrameDepth,
    /// NDC depth range, reversed-Z and row order the eyes were rendered under.
    pub conv: Conventions,
}

/// The middle (preview) camera: GL view and projection, and the output size.
#[derive(Debug, Clone, Copy)]
pub struct MiddleCamera {
    /// World -> GL eye transform (-Z forward), row-major.
    pub view: Mat4,
    /// GL eye -> clip projection under the frame's conventions, row-major.
    pub proj: Mat4,
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
}

impl MiddleCamera {
    /// The seed's middle camera: origin halfway between the gaze origins, head orientation
    /// (`head_rotation` columns = head x, y, z axes in world, GL convention: -z forward).
    pub fn from_gaze(
        gaze_left: [f64; 3],
        gaze_right: [f64; 3],
        head_rotation: [[f64; 3]; 3],
        proj: Mat4,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let e = [0.0, 1.0, 2.0].map(|i: f64| 0.5 * (gaze_left[i as usize] + gaze_right[i as usize]));
        let r = head_rotation;
        let world_from_head: Mat4 = [
            [r[0][0], r[0][1], r[0][2], e[0]],
            [r[1][0], r[1][1], r[1][2], e[1]],
            [r[2][0], r[2][1], r[2][2], e[2]],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let view = mat4::inverse(&world_from_head).ok_or_else(|| Error::param("head rotation", "singular"))?;
        Ok(MiddleCamera {
            view,
            proj,
            width,
            height,
        })
    }
}

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

/// One eye of the rig.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Eye {
    /// The left eye.
    Left,
    /// The right eye.
    Right,
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

impl StereoFrame {
    /// Refuses colour and depth of different sizes, depth values outside the usable magnitudes
    /// ([`crate::depth::check_usable_depth`]), and non-finite or singular eye matrices.
    pub fn validate(&self) -> Result<()> {
        for (name, eye) in [("left", &self.left), ("right", &self.right)] {
            if (eye.color.width, eye.color.height) != (eye.depth.width, eye.depth.height) {
                return Err(Error::SizeMismatch {
                    message: format!(
                        "{name} eye: colour {}x{} vs depth {}x{}",
                        eye.color.width, eye.color.height, eye.depth.width, eye.depth.height
                    ),
                });
            }
            crate::depth::check_usable_depth(&format!("{name} eye depth"), &eye.depth.data)?;
            for (what, m) in [("view", &eye.view), ("projection", &eye.proj)] {
                if m.iter().flatten().any(|v| !v.is_finite()) || mat4::inverse(m).is_none() {
                    return Err(Error::param(
                        format!("{name} {what} matrix"),
                        "not finite or not invertible",
                    ));
                }
            }
        }
        Ok(())
    }
}
