//! stereo: the geometry of a stereo pair below the capabilities that render it: the frame
//! types (each eye's colour, depth and matrices; the middle camera), the camera file, frames
//! from disparities, the stereo matcher and densify, and the middle-ray walk ([`gather`]) that
//! both cyclopean's seed/refine and reproject's 3-D gather run.
//!
//! - [`matcher`]: the census and semi-global stereo matchers (GPU pass and CPU twin), for pairs
//!   without ground-truth disparities; [`trust`]: which semi-global disparities are matched and
//!   which inferred; [`densify`]: unknown disparities filled along 16 walks.
//! - [`camera_file`], [`camera_spec`]: the eyes' and the view's cameras from a JSON file.
//! - [`disparity_frame`]: a rectified pair with disparities as a frame; [`one_eye`]: the other
//!   eye's disparities from one.
//! - [`scene_frame`]: a stereo frame of the built-in scene under any conventions, for tests,
//!   the demo and the report.

pub mod camera_file;
pub mod camera_spec;
pub mod densify;
pub mod densify_reference;
pub mod disparity_frame;
pub mod frame_depth;
pub mod gather;
pub mod matcher;
pub mod one_eye;
pub mod scene_frame;
pub mod trust;
pub mod trust_reference;
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

/// One eye of the rig.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Eye {
    /// The left eye.
    Left,
    /// The right eye.
    Right,
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
