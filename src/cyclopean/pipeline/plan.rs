//! The cyclopean request: every setting both front ends give (the CLI's flags, Python's keyword
//! arguments), with one default and one set of checks for both, and the synthesis from decoded
//! images that both run.
//!
//! Why here: the CLI and the Python binding used to decide the method, the seed's fixation, the
//! rig's nominal values and the default outputs each on their own, and drifted. Now a front end
//! only names fields ([`CyclopeanRequest`]) and loads its inputs (files, or numpy arrays) into a
//! [`StereoInput`]; [`CyclopeanRequest::plan`] checks the settings against the input set-up and
//! [`CyclopeanPlan::frame`] / [`CyclopeanPlan::synthesise`] do the rest.

use super::reuse::Reused;
use super::CyclopeanMethod;
use crate::convention::Conventions;
use crate::cyclopean::fill::{Filler, FILLED};
use crate::cyclopean::forward::ForwardWarp;
use crate::cyclopean::splat::{SplatParams, SplatRenderer};
use crate::cyclopean::temporal::FROM_HISTORY;
use crate::io::{self, DepthMap, OutputSet, RgbImage};
use crate::job::ArgError;
use crate::mesh::BreakRule;
use crate::pass::Device;
use crate::stereo::camera_file::{CameraFile, EyeCameras};
use crate::stereo::densify::Densifier;
use crate::stereo::disparity_frame::{disparity_frame, median_fixation, DisparityRig};
use crate::stereo::gather::render::CyclopeanRenderer;
use crate::stereo::gather::{Blend, CyclopeanOutputs, CyclopeanParams};
use crate::stereo::matcher::range::{estimate_range, DisparityRange, SignedSearch};
use crate::stereo::matcher::{EyeEstimate, Matcher, MatcherMethod};
use crate::stereo::{Eye, EyeInput, MiddleCamera, StereoFrame};
use crate::view::ViewOutput;
use serde::Serialize;
use std::path::Path;

/// Every cyclopean setting a front end gives. `None` (and `false`) leave the choice to
/// [`CyclopeanRequest::plan`], the one place that makes it.
#[derive(Debug, Clone, Default, Serialize)]
pub struct CyclopeanRequest {
    /// The method; none: splat-gather, or seed/refine when only `refine_steps` is given.
    pub method: Option<CyclopeanMethod>,
    /// Seed/refine: reconstruction steps after the seed's (0 = seed; default 3).
    pub refine_steps: Option<u32>,
    /// Seed/refine: how the eyes are blended (default hard).
    pub blend: Option<Blend>,
    /// Seed/refine: depth disagreement treated as different surfaces.
    pub z_threshold: Option<f64>,
    /// Seed/refine: `left:W` or `right:W`.
    pub dominant: Option<String>,
    /// Disparity input: where the view sits between the eyes (0 left, 1 right; default 0.5).
    pub position: Option<f64>,
    /// Disparity input: focal length, pixels (with `baseline`: metric depth).
    pub focal: Option<f64>,
    /// Disparity input: baseline, metres (with `focal`).
    pub baseline: Option<f64>,
    /// Disparity input: right principal point minus left, pixels.
    pub doffs: f64,
    /// The outputs; none: colour and mask, plus depth where it is metric.
    #[serde(serialize_with = "super::super::outputs_text")]
    pub outputs: Option<OutputSet>,
    /// Holes filled from the background side (mask 128 there); off, holes stay.
    pub fill: bool,
    /// Two images alone: the largest disparity searched, pixels (none: estimated from the
    /// images, see [`crate::stereo::matcher::range`]).
    pub max_disparity: Option<i32>,
    /// Two images alone: the smallest disparity searched, pixels, negative allowed (none:
    /// estimated from the images).
    pub min_disparity: Option<i32>,
    /// Two images alone: estimated disparities whose confidence (the matcher's, in [0, 1]:
    /// the eyes' agreement and the local spread) is below this are dropped, trading coverage
    /// for precision; none keeps every disparity the left-right check kept.
    pub min_confidence: Option<f64>,
    /// Two images alone: also give each eye's matcher confidence (a float map in [0, 1], 0 where
    /// the disparity is unknown), the same values `min_confidence` is held against.
    pub confidence: bool,
    /// Two images alone: the stereo matcher (none: [`MatcherMethod::default`], the census one).
    pub matcher: Option<MatcherMethod>,
}

/// The matcher's search range for two images alone when none is given and the images give none
/// (too little texture for the coarse pass): a sixth of the width
/// (Middlebury's quarter-size pairs need about a seventh), rounded up to 16 px, in 16..=256.
pub fn default_max_disparity(width: u32) -> u32 {
    (width.div_ceil(6).div_ceil(16) * 16).clamp(16, 256)
}

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

/// Which stereo inputs a call gives (whatever the front end calls them).
#[derive(Debug, Clone, Copy, Default)]
pub struct StereoGiven {
    /// Left disparity.
    pub left_disparity: bool,
    /// Right disparity.
    pub right_disparity: bool,
    /// Left depth.
    pub left_depth: bool,
    /// Right depth.
    pub right_depth: bool,
    /// The camera file.
    pub cameras: bool,
}

impl StereoGiven {
    /// The set-up the inputs make, or the input that is missing or in excess.
    pub fn kind(self) -> Result<StereoKind, ArgError> {
        let disparity = self.left_disparity || self.right_disparity;
        let depth = self.left_depth || self.right_depth || self.cameras;
        match (disparity, depth) {
            (true, true) => Err(ArgError::DisparityAndDepth),
            (false, false) => Ok(StereoKind::Images),
            // One eye's disparity is enough: the other's is derived (cyclopean::one_eye).
            (true, false) => Ok(StereoKind::Disparity),
            (false, true) => {
                for (flag, given) in [
                    ("--left-depth", self.left_depth),
                    ("--right-depth", self.right_depth),
                    ("--cameras", self.cameras),
                ] {
                    if !given {
                        return Err(ArgError::DepthInputMissing(flag));
                    }
                }
                Ok(StereoKind::Cameras)
            }
        }
    }
}

/// The seed/refine settings, all but the fixation (known once the inputs are read).
#[derive(Debug, Clone, Copy)]
struct GatherSettings {
    refine: bool,
    steps: u32,
    blend: Blend,
    z_threshold: Option<f64>,
    dominant: Option<(Eye, f64)>,
}

impl GatherSettings {
    fn params(&self, fixation: f64) -> crate::Result<CyclopeanParams> {
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
    kind: StereoKind,
    method: CyclopeanMethod,
    gather: Option<GatherSettings>,
    /// The disparity rig: focal and baseline (nominal without a calibration), doffs, position.
    rig: (Option<f64>, Option<f64>, f64, f64),
    outputs: OutputSet,
    fill: bool,
    /// The search range's ends given (min, max); the others are estimated.
    range: (Option<i32>, Option<i32>),
    min_confidence: Option<f64>,
    confidence: bool,
    matcher: MatcherMethod,
}

/// `--dominant`'s `eye:weight`.
pub(super) fn dominant(d: &str) -> Result<(Eye, f64), ArgError> {
    let (eye, w) = d.split_once(':').ok_or_else(|| ArgError::DominantForm(d.into()))?;
    let eye = match eye {
        "left" => Eye::Left,
        "right" => Eye::Right,
        _ => return Err(ArgError::DominantEye(d.into())),
    };
    let w = w.parse().map_err(|source| ArgError::DominantWeight {
        value: d.into(),
        source,
    })?;
    Ok((eye, w))
}

impl CyclopeanRequest {
    /// Checks the settings against each other and the input set-up: method options with
    /// their method, rig options with disparities, outputs the input can give.
    pub fn plan(&self, kind: StereoKind) -> Result<CyclopeanPlan, ArgError> {
        let method = match (self.method, self.refine_steps) {
            (Some(m), _) => m,
            (None, Some(0)) => CyclopeanMethod::Seed,
            (None, Some(_)) => CyclopeanMethod::Refine,
            (None, None) => CyclopeanMethod::SplatGather,
        };
        let gathers = matches!(method, CyclopeanMethod::Seed | CyclopeanMethod::Refine);
        if !gathers {
            for (flag, given) in [
                ("--refine-steps", self.refine_steps.is_some()),
                ("--blend", self.blend.is_some()),
                ("--z-threshold", self.z_threshold.is_some()),
                ("--dominant", self.dominant.is_some()),
            ] {
                if given {
                    return Err(ArgError::GatherOptionOnly(flag));
                }
            }
        }
        if let Some(steps) = self.refine_steps.filter(|s| *s > 16) {
            return Err(ArgError::Invalid(crate::Error::param(
                "--refine-steps",
                format!("{steps} outside 0..=16"),
            )));
        }
        for (flag, given) in [
            ("--max-disparity", self.max_disparity.is_some()),
            ("--min-disparity", self.min_disparity.is_some()),
            ("--min-confidence", self.min_confidence.is_some()),
            ("--confidence", self.confidence),
            ("--matcher", self.matcher.is_some()),
        ] {
            if given && kind != StereoKind::Images {
                return Err(ArgError::MatcherOptionWithMaps(flag));
            }
        }
        if let Some(c) = self.min_confidence.filter(|c| !(0.0..=1.0).contains(c)) {
            return Err(ArgError::Invalid(crate::Error::param(
                "--min-confidence",
                format!("{c} outside [0, 1] (the matcher's confidence)"),
            )));
        }
        if let (Some(lo), Some(hi)) = (self.min_disparity, self.max_disparity) {
            if lo >= hi {
                return Err(ArgError::Invalid(crate::Error::param(
                    "--min-disparity/--max-disparity",
                    format!("{lo}..{hi} px searches nothing: the minimum must be below the maximum"),
                )));
            }
        }
        // The search the given ends imply at least (a lone maximum searches from 0 or below),
        // bounded before any image is read.
        if let Some(max) = self.max_disparity {
            let min = self.min_disparity.unwrap_or(0);
            DisparityRange { min, max }.check_search().map_err(ArgError::Invalid)?;
        }
        let metric = match kind {
            StereoKind::Disparity | StereoKind::Images => {
                self.check_rig()?;
                self.focal.is_some()
            }
            StereoKind::Cameras => {
                for (flag, given) in [
                    ("--position", self.position.is_some()),
                    ("--focal", self.focal.is_some()),
                    ("--baseline", self.baseline.is_some()),
                    ("--doffs", self.doffs != 0.0),
                ] {
                    if given {
                        return Err(ArgError::RigOptionWithCameraFile(flag));
                    }
                }
                true
            }
        };
        let outputs = self.outputs.unwrap_or(OutputSet {
            rgb: true,
            depth: metric,
            mask: true,
        });
        if outputs.depth && !metric {
            return Err(ArgError::DepthOutputNotMetric);
        }
        let gather = match gathers {
            true => Some(GatherSettings {
                refine: method == CyclopeanMethod::Refine,
                steps: self.refine_steps.unwrap_or(3),
                blend: self.blend.unwrap_or(Blend::Hard),
                z_threshold: self.z_threshold,
                dominant: self.dominant.as_deref().map(dominant).transpose()?,
            }),
            false => None,
        };
        Ok(CyclopeanPlan {
            kind,
            method,
            gather,
            rig: (self.focal, self.baseline, self.doffs, self.position.unwrap_or(0.5)),
            outputs,
            fill: self.fill,
            range: (self.min_disparity, self.max_disparity),
            min_confidence: self.min_confidence,
            confidence: self.confidence,
            matcher: self.matcher.unwrap_or_default(),
        })
    }

    /// The disparity rig's values: finite, focal and baseline together and in range.
    fn check_rig(&self) -> Result<(), ArgError> {
        match (self.focal, self.baseline) {
            (Some(_), None) => return Err(ArgError::RigPartner("--focal", "--baseline")),
            (None, Some(_)) => return Err(ArgError::RigPartner("--baseline", "--focal")),
            _ => {}
        }
        if !self.doffs.is_finite() {
            return Err(ArgError::Invalid(crate::Error::param(
                "--doffs",
                format!("{} must be finite", self.doffs),
            )));
        }
        // The bounds of focal lengths everywhere (intrinsics, flags, files); a baseline is a
        // length, held to the options' magnitude.
        use crate::camera::{MAX_INTRINSIC, MIN_FOCAL_PX};
        let min_baseline = f64::from(crate::depth::MIN_DEPTH_VALUE);
        for (flag, v, lo) in [
            ("--focal", self.focal, MIN_FOCAL_PX),
            ("--baseline", self.baseline, min_baseline),
        ] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && (lo..=MAX_INTRINSIC).contains(v))) {
                return Err(ArgError::Invalid(crate::Error::param(
                    flag,
                    format!("{v} must be in [{lo:e}, {MAX_INTRINSIC:e}]"),
                )));
            }
        }
        if let Some(p) = self.position.filter(|p| !(0.0..=1.0).contains(p)) {
            return Err(ArgError::Invalid(crate::Error::param(
                "--position",
                format!("{p} outside [0, 1] (0 = left eye, 1 = right eye)"),
            )));
        }
        Ok(())
    }
}

/// `out` with its holes taken from `dense` where that view has a pixel, marked [`FILLED`].
fn holes_from(
    mut out: crate::stereo::gather::CyclopeanOutput,
    dense: &crate::stereo::gather::CyclopeanOutput,
) -> crate::Result<crate::stereo::gather::CyclopeanOutput> {
    let missing = || crate::Error::param("fill", "the dense view needs colour and depth");
    let (dc, dd) = (
        dense.color.as_ref().ok_or_else(missing)?,
        dense.depth.as_ref().ok_or_else(missing)?,
    );
    let (oc, od) = (
        out.color.as_mut().ok_or_else(missing)?,
        out.depth.as_mut().ok_or_else(missing)?,
    );
    for (i, s) in out.sources.iter_mut().enumerate() {
        if *s == 0 && dense.sources[i] != 0 {
            *s = FILLED;
            oc.data[3 * i..3 * i + 3].copy_from_slice(&dc.data[3 * i..3 * i + 3]);
            od.data[i] = dd.data[i];
        }
    }
    Ok(out)
}

/// An eye's estimated disparities with those below `min` confidence (if any) made unknown (0).
fn confident(eye: &mut EyeEstimate, min: Option<f64>) {
    let Some(min) = min else { return };
    for (v, c) in eye.disparity.data.iter_mut().zip(&eye.confidence.data) {
        if f64::from(*c) < min {
            *v = 0.0;
        }
    }
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

/// A pair alone's disparities ([`CyclopeanPlan::frame`]).
struct Estimate {
    /// Left and right disparities, stored as d + offset (0 unknown), the input's columns.
    left: DepthMap,
    right: DepthMap,
    confidence: Option<[DepthMap; 2]>,
    offset: u32,
    range: DisparityRange,
    estimated: bool,
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
    fn error(self, message: impl Into<String>) -> crate::Error {
        match self {
            InputName::File(p) => crate::Error::decode(p, message),
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

/// The view synthesised: its planes and mask (1 rendered, [`io::MASK_FILLED`] filled, 0 hole).
pub struct Synthesised {
    /// Colour, depth (those asked for) and the mask.
    pub view: ViewOutput,
    /// Fraction of pixels some eye saw in this frame (filled pixels not counted).
    pub coverage: f64,
    /// Milliseconds before the render itself: uploads, meshes, programs.
    pub setup_ms: f64,
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
                        let eyes = [(&left, &est.left), (&right, &est.right)];
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

    /// The search range of a pair alone: the ends given, the others estimated from the images
    /// (a lone `--max-disparity` keeps its meaning of a search from 0 where the images show no
    /// negative disparity; without an estimate, 0..=[`default_max_disparity`]). True when an end
    /// was estimated.
    fn range(&self, left: &RgbImage, right: &RgbImage, left_rgb: InputName) -> crate::Result<(DisparityRange, bool)> {
        let (lo, hi) = self.range;
        let estimated = match (lo, hi) {
            (Some(_), Some(_)) => None,
            _ => estimate_range(left, right)?,
        };
        let base = estimated.unwrap_or(DisparityRange {
            min: 0,
            max: default_max_disparity(left.width) as i32,
        });
        let range = DisparityRange {
            min: lo.unwrap_or(match hi {
                Some(_) => base.min.min(0),
                None => base.min,
            }),
            max: hi.unwrap_or(match lo {
                Some(lo) => base.max.max(lo + 1),
                None => base.max,
            }),
        };
        range
            .validate(left.width)
            .map_err(|e| left_rgb.error(format!("{} px wide: {e}", left.width)))?;
        Ok((range, lo.is_none() || hi.is_none()))
    }

    /// Both eyes' disparities of a pair alone over its signed range, by the census matcher on
    /// `device` (those below the minimum confidence made unknown), and their confidence when
    /// asked for. Stored as d + offset ([`SignedSearch`]).
    fn estimate(
        &self,
        device: &Device,
        left: &RgbImage,
        right: &RgbImage,
        left_rgb: InputName,
        reuse: Option<&mut Reused>,
    ) -> crate::Result<Estimate> {
        let (range, estimated) = self.range(left, right, left_rgb)?;
        let search = SignedSearch::new(range);
        // A negative minimum widens both images by its size: the widened pair must fit the GPU.
        device
            .check_image_size("widened pair", search.width(left.width), left.height)
            .map_err(|e| {
                left_rgb.error(format!(
                    "{} px wide, widened by {} columns for the search {}..{} px \
                     (--min-disparity/--max-disparity): {e}",
                    left.width, search.offset, range.min, range.max
                ))
            })?;
        let widened;
        let (l, r) = match search.offset {
            0 => (left, right),
            _ => {
                widened = search.widen(left, right)?;
                (&widened.0, &widened.1)
            }
        };
        let mut own;
        let matcher = match reuse {
            Some(re) => re.matcher(device, l.width, l.height, search.max_disparity, self.matcher)?,
            None => {
                own = Matcher::with_method(device, l.width, l.height, search.max_disparity, self.matcher)?;
                &mut own
            }
        };
        // The confidence stage runs only when something reads it.
        let (dl, dr, confidence) = if self.min_confidence.is_none() && !self.confidence {
            let (dl, dr) = matcher.estimate(l, r)?;
            (dl, dr, None)
        } else {
            let [mut el, mut er] = matcher.estimate_with_confidence(l, r)?;
            confident(&mut el, self.min_confidence);
            confident(&mut er, self.min_confidence);
            let confidence = match self.confidence {
                true => {
                    let (cl, cr) = search.crop(el.confidence, er.confidence, left.width)?;
                    Some([cl, cr])
                }
                false => None,
            };
            (el.disparity, er.disparity, confidence)
        };
        let (dl, dr) = search.crop(dl, dr, left.width)?;
        Ok(Estimate {
            left: dl,
            right: dr,
            confidence,
            offset: search.offset,
            range,
            estimated,
        })
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
        let [left, right] = eyes.map(|(color, disparity)| {
            let mut known = disparity.clone();
            known.data.iter_mut().filter(|d| !d.is_finite()).for_each(|d| *d = 0.0);
            densifier
                .densify(&known, color)
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
                "--focal/--baseline",
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

    /// Renders the view with the plan's method (and fill) on `device`.
    /// A sequence passes what it keeps between frames (`reuse`): the default method's renderer
    /// and the fill are reused, and with `fill` the holes the last frame's eyes saw take the
    /// temporal history first and the fill fills the rest (both count as filled in the mask).
    /// `dense`: disparities (given or estimated) with `fill`, the frame on dense disparities; its
    /// view fills the holes of `frame`'s first (pixels from densified disparities count as filled,
    /// so the mask's rendered pixels stay those of given or matched disparities), then the fill
    /// fills the rest.
    pub fn synthesise(
        &self,
        device: &Device,
        frame: &StereoFrame,
        mid: &MiddleCamera,
        fixation: f64,
        dense: Option<&StereoFrame>,
        mut reuse: Option<&mut Reused>,
    ) -> crate::Result<Synthesised> {
        let t0 = std::time::Instant::now();
        frame.validate()?;
        let params = self.gather.map(|g| g.params(fixation)).transpose()?;
        // The fill (and the history) read both planes whatever is returned.
        let wanted = CyclopeanOutputs {
            color: self.outputs.rgb || self.fill,
            depth: self.outputs.depth || self.fill,
        };
        let render = |frame: &StereoFrame, reuse: &mut Option<&mut Reused>| match (self.method, params) {
            (CyclopeanMethod::Seed | CyclopeanMethod::Refine, Some(p)) => {
                CyclopeanRenderer::with_outputs(device, frame, p, wanted)?.render(mid)
            }
            (CyclopeanMethod::Forward, _) => ForwardWarp::new(device, frame, &BreakRule::default())?.render(mid),
            _ => match reuse {
                Some(r) => r.splat(device, frame, wanted)?.render(mid),
                None => SplatRenderer::new(device, frame, SplatParams::default(), wanted)?.render(mid),
            },
        };
        let (mut out, mut timing) = render(frame, &mut reuse)?;
        if let Some(dense) = dense.filter(|_| self.fill) {
            dense.validate()?;
            let (from_dense, t) = render(dense, &mut reuse)?;
            timing.wall_ms += t.wall_ms;
            timing.gpu_ms = timing.gpu_ms.zip(t.gpu_ms).map(|(a, b)| a + b);
            out = holes_from(out, &from_dense)?;
        }
        if self.fill {
            out = match reuse {
                Some(r) => {
                    out = r.history(device, frame.conv)?.push(&out, mid)?;
                    r.filler(device)?.fill(&out, mid.width, mid.height)?
                }
                None => Filler::new(device)?.fill(&out, mid.width, mid.height)?,
            };
        }
        let setup_ms = (t0.elapsed().as_secs_f64() * 1e3 - timing.wall_ms).max(0.0);
        // The mask: 1 where an eye gave the pixel, MASK_FILLED where filled (from the history
        // or from the background side).
        let mask = io::Mask::new(
            mid.width,
            mid.height,
            out.sources
                .iter()
                .map(|&s| match s {
                    0 => 0,
                    FILLED | FROM_HISTORY => io::MASK_FILLED,
                    _ => 1,
                })
                .collect(),
        )?;
        // Seen by an eye in this frame: neither unseen, filled nor carried from history.
        let coverage = crate::metrics::valid_fraction(&out.sources, |s| ![0, FILLED, FROM_HISTORY].contains(s));
        // Some methods render planes that were not asked for: keep only those that were.
        let view = ViewOutput {
            width: mid.width,
            height: mid.height,
            color: out.color.filter(|_| self.outputs.rgb),
            depth: out.depth.filter(|_| self.outputs.depth),
            mask: Some(mask),
            timing: Some(timing),
            exact: None,
        };
        Ok(Synthesised {
            view,
            coverage,
            setup_ms,
        })
    }
}
