//! Faces of a stereo 360 capture: ray traced from the built-in scene ([`scene_faces`]) or
//! assembled from images loaded elsewhere ([`faces_from_images`]).

use super::{face_camera, CubeFace, FaceImage, FaceSet, OdsRig, Side};
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use crate::scene;

/// The six faces of `side`, N x N, FOV `fov_deg`, from the f64 ray tracer: colour rounded to
/// 8 bits, view-space Z, 0 where no surface is hit.
pub fn scene_faces(rig: &OdsRig, side: Side, n: u32, fov_deg: f64) -> Result<FaceSet> {
    rig.validate()?;
    if !(2..=crate::io::MAX_DIMENSION).contains(&n) {
        return Err(Error::param("face size", format!("{n} outside 2..=16384")));
    }
    if !(fov_deg > 90.0 && fov_deg < 178.0) {
        return Err(Error::param("face fov", format!("{fov_deg} deg outside (90, 178)")));
    }
    let cam = face_camera(n, fov_deg);
    let faces: Vec<FaceImage> = std::thread::scope(|s| {
        let handles: Vec<_> = CubeFace::ALL
            .iter()
            .map(|f| {
                let pose = f.pose(rig, side);
                s.spawn(move || scene::render_posed(&cam, &pose))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                let (color, depth) = h.join().expect("face rendering does not panic");
                FaceImage { color, depth }
            })
            .collect()
    });
    let set = FaceSet {
        rig: *rig,
        side,
        fov_deg,
        faces,
    };
    set.validate()?;
    Ok(set)
}

/// A face set from images (colour + view-space Z per face, [`CubeFace::ALL`] order), e.g.
/// loaded with `crate::io`; the faces must have been rendered with the poses
/// [`CubeFace::pose`] gives for `rig` and `side`.
pub fn faces_from_images(rig: &OdsRig, side: Side, fov_deg: f64, images: Vec<(RgbImage, DepthMap)>) -> Result<FaceSet> {
    let set = FaceSet {
        rig: *rig,
        side,
        fov_deg,
        faces: images
            .into_iter()
            .map(|(color, depth)| FaceImage { color, depth })
            .collect(),
    };
    set.validate()?;
    Ok(set)
}
