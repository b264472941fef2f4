//! The reproject request: every setting of a parallel-rig reprojection that both front ends
//! give (the CLI's flags, Python's keyword arguments), with one default and one set of checks,
//! and the render from a decoded source that both run.
//!
//! Why here: the Python binding used to re-decide the views (`both` from an eye, a target that
//! is the source), the depth kind's planes and the rig; now it fills a [`ReprojectRequest`],
//! [`ReprojectRequest::rig`] checks it once for both, and [`RigPlan::render`] renders.

use super::{device_depth, MethodChoice, SourceDepth, Target};
use crate::camera::stereo::{Eye, StereoParams};
use crate::camera::{Intrinsics, PinholeCamera};
use crate::convention::Conventions;
use crate::depth::DepthEncoding;
use crate::job::error::OptionsContext;
use crate::job::ArgError;
use crate::output::OutputSet;
use crate::pass::{Device, Timing};
use crate::reproject::render::Reprojector;
use crate::reproject::{
    Geometry, Method, ReprojectOutput, ReprojectOutputs, ReprojectParams, ReprojectSource, ShiftModel,
};
use serde::Serialize;
use std::time::Instant;

/// The source view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SourceView {
    /// The left eye.
    #[default]
    Left,
    /// The centre of the rig.
    #[serde(alias = "center")]
    Centre,
    /// The right eye.
    Right,
}

impl SourceView {
    /// The eye, or None for the centre.
    pub fn eye(self) -> Option<Eye> {
        match self {
            SourceView::Left => Some(Eye::Left),
            SourceView::Centre => None,
            SourceView::Right => Some(Eye::Right),
        }
    }
}

/// Every reproject setting a front end gives; [`Default`] holds the defaults of both.
#[derive(Debug, Clone, Serialize)]
pub struct ReprojectRequest {
    /// What the depth holds.
    pub depth_kind: SourceDepth,
    /// Near plane of device depth.
    pub near: Option<f64>,
    /// Far plane of device depth.
    pub far: Option<f64>,
    /// Rectified rig's baseline, metres (and disparity depth's).
    pub baseline: Option<f64>,
    /// Rectified rig's focal length, pixels (default: fx).
    pub focal: Option<f64>,
    /// cx_right - cx_left, pixels.
    pub doffs: f64,
    /// Game-engine rig's separation.
    pub separation: Option<f64>,
    /// Game-engine rig's convergence distance, metres.
    pub convergence: Option<f64>,
    /// The source view.
    pub from: SourceView,
    /// The target view(s).
    pub to: Target,
    /// The method; none: gather3d with a camera file, else shift-scan.
    pub method: Option<MethodChoice>,
    /// Steps of the shift walk / 3-D gather, 1..=16.
    pub steps: u32,
    /// Segment break threshold.
    pub tau_rel: f64,
    /// The outputs; none: all three.
    #[serde(serialize_with = "crate::job::outputs_text")]
    pub outputs: Option<OutputSet>,
}

impl Default for ReprojectRequest {
    fn default() -> Self {
        ReprojectRequest {
            depth_kind: SourceDepth::ViewZ,
            near: None,
            far: None,
            baseline: None,
            focal: None,
            doffs: 0.0,
            separation: None,
            convergence: None,
            from: SourceView::Left,
            to: Target::Right,
            method: None,
            steps: 3,
            tau_rel: 0.05,
            outputs: None,
        }
    }
}

/// A checked parallel-rig reprojection, waiting for the source's intrinsics and size.
#[derive(Debug, Clone)]
pub struct RigPlan {
    from: Option<Eye>,
    targets: Vec<Eye>,
    depth_kind: DepthEncoding,
    /// Game-engine stereo, or None for the rectified rig.
    seed: Option<StereoParams>,
    /// The rectified rig's shift per target (when no `seed`).
    rectified: Vec<ShiftModel>,
    params: ReprojectParams,
}

/// One target rendered.
pub struct RenderedTarget {
    /// The target eye (None: the camera file's middle camera).
    pub to: Option<Eye>,
    /// Its planes and mask.
    pub out: ReprojectOutput,
    /// Render time.
    pub timing: Timing,
    /// Set-up and shader compile, milliseconds.
    pub setup_ms: f64,
}

impl ReprojectRequest {
    /// The outputs asked for.
    pub fn outputs(&self) -> OutputSet {
        self.outputs.unwrap_or_default()
    }

    /// The method and its parameters, checked.
    pub fn params(&self) -> Result<ReprojectParams, ArgError> {
        let method = match self.method.unwrap_or_default() {
            MethodChoice::Shift => Method::Shift { steps: self.steps },
            MethodChoice::ShiftScan => Method::ShiftScan,
            MethodChoice::Gather3d => Method::Gather3d { steps: self.steps },
        };
        let params = ReprojectParams {
            method,
            outputs: ReprojectOutputs {
                color: self.outputs().rgb,
                depth: self.outputs().depth,
            },
            tau_rel: self.tau_rel,
        };
        params
            .validate()
            .for_options(crate::msg![crate::Field::Steps, "/", crate::Field::TauRel])?;
        Ok(params)
    }

    /// The target eyes of a rig.
    fn targets(&self) -> Result<Vec<Eye>, ArgError> {
        Ok(match (self.from.eye(), self.to) {
            (None, Target::Both) => vec![Eye::Left, Eye::Right],
            (_, Target::Both) => return Err(ArgError::BothFromEye),
            (Some(Eye::Left), Target::Left) | (Some(Eye::Right), Target::Right) => {
                return Err(ArgError::TargetIsSource)
            }
            (_, Target::Centre) => return Err(ArgError::CentreTargetNeedsCameras),
            (_, Target::Left) => vec![Eye::Left],
            (_, Target::Right) => vec![Eye::Right],
        })
    }

    /// The parallel rig's checks, in the order earlier releases made them; `fx` is the
    /// source's (the focal length when none is given).
    pub fn rig(&self, fx: f64) -> Result<RigPlan, ArgError> {
        let params = self.params()?;
        let targets = self.targets()?;
        let focal = self.focal.unwrap_or(fx);
        let depth_kind = match self.depth_kind {
            SourceDepth::ViewZ => DepthEncoding::ViewZ,
            SourceDepth::Device => device_depth(self.near, self.far, "the depth buffer")?,
            SourceDepth::Disparity => {
                let Some(baseline) = self.baseline else {
                    return Err(ArgError::DisparityWithoutBaseline);
                };
                let kind = DepthEncoding::Disparity {
                    focal_px: focal,
                    baseline,
                    doffs: self.doffs,
                };
                kind.validate().for_options(crate::msg![
                    crate::Field::DepthKind,
                    " disparity: ",
                    crate::Field::Focal,
                    "/",
                    crate::Field::Baseline,
                    "/",
                    crate::Field::Doffs
                ])?;
                kind
            }
        };
        if self.depth_kind != SourceDepth::Device && (self.near.is_some() || self.far.is_some()) {
            return Err(ArgError::PlanesWithoutDevice);
        }
        let seed = match (self.separation, self.convergence) {
            (Some(s), Some(c)) => Some(StereoParams::new(s, c).for_options(crate::msg![
                crate::Field::Separation,
                "/",
                crate::Field::Convergence
            ])?),
            (None, None) => None,
            (Some(_), None) => {
                return Err(ArgError::RigPartner(
                    crate::Field::Separation,
                    crate::Field::Convergence,
                ))
            }
            (None, Some(_)) => {
                return Err(ArgError::RigPartner(
                    crate::Field::Convergence,
                    crate::Field::Separation,
                ))
            }
        };
        // --baseline places a rectified rig; with a game-engine rig it would be ignored, unless
        // it makes disparity depth metric.
        if seed.is_some() && self.baseline.is_some() && self.depth_kind != SourceDepth::Disparity {
            return Err(ArgError::RigConflict);
        }
        let from = self.from.eye();
        let rectified = match (seed, self.baseline) {
            (Some(_), _) => Vec::new(),
            (None, Some(b)) => targets
                .iter()
                .map(|&to| {
                    ShiftModel::rectified(focal, b, self.doffs, from, Some(to)).for_options(crate::msg![
                        crate::Field::Focal,
                        "/",
                        crate::Field::Baseline,
                        "/",
                        crate::Field::Doffs
                    ])
                })
                .collect::<Result<_, _>>()?,
            (None, None) => return Err(ArgError::NoRig),
        };
        Ok(RigPlan {
            from,
            targets,
            depth_kind,
            seed,
            rectified,
            params,
        })
    }
}

impl RigPlan {
    /// The source view (None: the centre).
    pub fn from(&self) -> Option<Eye> {
        self.from
    }

    /// The target eyes, in the order rendered.
    pub fn targets(&self) -> &[Eye] {
        &self.targets
    }

    /// How the source's depth is read.
    pub fn depth_kind(&self) -> DepthEncoding {
        self.depth_kind
    }

    /// The method and its parameters.
    pub fn params(&self) -> ReprojectParams {
        self.params
    }

    /// A source of `color` and `depth` as this plan reads it, under `conv`.
    pub fn source(&self, color: crate::io::RgbImage, depth: crate::io::DepthMap, conv: Conventions) -> ReprojectSource {
        ReprojectSource {
            color,
            depth,
            depth_kind: self.depth_kind,
            conv,
        }
    }

    /// Renders every target of the rig from `src` (validated by the caller), the source
    /// camera `k` at the source's size.
    pub fn render(&self, device: &Device, src: &ReprojectSource, k: Intrinsics) -> crate::Result<Vec<RenderedTarget>> {
        render_targets(
            device,
            src,
            &self.geometries(k, src.color.width, src.color.height)?,
            self.params,
        )
    }

    /// Each target eye's geometry for a source camera `k` of `width` x `height`.
    pub(super) fn geometries(
        &self,
        k: Intrinsics,
        width: u32,
        height: u32,
    ) -> crate::Result<Vec<(Option<Eye>, Geometry)>> {
        let camera = PinholeCamera { k, width, height };
        camera.validate("source intrinsics")?;
        let mut geometries = Vec::new();
        for (i, &to) in self.targets.iter().enumerate() {
            let shift = match &self.seed {
                Some(p) => ShiftModel::seed(p, camera.width, self.from, Some(to)),
                None => self.rectified[i],
            };
            shift.validate()?;
            geometries.push((Some(to), Geometry::Rig { camera, shift }));
        }
        Ok(geometries)
    }
}

/// Renders each target geometry from `src`, timing the set-up of each.
pub(super) fn render_targets(
    device: &Device,
    src: &ReprojectSource,
    targets: &[(Option<Eye>, Geometry)],
    params: ReprojectParams,
) -> crate::Result<Vec<RenderedTarget>> {
    let mut results = Vec::with_capacity(targets.len());
    for (to, geometry) in targets {
        let t0 = Instant::now();
        let mut r = Reprojector::new(device, src, geometry, params)?;
        let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
        let (out, timing) = r.render()?;
        results.push(RenderedTarget {
            to: *to,
            out,
            timing,
            setup_ms,
        });
    }
    Ok(results)
}
