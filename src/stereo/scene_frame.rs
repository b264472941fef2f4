//! A stereo frame of the built-in scene, rendered exactly (f64 ray tracing) under any
//! conventions, with the ray-traced middle view as ground truth.

use super::{EyeInput, FrameDepth, MiddleCamera, StereoFrame};
use crate::camera::{gl_projection, PinholeCamera, Pose};
use crate::convention::{Conventions, DepthPlanes};
use crate::depth::DepthEncoding;
use crate::io::{DepthMap, RgbImage};
use crate::world;

/// A parallel stereo rig: both eyes share the head's orientation, offset by ∓ipd/2 along its x.
#[derive(Debug, Clone, Copy)]
pub struct StereoRig {
    /// Intrinsics and image size shared by both eyes and the middle camera.
    pub camera: PinholeCamera,
    /// Interpupillary distance (eye separation), metres.
    pub ipd: f64,
    /// The middle (cyclopean) camera's pose.
    pub head: Pose,
    /// Near and far planes of the eyes' projections (device depth is written with them).
    pub planes: DepthPlanes,
}

impl StereoRig {
    /// 64 mm IPD at the demo camera's pose, near 0.05 m, far 100 m.
    pub fn demo(width: u32, height: u32) -> Self {
        StereoRig {
            camera: world::demo_camera(width, height),
            ipd: 0.064,
            head: Pose::IDENTITY,
            planes: DepthPlanes { near: 0.05, far: 100.0 },
        }
    }

    /// Pose of one eye: `side` -1 for the left, +1 for the right (offset `side` * ipd / 2 along the head's x).
    pub fn eye_pose(&self, side: f64) -> Pose {
        self.right_of_head(0.5 * side * self.ipd)
    }

    /// The head's pose moved `metres` along its own x axis (to its right; negative: left).
    pub fn right_of_head(&self, metres: f64) -> Pose {
        let r = &self.head.rotation;
        let p = self.head.position;
        Pose {
            rotation: *r,
            position: [0, 1, 2].map(|axis| p[axis] + metres * r[axis][0]),
        }
    }
}

/// Ground truth of the middle view.
pub struct MiddleTruth {
    /// Colour of the ray-traced middle view.
    pub color: RgbImage,
    /// Middle view-space distance; 0 where the scene has no surface.
    pub depth: DepthMap,
}

fn eye_input(rig: &StereoRig, pose: &Pose, conv: &Conventions, kind: FrameDepth) -> EyeInput {
    let (color, z) = world::render_posed(&rig.camera, pose);
    let depth = match kind {
        FrameDepth::ViewZ => z,
        FrameDepth::Device => {
            let far = conv.clear_depth() as f32;
            let encoding = DepthEncoding::Device { planes: rig.planes };
            let data = z
                .data
                .iter()
                .map(|&v| {
                    if v > 0.0 {
                        encoding.encode(conv, v as f64, 1.0) as f32
                    } else {
                        far
                    }
                })
                .collect();
            DepthMap::new(z.width, z.height, data).expect("same size")
        }
    };
    // Reversed-Z device depth of far surfaces can fall below the usable magnitudes: holes.
    let mut depth = depth;
    crate::depth::clear_unusable_depth(&mut depth.data);
    EyeInput {
        color,
        depth,
        view: pose.gl_view(),
        proj: gl_projection(&rig.camera, &rig.planes, conv),
    }
}

/// Left/right eyes, the middle camera (same intrinsics as the eyes) and its ground truth.
pub fn scene_frame(rig: &StereoRig, conv: Conventions, kind: FrameDepth) -> (StereoFrame, MiddleCamera, MiddleTruth) {
    let frame = StereoFrame {
        left: eye_input(rig, &rig.eye_pose(-1.0), &conv, kind),
        right: eye_input(rig, &rig.eye_pose(1.0), &conv, kind),
        depth_kind: kind,
        conv,
    };
    let mid = MiddleCamera {
        view: rig.head.gl_view(),
        proj: gl_projection(&rig.camera, &rig.planes, &conv),
        width: rig.camera.width,
        height: rig.camera.height,
    };
    let (color, depth) = world::render_posed(&rig.camera, &rig.head);
    (frame, mid, MiddleTruth { color, depth })
}
