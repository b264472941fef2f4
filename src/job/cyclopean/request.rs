//! The cyclopean request: every setting both front ends give (the CLI's flags, Python's keyword
//! arguments), with one default and one set of checks for both; the checked request is a
//! [`CyclopeanPlan`], which the pipeline ([`crate::cyclopean::pipeline`]) runs.
//!
//! Why here: the CLI and the Python binding used to decide the method, the seed's fixation, the
//! rig's nominal values and the default outputs each on their own, and drifted. Now a front end
//! only names fields ([`CyclopeanRequest`]) and loads its inputs (files, or numpy arrays) into a
//! [`StereoInput`](crate::cyclopean::pipeline::StereoInput); [`CyclopeanRequest::plan`] checks
//! the settings against the input set-up and [`CyclopeanPlan::frame`] /
//! [`CyclopeanPlan::synthesise`] do the rest.

use crate::cyclopean::pipeline::{CyclopeanPlan, GatherSettings, StereoKind};
use crate::cyclopean::CyclopeanMethod;
use crate::job::ArgError;
use crate::output::OutputSet;
use crate::stereo::gather::Blend;
use crate::stereo::matcher::range::DisparityRange;
use crate::stereo::matcher::MatcherMethod;
use crate::stereo::Eye;
use serde::Serialize;

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
    /// Two images alone: the stereo matcher (none: [`MatcherMethod::default`], the semi-global one).
    pub matcher: Option<MatcherMethod>,
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
                    (crate::Field::LeftDepth, self.left_depth),
                    (crate::Field::RightDepth, self.right_depth),
                    (crate::Field::Cameras, self.cameras),
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
                (crate::Field::RefineSteps, self.refine_steps.is_some()),
                (crate::Field::Blend, self.blend.is_some()),
                (crate::Field::ZThreshold, self.z_threshold.is_some()),
                (crate::Field::Dominant, self.dominant.is_some()),
            ] {
                if given {
                    return Err(ArgError::GatherOptionOnly(flag));
                }
            }
        }
        if let Some(steps) = self.refine_steps.filter(|s| *s > 16) {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::RefineSteps,
                format!("{steps} outside 0..=16"),
            )));
        }
        for (flag, given) in [
            (crate::Field::MaxDisparity, self.max_disparity.is_some()),
            (crate::Field::MinDisparity, self.min_disparity.is_some()),
            (crate::Field::MinConfidence, self.min_confidence.is_some()),
            (crate::Field::Confidence, self.confidence),
            (crate::Field::Matcher, self.matcher.is_some()),
        ] {
            if given && kind != StereoKind::Images {
                return Err(ArgError::MatcherOptionWithMaps(flag));
            }
        }
        if let Some(c) = self.min_confidence.filter(|c| !(0.0..=1.0).contains(c)) {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::MinConfidence,
                format!("{c} outside [0, 1] (the matcher's confidence)"),
            )));
        }
        if let (Some(lo), Some(hi)) = (self.min_disparity, self.max_disparity) {
            if lo >= hi {
                return Err(ArgError::Invalid(crate::Error::param(
                    crate::msg![crate::Field::MinDisparity, "/", crate::Field::MaxDisparity],
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
                    (crate::Field::Position, self.position.is_some()),
                    (crate::Field::Focal, self.focal.is_some()),
                    (crate::Field::Baseline, self.baseline.is_some()),
                    (crate::Field::Doffs, self.doffs != 0.0),
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
            (Some(_), None) => return Err(ArgError::RigPartner(crate::Field::Focal, crate::Field::Baseline)),
            (None, Some(_)) => return Err(ArgError::RigPartner(crate::Field::Baseline, crate::Field::Focal)),
            _ => {}
        }
        if !self.doffs.is_finite() {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::Doffs,
                format!("{} must be finite", self.doffs),
            )));
        }
        // The bounds of focal lengths everywhere (intrinsics, flags, files); a baseline is a
        // length, held to the options' magnitude.
        use crate::camera::{MAX_INTRINSIC, MIN_FOCAL_PX};
        let min_baseline = f64::from(crate::depth::MIN_DEPTH_VALUE);
        for (flag, v, lo) in [
            (crate::Field::Focal, self.focal, MIN_FOCAL_PX),
            (crate::Field::Baseline, self.baseline, min_baseline),
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
                crate::Field::Position,
                format!("{p} outside [0, 1] (0 = left eye, 1 = right eye)"),
            )));
        }
        Ok(())
    }
}
