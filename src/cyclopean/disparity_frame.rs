//! A stereo frame from a rectified pair with disparity maps (Middlebury style), with a nominal
//! focal length and baseline: depth Z = f B / d, eyes at -B/2 and +B/2 on a parallel rig, and the
//! middle camera halfway. Disparity 0 (unknown) and non-finite values become invalid depth.

use super::scene_frame::StereoRig;
use super::{DepthKind, EyeInput, MiddleCamera, StereoFrame};
use crate::camera::{gl_projection, Intrinsics, PinholeCamera, Pose};
use crate::convention::{Conventions, DepthPlanes};
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};

/// Left/right colour and their disparities (pixels, left: x_right = x_left - d; right:
/// x_left = x_right + d), with the nominal focal length (px) and baseline (m).
pub fn disparity_frame(
    left: (RgbImage, DepthMap),
    right: (RgbImage, DepthMap),
    focal_px: f64,
    baseline: f64,
    conv: Conventions,
) -> Result<(StereoFrame, MiddleCamera)> {
    if !(focal_px.is_finite() && focal_px > 0.0 && baseline.is_finite() && baseline > 0.0) {
        return Err(Error::param(
            "focal/baseline",
            format!("{focal_px} px, {baseline} m: both must be finite and > 0"),
        ));
    }
    let (w, h) = (left.0.width, left.0.height);
    for (name, (c, d)) in [("left", &left), ("right", &right)] {
        if (c.width, c.height) != (w, h) || (d.width, d.height) != (w, h) {
            return Err(Error::SizeMismatch {
                message: format!("{name} colour/disparity differ from the left colour's {w}x{h}"),
            });
        }
    }
    let camera = PinholeCamera {
        k: Intrinsics {
            fx: focal_px,
            fy: focal_px,
            cx: (w as f64 - 1.0) / 2.0,
            cy: (h as f64 - 1.0) / 2.0,
        },
        width: w,
        height: h,
    };
    let rig = StereoRig {
        camera,
        ipd: baseline,
        head: Pose::IDENTITY,
        planes: DepthPlanes { near: 0.01, far: 1e4 },
    };
    let to_depth = |d: &DepthMap| {
        let z = d.data.iter().map(|&v| {
            if v.is_finite() && v > 0.0 {
                (focal_px * baseline / v as f64) as f32
            } else {
                0.0
            }
        });
        DepthMap::new(w, h, z.collect()).expect("same size")
    };
    let eye = |(color, disparity): (RgbImage, DepthMap), side: f64| EyeInput {
        depth: to_depth(&disparity),
        color,
        view: rig.eye_pose(side).gl_view(),
        proj: gl_projection(&camera, &rig.planes, &conv),
    };
    let frame = StereoFrame {
        left: eye(left, -1.0),
        right: eye(right, 1.0),
        depth_kind: DepthKind::ViewZ,
        conv,
    };
    let mid = MiddleCamera {
        view: rig.head.gl_view(),
        proj: gl_projection(&camera, &rig.planes, &conv),
        width: w,
        height: h,
    };
    Ok((frame, mid))
}
