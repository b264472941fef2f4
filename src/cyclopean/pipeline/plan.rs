//! The checked request for one input set-up ([`CyclopeanPlan`], made by the job's
//! [`CyclopeanRequest::plan`](crate::job::cyclopean::CyclopeanRequest::plan)) and the frame it
//! builds from decoded inputs: the disparity rig, densified disparities for the fill, or the
//! camera file's eyes.

use super::reuse::Reused;
use crate::convention::Conventions;
use crate::cyclopean::CyclopeanMethod;
use crate::io::{DepthMap, RgbImage};
use crate::output::OutputSet;
use crate::pass::Device;
use crate::stereo::camera_file::{CameraFile, EyeCameras};
use crate::stereo::densify::{Densifier, OtherEye};
use crate::stereo::disparity_frame::{disparity_frame, median_fixation, DisparityRig};
use crate::stereo::gather::{Blend, CyclopeanParams};
use crate::stereo::matcher::range::DisparityRange;
use crate::stereo::matcher::MatcherMethod;
use crate::stereo::{Eye, EyeInput, MiddleCamera, StereoFrame};
use std::path::Path;

/// The two input set-ups.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StereoKind {
    /// A rectified pair with disparities.
    Disparity,
    /// Depth per eye placed by a camera file.
    Cameras,
    /// A rectified pair alone: disparities estimated by the census matcher.
    Images,
}

/// The seed/refine settings, all but the fixation (known once the inputs are read).
#[derive(Debug, Clone, Copy)]
pub(crate) struct GatherSettings {
    pub(crate) refine: bool,
    pub(crate) steps: u32,
    pub(crate) blend: Blend,
    pub(crate) z_threshold: Option<f64>,
    pub(crate) dominant: Option<(Eye, f64)>,
}

impl GatherSettings {
    pub(super) fn params(&self, fixation: f64) -> crate::Result<CyclopeanParams> {
        let mut params = CyclopeanParams::seed(fixation);
        if self.refine && self.steps > 0 {
            params.method = crate::stereo::gather::Method::Refine { steps: self.steps };
        }
        params.blend = self.blend;
        if let Some(t) = self.z_threshold {
            params.z_threshold = t;
        }
        params.dominant = self.dominant;
        params.validate()?;
        Ok(params)
    }
}

/// A checked request for one input set-up.
#[derive(Debug, Clone)]
pub struct CyclopeanPlan {
    pub(crate) kind: StereoKind,
    pub(crate) method: CyclopeanMethod,
    pub(crate) gather: Option<GatherSettings>,
    /// The disparity rig: focal and baseline (nominal without a calibration), doffs, position.
    pub(crate) rig: (Option<f64>, Option<f64>, f64, f64),
    pub(crate) outputs: OutputSet,
    pub(crate) fill: bool,
    /// The search range's ends given (min, max); the others are estimated.
    pub(crate) range: (Option<i32>, Option<i32>),
    pub(crate) min_confidence: Option<f64>,
    pub(crate) confidence: bool,
    pub(crate) matcher: MatcherMethod,
}

/// A frame ready to render.
pub struct Framed {
    /// Both eyes, placed.
    pub frame: StereoFrame,
    /// The view's camera.
    pub mid: MiddleCamera,
    /// Where the seed/refine methods start: the median depth the left eye saw, or the camera
    /// file's fixation.
    pub fixation: f64,
    /// Two images alone with `confidence` asked for: the matcher's confidence of the left and
    /// the right eye (rows top-down, in [0, 1], 0 where the disparity is unknown).
    pub confidence: Option<[DepthMap; 2]>,
    /// Two images alone: the disparity range searched, and whether it was estimated (else given).
    pub range: Option<(DisparityRange, bool)>,
    /// Disparities (given or estimated) with `fill`: the same frame on disparities made dense
    /// ([`crate::stereo::densify`]); what it renders fills the holes of `frame`'s view.
    pub dense: Option<StereoFrame>,
}

/// The decoded inputs of one view, each eye's colour with its disparity or depth.
pub enum StereoInput {
    /// A rectified pair: disparities in pixels (0 = unknown).
    Disparity {
        /// Left colour and disparity.
        left: (RgbImage, DepthMap),
        /// Right colour and disparity.
        right: (RgbImage, DepthMap),
    },
    /// Depth per eye as the camera file says, and the file.
    Cameras {
        /// Left colour and depth.
        left: (RgbImage, DepthMap),
        /// Right colour and depth.
        right: (RgbImage, DepthMap),
        /// The eyes' and the view's cameras.
        cameras: Box<CameraFile>,
    },
    /// A rectified pair alone: the disparities are estimated.
    Images {
        /// Left colour.
        left: RgbImage,
        /// Right colour.
        right: RgbImage,
    },
}

/// How messages name an input: by its file (a decode error, exit 1) or by the argument that
/// holds it (a bad argument).
#[derive(Debug, Clone, Copy)]
pub enum InputName<'a> {
    /// A file read by the CLI.
    File(&'a Path),
    /// A front end's argument, e.g. Python's `left_disparity`.
    Argument(&'a str),
}

impl InputName<'_> {
    /// A file's error (its text as the command line spells it), or an argument's.
    pub(super) fn error(self, message: impl Into<crate::Message>) -> crate::Error {
        match self {
            InputName::File(p) => crate::Error::decode(p, message.into().to_string()),
            InputName::Argument(a) => crate::Error::param(a, message),
        }
    }

    fn check_size(self, cam: &EyeCameras, width: u32, height: u32) -> crate::Result<()> {
        match self {
            InputName::File(p) => cam.check_size(&p.display().to_string(), width, height),
            InputName::Argument(a) => cam
                .check_size(a, width, height)
                .map_err(|e| crate::Error::param(a, e.to_string())),
        }
    }
}

impl CyclopeanPlan {
    /// The set-up this plan was checked for.
    pub fn kind(&self) -> StereoKind {
        self.kind
    }

    /// The outputs to return or write.
    pub fn outputs(&self) -> OutputSet {
        self.outputs
    }

    /// The method.
    pub fn method(&self) -> CyclopeanMethod {
        self.method
    }

    /// The frame, the view and the fixation the seed/refine methods start from: the median
    /// depth the left eye saw (disparities), or the camera file's fixation. `names` name the
    /// left and right colour, the left disparity or depth and the cameras in messages. Two
    /// images alone are matched on `device` (the census matcher's GPU pass, bit-exact with its
    /// twin), with each eye's confidence when the request asked for it; a sequence passes its
    /// `reuse` so the matcher is made once.
    pub fn frame(
        &self,
        device: &Device,
        input: StereoInput,
        names: [InputName; 4],
        reuse: Option<&mut Reused>,
    ) -> crate::Result<Framed> {
        let [left_rgb, right_rgb, left_map, cameras_name] = names;
        match input {
            StereoInput::Disparity { left, right } => {
                // Given disparities (ground truth, a sensor) have unknown pixels too: densified
                // as the matcher's are, so only true disocclusions reach the colour fill.
                let dense = match self.fill {
                    true => Some(self.dense_frame(
                        device,
                        [(&left.0, &left.1), (&right.0, &right.1)],
                        left_map,
                        0,
                        reuse,
                    )?),
                    false => None,
                };
                Ok(Framed {
                    dense,
                    ..self.disparity_frame(left, right, left_map, 0)?
                })
            }
            StereoInput::Images { left, right } => {
                let mut reuse = reuse;
                let est = self.estimate(device, &left, &right, left_rgb, reuse.as_deref_mut())?;
                let dense = match self.fill {
                    true => {
                        let (l, r) = est
                            .with_inferred
                            .as_ref()
                            .map_or((&est.left, &est.right), |(l, r)| (l, r));
                        let eyes = [(&left, l), (&right, r)];
                        Some(self.dense_frame(device, eyes, left_map, est.offset, reuse)?)
                    }
                    false => None,
                };
                Ok(Framed {
                    confidence: est.confidence,
                    range: Some((est.range, est.estimated)),
                    dense,
                    ..self.disparity_frame((left, est.left), (right, est.right), left_map, est.offset)?
                })
            }
            StereoInput::Cameras { left, right, cameras } => {
                left_rgb.check_size(&cameras.left, left.0.width, left.0.height)?;
                right_rgb.check_size(&cameras.right, right.0.width, right.0.height)?;
                let (mid, fixation) = cameras
                    .middle_and_fixation()
                    .map_err(|e| cameras_name.error(e.to_string()))?;
                let eye = |(color, depth): (RgbImage, DepthMap), cam: &EyeCameras| EyeInput {
                    color,
                    depth,
                    view: cam.view,
                    proj: cam.proj,
                };
                let frame = StereoFrame {
                    left: eye(left, &cameras.left),
                    right: eye(right, &cameras.right),
                    depth_kind: cameras.depth_kind,
                    conv: cameras.conventions,
                };
                Ok(Framed {
                    frame,
                    mid,
                    fixation,
                    confidence: None,
                    range: None,
                    dense: None,
                })
            }
        }
    }

    /// With `fill`: the frame on both eyes' disparities (stored as d + `offset`) made dense
    /// ([`Densifier`], on `device` or a sequence's `reuse`), whose view fills the holes of the
    /// view on the disparities as they are. Non-finite values are unknown, as for the render.
    fn dense_frame(
        &self,
        device: &Device,
        eyes: [(&RgbImage, &DepthMap); 2],
        left_map: InputName,
        offset: u32,
        reuse: Option<&mut Reused>,
    ) -> crate::Result<StereoFrame> {
        let mut own;
        let densifier = match reuse {
            Some(r) => r.densifier(device)?,
            None => {
                own = Densifier::new(device)?;
                &mut own
            }
        };
        let [left, right] = [Eye::Left, Eye::Right].map(|eye| {
            let (color, disparity) = eyes[eye as usize];
            let mut known = disparity.clone();
            known.data.iter_mut().filter(|d| !d.is_finite()).for_each(|d| *d = 0.0);
            densifier
                .densify(&known, color, OtherEye { eye, offset })
                .map(|dense| (color.clone(), dense.disparity))
        });
        Ok(self.disparity_frame(left?, right?, left_map, offset)?.frame)
    }

    /// A rectified pair with disparities: the frame, the view and the seed's fixation (the
    /// median depth the left eye saw).
    fn disparity_frame(
        &self,
        left: (RgbImage, DepthMap),
        right: (RgbImage, DepthMap),
        left_map: InputName,
        offset: u32,
    ) -> crate::Result<Framed> {
        let (focal, baseline, doffs, position) = self.rig;
        // Without a calibration only f B matters for the view; any nominal values do, and a
        // signed range's offset becomes the principal points' (every shift stays t d, every
        // depth positive). With one, the depth is the calibration's: f B / (d + doffs).
        let rig = DisparityRig {
            focal_px: focal.unwrap_or(left.0.width as f64),
            baseline: baseline.unwrap_or(0.1),
            doffs: match focal {
                Some(_) => doffs,
                None => doffs + offset as f64,
            },
            position,
            offset: offset as f64,
        };
        let known = left.1.data.iter().any(|&d| d.is_finite() && d > 0.0);
        let (frame, mid) = disparity_frame(left, right, &rig, Conventions::default())?;
        // f B / d outside the usable depths makes holes (the one depth rule); all of them is
        // the rig's fault, said by name rather than a silent 0 % valid view.
        if known && !frame.left.depth.data.iter().any(|z| z.is_finite() && *z > 0.0) {
            return Err(crate::Error::param(
                crate::msg![crate::Field::Focal, "/", crate::Field::Baseline],
                format!(
                    "f B / disparity = {:e} m / px puts every known disparity outside the usable depths [{:e}, {:e}] m",
                    rig.focal_px * rig.baseline,
                    crate::depth::MIN_DEPTH_VALUE,
                    crate::depth::MAX_DEPTH_VALUE
                ),
            ));
        }
        let fixation =
            median_fixation(&frame).ok_or_else(|| left_map.error("no known disparity (all 0 or non-finite)"))?;
        Ok(Framed {
            frame,
            mid,
            fixation,
            confidence: None,
            range: None,
            dense: None,
        })
    }
}
