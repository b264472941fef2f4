//! A stereo frame from a rectified pair with disparity maps (Middlebury style): depth
//! Z = f B / (d + doffs), eyes at -B/2 and +B/2 on a parallel rig, and the in-between camera at
//! x = (t - 1/2) B. Disparity 0 (unknown) and non-finite values become invalid depth.
//!
//! With `doffs` (the right principal point minus the left one, Middlebury 2014) the right eye's
//! principal point is `cx + doffs` and the in-between camera's `cx + t doffs`: then every image
//! shift is exactly `t d`, whatever f, B and doffs, and only the metric depth depends on them.
//!
//! With `offset` the stored values are d + offset (the signed matcher's maps, see
//! [`crate::stereo::matcher::range`]): 0 stays unknown, the image shift is the stored value
//! minus the offset and the depth f B / (stored - offset + doffs).

use super::scene_frame::StereoRig;
use super::{EyeInput, FrameDepth, MiddleCamera, StereoFrame};
use crate::camera::{gl_projection, Intrinsics, PinholeCamera, Pose};
use crate::convention::{Conventions, DepthPlanes};
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};

/// The rectified rig: focal length (px), baseline (m), principal-point offset (px) and the
/// position of the synthesised view (0 = left eye, 1 = right eye).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisparityRig {
    /// Focal length, pixels.
    pub focal_px: f64,
    /// Baseline between the eyes, metres.
    pub baseline: f64,
    /// Right principal point x minus the left one, pixels (Middlebury 2014's `doffs`).
    pub doffs: f64,
    /// Position of the synthesised view along the baseline: 0 = left eye, 1 = right eye.
    pub position: f64,
    /// What the stored disparities hold above the image shift, pixels (0: they are the shift).
    pub offset: f64,
}

impl DisparityRig {
    /// The middle view of a rig with no principal-point offset.
    pub fn middle(focal_px: f64, baseline: f64) -> Self {
        DisparityRig {
            focal_px,
            baseline,
            doffs: 0.0,
            position: 0.5,
            offset: 0.0,
        }
    }

    /// Refuses a non-positive or non-finite focal length or baseline, a non-finite doffs and a position outside its range.
    pub fn validate(&self) -> Result<()> {
        if !(self.focal_px.is_finite() && self.focal_px > 0.0 && self.baseline.is_finite() && self.baseline > 0.0) {
            return Err(Error::param(
                "focal/baseline",
                format!("{} px, {} m: both must be finite and > 0", self.focal_px, self.baseline),
            ));
        }
        if !self.doffs.is_finite() {
            return Err(Error::param("doffs", format!("{} must be finite", self.doffs)));
        }
        if !(self.offset.is_finite() && self.offset >= 0.0) {
            return Err(Error::param(
                "disparity offset",
                format!("{} must be finite and >= 0", self.offset),
            ));
        }
        if !(0.0..=1.0).contains(&self.position) {
            return Err(Error::param(
                "position",
                format!("{} outside [0, 1] (0 = left eye, 1 = right eye)", self.position),
            ));
        }
        Ok(())
    }
}

/// Left/right colour and their disparities (pixels, left: x_right = x_left - d; right:
/// x_left = x_right + d) on `rig`.
pub fn disparity_frame(
    left: (RgbImage, DepthMap),
    right: (RgbImage, DepthMap),
    rig: &DisparityRig,
    conv: Conventions,
) -> Result<(StereoFrame, MiddleCamera)> {
    rig.validate()?;
    let (w, h) = (left.0.width, left.0.height);
    for (name, (c, d)) in [("left", &left), ("right", &right)] {
        if (c.width, c.height) != (w, h) || (d.width, d.height) != (w, h) {
            return Err(Error::SizeMismatch {
                message: format!(
                    "{name} colour {}x{} / disparity {}x{} differ from the left colour's {w}x{h}",
                    c.width, c.height, d.width, d.height
                ),
            });
        }
    }
    let camera_at = |shift: f64| PinholeCamera {
        k: Intrinsics {
            fx: rig.focal_px,
            fy: rig.focal_px,
            cx: (w as f64 - 1.0) / 2.0 + shift,
            cy: (h as f64 - 1.0) / 2.0,
        },
        width: w,
        height: h,
    };
    let stereo = StereoRig {
        camera: camera_at(0.0),
        ipd: rig.baseline,
        head: Pose::IDENTITY,
        planes: DepthPlanes { near: 0.01, far: 1e4 },
    };
    let fb = rig.focal_px * rig.baseline;
    let to_depth = |d: &DepthMap| {
        let z = d.data.iter().map(|&v| {
            let v = v as f64;
            let shift = v - rig.offset;
            if v.is_finite() && v > 0.0 && shift + rig.doffs > 0.0 {
                (fb / (shift + rig.doffs)) as f32
            } else {
                0.0
            }
        });
        let mut z: Vec<f32> = z.collect();
        // f B / d leaves the usable magnitudes for tiny disparities: holes, as a loader makes them.
        crate::depth::clear_unusable_depth(&mut z);
        DepthMap::new(w, h, z).expect("same size")
    };
    let eye = |(color, disparity): (RgbImage, DepthMap), side: f64, shift: f64| EyeInput {
        depth: to_depth(&disparity),
        color,
        view: stereo.eye_pose(side).gl_view(),
        proj: gl_projection(&camera_at(shift), &stereo.planes, &conv),
    };
    let frame = StereoFrame {
        left: eye(left, -1.0, 0.0),
        right: eye(right, 1.0, rig.doffs),
        depth_kind: FrameDepth::ViewZ,
        conv,
    };
    let mid = MiddleCamera {
        view: stereo.eye_pose(2.0 * rig.position - 1.0).gl_view(),
        proj: gl_projection(&camera_at(rig.position * rig.doffs), &stereo.planes, &conv),
        width: w,
        height: h,
    };
    Ok((frame, mid))
}

/// The fixation the seed and refine methods start from on a rectified pair: the median depth
/// the left eye saw (a far or near fixation leaves more of the view to the refinement). None
/// when the left eye has no known depth.
pub fn median_fixation(frame: &StereoFrame) -> Option<f64> {
    let mut z: Vec<f32> = frame.left.depth.data.iter().copied().filter(|z| *z > 0.0).collect();
    if z.is_empty() {
        return None;
    }
    let half = z.len() / 2;
    Some(*z.select_nth_unstable_by(half, f32::total_cmp).1 as f64)
}
