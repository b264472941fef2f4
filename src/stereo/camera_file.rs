//! The cameras of a stereo frame as a JSON file, for `viewsynth cyclopean`.
//!
//! ```json
//! { "conventions": { "ndc_depth": "minus-one-to-one", "reversed_z": false, "row_order": "bottom-up" },
//!   "depth_kind": "device",
//!   "left":  { "view": [[1,0,0,0.032],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "proj": [[..4], [..4], [..4], [..4]] },
//!   "right": { "view": [..], "proj": [..] },
//!   "middle": { "proj": [..], "width": 640, "height": 480 },
//!   "gaze": { "left":  { "origin": [-0.032,0,0], "direction": [0.01,0,-1] },
//!             "right": { "origin": [ 0.032,0,0], "direction": [-0.01,0,-1] } },
//!   "head_rotation": [[1,0,0],[0,1,0],[0,0,1]],
//!   "fixation_distance": null, "fixation_range": [0.1, 1000] }
//! ```
//! Matrices are row-major, GL style (world -> eye with -z forward; eye -> clip matching the
//! conventions). Any camera may instead be given in the computer-vision form
//! `{ "K": [[fx,0,cx],[0,fy,cy],[0,0,1]], "R": [[..3]; 3], "t": [tx,ty,tz], "width": W, "height": H,
//! "near": n, "far": f }` (world -> camera, OpenCV axes), converted exactly by
//! [`super::camera_spec`]. The middle view is `middle.view` when given, else the seed's: origin halfway
//! between the gaze origins, `head_rotation` (columns = head axes in world). The fixation
//! distance is `fixation_distance` when given, else the vergence of the gaze rays
//! (`camera::vergence::resolve_fixation`, with its documented fallbacks), measured along the
//! middle view axis.

use super::camera_spec::CameraSpec;
use super::{FrameDepth, MiddleCamera};
use crate::camera::mat4::{self, Mat4};
use crate::camera::vergence::{resolve_fixation, DepthRange, GazeRay};
use crate::convention::Conventions;
use crate::depth::DepthKind;
use crate::error::{Error, Result};
use serde::{Deserialize, Deserializer};
use std::path::Path;

/// An eye's GL matrices, from either form of the file.
#[derive(Debug, Clone, PartialEq)]
pub struct EyeCameras {
    /// World -> GL eye transform (-Z forward), row-major.
    pub view: Mat4,
    /// GL eye -> clip projection under the file's conventions, row-major.
    pub proj: Mat4,
    /// The image size the file states (`width`/`height`; required with `K`), if any.
    pub size: Option<[u32; 2]>,
}

impl EyeCameras {
    /// Refuse an image whose size differs from the one the camera was given for (`what` names
    /// the image in the error).
    pub fn check_size(&self, what: &str, width: u32, height: u32) -> Result<()> {
        match self.size {
            Some([w, h]) if (w, h) != (width, height) => Err(Error::SizeMismatch {
                message: format!("{what} is {width}x{height}, its camera in the camera file {w}x{h}"),
            }),
            _ => Ok(()),
        }
    }
}

/// The middle camera as the file gives it, before its view is derived.
#[derive(Debug, Clone)]
pub struct MiddleSpec {
    /// GL eye -> clip projection under the file's conventions, row-major.
    pub proj: Mat4,
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// World -> GL eye transform; None to derive it from the gaze rays and head rotation.
    pub view: Option<Mat4>,
}

/// A gaze ray in world coordinates, metres.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ray {
    /// The eye's centre.
    pub origin: [f64; 3],
    /// Direction of gaze (need not be unit length).
    pub direction: [f64; 3],
}

/// The two gaze rays, whose vergence gives the fixation distance.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gaze {
    /// Left eye's gaze.
    pub left: Ray,
    /// Right eye's gaze.
    pub right: Ray,
}

/// The file as written, before the cameras are resolved to GL matrices.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraFileSpec {
    #[serde(default)]
    conventions: Conventions,
    #[serde(deserialize_with = "frame_depth")]
    depth_kind: FrameDepth,
    left: CameraSpec,
    right: CameraSpec,
    middle: CameraSpec,
    #[serde(default)]
    gaze: Option<Gaze>,
    #[serde(default)]
    head_rotation: Option<[[f64; 3]; 3]>,
    #[serde(default)]
    fixation_distance: Option<f64>,
    #[serde(default)]
    fixation_range: Option<[f64; 2]>,
}

/// `depth_kind`: any depth kind's name parses (an unknown one lists them all, as for every
/// depth kind in a file), but the eyes' planes are their projections, so only device depth or
/// view Z is accepted; the error names the field and the two accepted values.
fn frame_depth<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<FrameDepth, D::Error> {
    FrameDepth::try_from(DepthKind::deserialize(d)?).map_err(|kind| {
        serde::de::Error::custom(format!(
            "depth_kind \"{}\": expected \"device\" or \"view-z\"",
            kind.name()
        ))
    })
}

/// A parsed cameras.json, every camera resolved to GL matrices.
#[derive(Debug, Clone, Deserialize)]
#[serde(try_from = "CameraFileSpec")]
pub struct CameraFile {
    /// NDC depth range, reversed-Z and row order of the projections and of the depth files (default: GL's).
    pub conventions: Conventions,
    /// What the eye depth maps hold.
    pub depth_kind: FrameDepth,
    /// The left eye's cameras.
    pub left: EyeCameras,
    /// The right eye's cameras.
    pub right: EyeCameras,
    /// The middle camera.
    pub middle: MiddleSpec,
    /// Gaze rays; needed when the middle view or the fixation distance is not given.
    pub gaze: Option<Gaze>,
    /// Head orientation: columns = head x, y, z axes in world (GL convention, -Z forward); identity when None.
    pub head_rotation: Option<[[f64; 3]; 3]>,
    /// Fixation distance along the middle view axis, metres; None to take it from the gaze vergence.
    pub fixation_distance: Option<f64>,
    /// Accepted fixation depths [min, max] for the vergence (default [0.1, 1000] m).
    pub fixation_range: Option<[f64; 2]>,
}

impl TryFrom<CameraFileSpec> for CameraFile {
    type Error = Error;

    fn try_from(f: CameraFileSpec) -> Result<Self> {
        let conv = f.conventions;
        let eye = |spec: &CameraSpec, name: &str| -> Result<EyeCameras> {
            let cam = spec.resolve(name, &conv)?;
            let view = cam
                .view
                .ok_or_else(|| Error::param(format!("{name}.view"), "missing: give view or R and t"))?;
            Ok(EyeCameras {
                view,
                proj: cam.proj,
                size: cam.size,
            })
        };
        let middle = f.middle.resolve("middle", &conv)?;
        let [width, height] = middle
            .size
            .ok_or_else(|| Error::param("middle.width/height", "missing: the middle view's image size"))?;
        Ok(CameraFile {
            conventions: conv,
            depth_kind: f.depth_kind,
            left: eye(&f.left, "left")?,
            right: eye(&f.right, "right")?,
            middle: MiddleSpec {
                proj: middle.proj,
                width,
                height,
                view: middle.view,
            },
            gaze: f.gaze,
            head_rotation: f.head_rotation,
            fixation_distance: f.fixation_distance,
            fixation_range: f.fixation_range,
        })
    }
}

impl CameraFile {
    /// Read and resolve a camera file; errors name the file and the field.
    pub fn load(path: &Path) -> Result<Self> {
        crate::io::load_json(path, crate::io::MAX_JSON_MAGNITUDE)
    }

    /// The middle camera and the fixation distance along its view axis.
    pub fn middle_and_fixation(&self) -> Result<(MiddleCamera, f64)> {
        let m = &self.middle;
        let gaze = self.gaze;
        let view = match (m.view, gaze) {
            (Some(v), _) => v,
            (None, Some(g)) => {
                MiddleCamera::from_gaze(
                    g.left.origin,
                    g.right.origin,
                    self.head_rotation
                        .unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
                    m.proj,
                    m.width,
                    m.height,
                )?
                .view
            }
            (None, None) => {
                return Err(Error::param(
                    "middle.view",
                    "give middle.view or gaze rays to derive it",
                ))
            }
        };
        let mid = MiddleCamera {
            view,
            proj: m.proj,
            width: m.width,
            height: m.height,
        };
        let fixation = match (self.fixation_distance, gaze) {
            (Some(d), _) => d,
            (None, Some(g)) => {
                let [lo, hi] = self.fixation_range.unwrap_or([0.1, 1000.0]);
                let range = DepthRange::new(lo, hi)?;
                let ray = |r: Ray| GazeRay {
                    origin: r.origin,
                    direction: r.direction,
                };
                let f = resolve_fixation(&ray(g.left), &ray(g.right), &range, None, None)?;
                let d = -mat4::transform_point(&view, f.point)[2];
                if !(d.is_finite() && d > 0.0) {
                    return Err(Error::param(
                        "gaze",
                        format!("fixation lies behind the middle camera ({d})"),
                    ));
                }
                d
            }
            (None, None) => return Err(Error::param("fixation_distance", "give fixation_distance or gaze rays")),
        };
        Ok((mid, fixation))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(extra: &str) -> String {
        let id = "[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]";
        let proj = "[[1,0,0,0],[0,1,0,0],[0,0,-1.001,-0.1],[0,0,-1,0]]";
        format!(
            r#"{{"depth_kind":"view-z","left":{{"view":{id},"proj":{proj}}},"right":{{"view":{id},"proj":{proj}}},
               "middle":{{"proj":{proj},"width":8,"height":6}}{extra}}}"#
        )
    }

    #[test]
    fn fixation_from_converging_gaze_is_measured_along_the_middle_axis() {
        // Eyes at x = -+0.03 looking at (0, 0, -2): fixation distance 2 from the midpoint.
        let d = 0.03 / (0.03f64 * 0.03 + 4.0).sqrt();
        let dz = -2.0 / (0.03f64 * 0.03 + 4.0).sqrt();
        let text = file(&format!(
            r#","gaze":{{"left":{{"origin":[-0.03,0,0],"direction":[{d},0,{dz}]}},"right":{{"origin":[0.03,0,0],"direction":[{},0,{dz}]}}}}"#,
            -d
        ));
        let f: CameraFile = serde_json::from_str(&text).unwrap();
        let (mid, fix) = f.middle_and_fixation().unwrap();
        assert!((fix - 2.0).abs() < 1e-9, "{fix}");
        assert_eq!(mid.width, 8);
    }

    #[test]
    fn depth_kind_names_round_trip_and_other_kinds_are_refused_naming_the_field() {
        for (kind, name) in [(FrameDepth::Device, "device"), (FrameDepth::ViewZ, "view-z")] {
            assert_eq!(serde_json::to_string(&kind).unwrap(), format!("\"{name}\""));
            assert_eq!(
                serde_json::from_str::<FrameDepth>(&format!("\"{name}\"")).unwrap(),
                kind
            );
            assert_eq!(kind.name(), name);
            let f: CameraFile = serde_json::from_str(&file("").replace("view-z", name)).unwrap();
            assert_eq!(f.depth_kind, kind);
        }
        let dir = tempfile::tempdir().unwrap();
        for refused in ["view-distance", "disparity"] {
            let path = dir.path().join(format!("{refused}.json"));
            std::fs::write(&path, file("").replace("view-z", refused)).unwrap();
            let e = CameraFile::load(&path).unwrap_err().to_string();
            // The message `viewsynth cyclopean --cameras` has always given.
            let expected = format!("depth_kind \"{refused}\": expected \"device\" or \"view-z\"");
            assert_eq!(e, Error::decode(&path, expected).to_string());
            assert!(e.contains(&path.display().to_string()), "{e}");
        }
        // A name no depth kind has is still refused, listing the kinds.
        let e = serde_json::from_str::<CameraFile>(&file("").replace("view-z", "z-buffer")).unwrap_err();
        assert!(e.to_string().contains("unknown variant `z-buffer`"), "{e}");
    }

    #[test]
    fn missing_fixation_and_unknown_fields_are_errors() {
        let f: CameraFile = serde_json::from_str(&file("")).unwrap();
        assert!(f.middle_and_fixation().unwrap_err().to_string().contains("middle.view"));
        assert!(serde_json::from_str::<CameraFile>(&file(r#","bogus":1"#)).is_err());
    }
}
