//! Faces of a stereo 360 capture: ray traced from the built-in scene ([`scene_faces`]) or
//! assembled from images loaded elsewhere ([`faces_from_images`]).

use super::{face_camera, CubeFace, FaceImage, FaceSet, OdsRig, Side};
use crate::convention::Conventions;
use crate::depth::DepthEncoding;
use crate::error::{Error, Result};
use crate::io::{self, DepthDecode, DepthMap, RgbImage};
use std::path::{Path, PathBuf};

/// File name tags of the faces in a face folder, in [`CubeFace::ALL`] order (+Z, -Z, up, down,
/// +X, -X).
pub const FACE_TAGS: [&str; 6] = ["pz", "nz", "up", "down", "px", "nx"];
/// Colour file extensions tried in a face folder, in this order.
pub const FACE_COLOR_EXTS: [&str; 5] = ["png", "jpg", "jpeg", "ppm", "exr"];
/// Depth (view-space Z) file extensions tried in a face folder, in this order.
pub const FACE_DEPTH_EXTS: [&str; 5] = ["exr", "npy", "npz", "pfm", "png"];
use crate::world;

/// The six faces of `side`, N x N, FOV `fov_deg`, from the f64 ray tracer: colour rounded to
/// 8 bits, view-space Z, 0 where no surface is hit.
pub fn scene_faces(rig: &OdsRig, side: Side, n: u32, fov_deg: f64) -> Result<FaceSet> {
    scene_faces_of(&world::demo_scene(), rig, side, n, fov_deg)
}

/// [`scene_faces`] for any scene (built in or loaded).
pub fn scene_faces_of(scene: &world::Scene, rig: &OdsRig, side: Side, n: u32, fov_deg: f64) -> Result<FaceSet> {
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
                s.spawn(move || world::render_scene(scene, &cam, &pose))
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

/// Face depth as view Z (what the stitch reads) from what a face file holds: view Z passes
/// through; device depth under `conv` (written with its planes) is converted in f64, the far
/// value and anything invalid becoming 0 (background). Disparity has no meaning for a face.
pub fn view_z_of(depth: &DepthMap, kind: &DepthEncoding, conv: &Conventions) -> Result<DepthMap> {
    kind.validate()?;
    match kind {
        DepthEncoding::ViewZ => Ok(depth.clone()),
        DepthEncoding::Device { .. } => Ok(kind.view_z_map(conv, depth)),
        DepthEncoding::Disparity { .. } => Err(Error::param(
            "face depth kind",
            "disparity has no meaning for a cube face: give view Z or device depth",
        )),
        DepthEncoding::ViewDistance => Err(Error::param(
            "face depth kind",
            "view distance along the ray is not read for cube faces: give view Z or device depth",
        )),
    }
}

/// `dir/stem.ext` for the one extension of `exts` that exists; the error names the first
/// candidate and what it should hold, or every file found when more than one exists (which
/// one is meant cannot be guessed).
fn find_face_file(dir: &Path, stem: &str, exts: &[&str], what: &str) -> Result<PathBuf> {
    let candidates: Vec<PathBuf> = exts.iter().map(|e| dir.join(format!("{stem}.{e}"))).collect();
    // A FIFO, device or folder under a face's name is named as such, not taken for absent.
    if let Some(odd) = candidates.iter().find(|p| p.exists() && !p.is_file()) {
        return Err(Error::io(
            odd,
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("{what}: not a regular file (faces are read from regular files only)"),
            ),
        ));
    }
    let found: Vec<PathBuf> = candidates.into_iter().filter(|p| p.is_file()).collect();
    if found.len() > 1 {
        let names: Vec<String> = found.iter().map(|p| p.display().to_string()).collect();
        return Err(Error::decode(
            dir,
            format!("{what}: {} files, keep one: {}", found.len(), names.join(" and ")),
        ));
    }
    found.into_iter().next().ok_or_else(|| {
        Error::io(
            dir.join(format!("{stem}.{}", exts[0])),
            std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!("missing {what} (also looked for .{})", exts[1..].join(", .")),
            ),
        )
    })
}

/// How a face folder's depth files are read.
#[derive(Debug, Clone, Copy)]
pub struct FaceDepthFiles<'a> {
    /// Integer depth scale and the like.
    pub decode: &'a DepthDecode,
    /// The array of `.npz` depth files (refused for any other format); None: the only array,
    /// else the first floating-point one.
    pub npz_key: Option<&'a str>,
}

/// The six faces of `side` from a face folder: colour `{left,right}_{tag}.{png,jpg,jpeg,ppm,exr}`
/// and view-space Z `{left,right}_{tag}_depth.{exr,npy,npz,pfm,png}` ([`FACE_TAGS`]; integer depth
/// decoded as `files` says; device depth converted with [`view_z_of`]), rendered with the poses
/// [`CubeFace::pose`] gives for `rig`.
pub fn load_face_dir(
    dir: &Path,
    rig: &OdsRig,
    side: Side,
    fov_deg: f64,
    files: FaceDepthFiles<'_>,
    kind: &DepthEncoding,
    conv: &Conventions,
) -> Result<FaceSet> {
    if !dir.is_dir() {
        return Err(Error::io(
            dir,
            std::io::Error::new(std::io::ErrorKind::NotFound, "not a directory"),
        ));
    }
    let eye = match side {
        Side::Left => "left",
        Side::Right => "right",
    };
    let mut images = Vec::new();
    for (face, tag) in CubeFace::ALL.iter().zip(FACE_TAGS) {
        let what = format!("the {eye} eye's {} face", face.label());
        let c = find_face_file(
            dir,
            &format!("{eye}_{tag}"),
            &FACE_COLOR_EXTS,
            &format!("colour of {what}"),
        )?;
        let d = find_face_file(
            dir,
            &format!("{eye}_{tag}_depth"),
            &FACE_DEPTH_EXTS,
            &format!("view-space Z of {what}"),
        )?;
        let depth =
            view_z_of(&io::load_depth_with_key(&d, files.npz_key, files.decode)?, kind, conv).map_err(|e| match e {
                Error::InvalidParameter { name, message } => Error::decode(&d, format!("{name}: {message}")),
                other => other,
            })?;
        images.push((io::load_rgb(&c)?, depth));
    }
    faces_from_images(rig, side, fov_deg, images)
}
