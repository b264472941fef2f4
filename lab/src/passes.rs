//! Every pass of the library, described once and run on any device: the rows the report's
//! device-agreement table and the benchmark's per-pass timings share.
//!
//! A [`PassCase`] names a pass and, given the [`PassInputs`] of one size and convention and a
//! [`Device`] (GL or Vulkan: the lab never asks which), makes its frame: a closure that renders
//! and reads back, returning the views it made. GL against Vulkan is then nothing but the same
//! case run on two devices: timed by [`crate::bench::passes::passes_bench`], compared under the one
//! agreement rule of [`crate::eval::backends`] by [`crate::eval::backends::device_rows`].

use viewsynth::convention::Conventions;
use viewsynth::cyclopean::forward::ForwardWarp;
use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
use viewsynth::error::Result;
use viewsynth::io::RgbImage;
use viewsynth::pass::Device;
use viewsynth::refocus::manifest::{TargetSpec, DEFAULT_SCALES};
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusSource, Refocuser};
use viewsynth::reproject::render::Reprojector;
use viewsynth::scene::render::{GlCamera, SceneRenderer};
use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
use viewsynth::stereo::gather::{CyclopeanOutput, CyclopeanOutputs, CyclopeanParams, Method as Cm};
use viewsynth::stereo::matcher::Matcher;
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::{FrameDepth, StereoFrame};
use viewsynth::stitch::render::StitchRenderer;
use viewsynth::stitch::FaceSet;
use viewsynth::stitch::{faces::scene_faces, Method as Sm, OdsRig, Side, StitchParams};
use viewsynth::view::ViewOutput;

use crate::eval::reproject::{methods as reproject_methods, Case as ReprojectCase};

/// One frame of a pass on one device: renders, reads back and returns the views it made.
pub type Frame<'a> = Box<dyn FnMut() -> Result<Vec<ViewOutput>> + 'a>;

/// A pass of the library, by the name its rows carry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PassCase {
    /// Refocus, 5 focal scales a frame, on one path.
    Refocus(Method),
    /// Cyclopean gather (seed: 0 refinement steps).
    Cyclopean {
        /// Refinement steps.
        steps: u32,
    },
    /// Cyclopean splat-gather.
    Splat,
    /// Cyclopean forward warp.
    Forward,
    /// The census stereo matcher, both eyes, search 0-64 px.
    Matcher,
    /// Reprojection, by its index in the lab's method list.
    Reproject(usize),
    /// Stitch, one stereo equirect.
    Stitch(Sm),
    /// The scene ray tracer.
    Scene,
}

impl PassCase {
    /// Every pass, in table order.
    pub fn all() -> Vec<PassCase> {
        let mut v = vec![
            PassCase::Refocus(Method::Fullscreen),
            PassCase::Refocus(Method::Mesh),
            PassCase::Cyclopean { steps: 0 },
            PassCase::Cyclopean { steps: 3 },
            PassCase::Splat,
            PassCase::Forward,
            PassCase::Matcher,
        ];
        v.extend((0..reproject_methods().len()).map(PassCase::Reproject));
        v.extend(Sm::ALL.into_iter().map(PassCase::Stitch));
        v.push(PassCase::Scene);
        v
    }

    /// The row's name.
    pub fn name(&self) -> String {
        match self {
            PassCase::Refocus(Method::Fullscreen) => "refocus fullscreen".into(),
            PassCase::Refocus(Method::Mesh) => "refocus mesh".into(),
            PassCase::Cyclopean { steps: 0 } => "cyclopean seed".into(),
            PassCase::Cyclopean { steps } => format!("cyclopean refine {steps}"),
            PassCase::Splat => "cyclopean splat-gather".into(),
            PassCase::Forward => "cyclopean forward".into(),
            PassCase::Matcher => "census stereo matcher (0-64 px)".into(),
            PassCase::Reproject(k) => format!("reproject {}", reproject_methods()[*k].method.label()),
            PassCase::Stitch(m) => format!("stitch {}", m.label()),
            PassCase::Scene => "scene ray tracer".into(),
        }
    }

    /// The shader-library programs (`ProgramKind::name`) this case's frame runs: what ties the
    /// lab's cases to the registered programs (the test below).
    pub fn programs(&self) -> &'static [&'static str] {
        match self {
            PassCase::Refocus(Method::Fullscreen) => &["refocus/fullscreen"],
            PassCase::Refocus(Method::Mesh) => &["refocus/mesh_interior", "refocus/mesh_boundary"],
            PassCase::Cyclopean { .. } => &["cyclopean/gather"],
            PassCase::Splat => &[
                "cyclopean/edge_snap",
                "cyclopean/splat",
                "cyclopean/splat_gather",
                "cyclopean/splat_edges",
            ],
            PassCase::Forward => &["cyclopean/forward"],
            PassCase::Matcher => &[
                "cyclopean/matcher_grey",
                "cyclopean/matcher_census",
                "cyclopean/matcher_rows",
                "cyclopean/matcher_columns",
                "cyclopean/matcher_winner",
                "cyclopean/matcher_subpixel",
                "cyclopean/matcher_lr_check",
                "cyclopean/matcher_median",
            ],
            PassCase::Reproject(k) => match reproject_methods()[*k].method {
                viewsynth::reproject::Method::Gather3d { .. } => &["cyclopean/gather"],
                _ => &["reproject/shift"],
            },
            PassCase::Stitch(_) => &["stitch/stitch"],
            PassCase::Scene => &["scene/raytrace"],
        }
    }

    /// This pass's frame on `device` over `inputs`.
    pub fn frame<'a>(&self, device: &'a Device, inputs: &'a PassInputs) -> Result<Frame<'a>> {
        let (w, h) = (inputs.width, inputs.height);
        let cyclopean = move |(out, t): (CyclopeanOutput, viewsynth::pass::Timing)| {
            vec![ViewOutput::from_cyclopean(&out, w, h, Some(t))]
        };
        let mid = &inputs.mid;
        Ok(match *self {
            PassCase::Refocus(method) => {
                let mut r = Refocuser::new(
                    device,
                    &inputs.refocus,
                    &BreakRule::default(),
                    method,
                    OutputSet::default(),
                    inputs.conv,
                )?;
                let targets = &inputs.targets;
                Box::new(move || {
                    targets
                        .iter()
                        .map(|c| r.render(c).map(|o| ViewOutput::from_refocus(&o)))
                        .collect()
                })
            }
            PassCase::Cyclopean { steps } => {
                let seed = CyclopeanParams::seed(3.0);
                let params = match steps {
                    0 => seed,
                    steps => CyclopeanParams {
                        method: Cm::Refine { steps },
                        ..seed
                    },
                };
                let mut r = CyclopeanRenderer::new(device, &inputs.frame, params)?;
                Box::new(move || r.render(mid).map(cyclopean))
            }
            PassCase::Splat => {
                let mut r = SplatRenderer::new(
                    device,
                    &inputs.frame,
                    SplatParams::default(),
                    CyclopeanOutputs::default(),
                )?;
                Box::new(move || r.render(mid).map(cyclopean))
            }
            PassCase::Forward => {
                let mut r = ForwardWarp::new(device, &inputs.frame, &BreakRule::default())?;
                Box::new(move || r.render(mid).map(cyclopean))
            }
            PassCase::Matcher => {
                let (l, r) = (&inputs.pair.0, &inputs.pair.1);
                // The pair is at least 128 x 64 (the synthetic texture's smallest size).
                let (w, h) = (l.width, l.height);
                let mut m = Matcher::new(device, w, h, 64)?;
                // Disparities as depth planes (0 = unknown, so compared where both are known).
                Box::new(move || {
                    let (dl, dr) = m.estimate(l, r)?;
                    Ok([dl, dr]
                        .into_iter()
                        .map(|d| ViewOutput {
                            width: w,
                            height: h,
                            color: None,
                            depth: Some(d),
                            mask: None,
                            timing: None,
                            exact: None,
                        })
                        .collect())
                })
            }
            PassCase::Reproject(k) => {
                let case = &inputs.reproject;
                let mut r = Reprojector::new(device, &case.source, &case.geometry, reproject_methods()[k])?;
                Box::new(move || {
                    let (out, t) = r.render()?;
                    Ok(vec![ViewOutput::from_reproject(&out, w, h, Some(t))])
                })
            }
            PassCase::Stitch(method) => {
                let params = StitchParams {
                    method,
                    overlap_deg: 10.0,
                    width: 2 * w,
                    height: w,
                };
                let mut r = StitchRenderer::with_conventions(device, &inputs.faces.0, &inputs.faces.1, inputs.conv)?;
                Box::new(move || {
                    let out = r.render_outputs(&params, OutputSet::RGB_DEPTH)?;
                    Ok(vec![ViewOutput::from_stitch(out.color, out.distance, Some(out.timing))])
                })
            }
            PassCase::Scene => {
                let mut r = SceneRenderer::new(device, &inputs.scene)?;
                let cam = &inputs.camera;
                Box::new(move || {
                    let (img, t) = r.render(cam)?;
                    Ok(vec![ViewOutput {
                        width: w,
                        height: h,
                        color: Some(img.color),
                        depth: Some(img.view_z),
                        mask: None,
                        timing: Some(t),
                        exact: None,
                    }])
                })
            }
        })
    }
}

/// What every pass reads, built once for one size and convention from the built-in scene: the
/// refocus source and its 5 targets, the stereo frame and its middle camera, a matcher pair (at
/// least 128 x 64), a
/// reprojection case, the cube faces of both eyes (`width / 4` px, 110 deg) and the scene.
pub struct PassInputs {
    /// View width.
    pub width: u32,
    /// View height.
    pub height: u32,
    /// The conventions every pass runs under.
    pub conv: Conventions,
    refocus: RefocusSource,
    targets: Vec<viewsynth::camera::PinholeCamera>,
    frame: StereoFrame,
    mid: viewsynth::stereo::MiddleCamera,
    pair: (RgbImage, RgbImage),
    reproject: ReprojectCase,
    faces: (FaceSet, FaceSet),
    scene: viewsynth::world::Scene,
    camera: GlCamera,
}

impl PassInputs {
    /// The inputs at `width` x `height` under `conv`, the eyes' depth as device depth under it.
    pub fn new(width: u32, height: u32, conv: Conventions) -> Result<Self> {
        Self::with_depth(width, height, conv, FrameDepth::Device)
    }

    /// [`PassInputs::new`] with the eyes' depth (stereo frame and reprojection source) as `kind`:
    /// view Z gives every convention the same input bits.
    pub fn with_depth(width: u32, height: u32, conv: Conventions, kind: FrameDepth) -> Result<Self> {
        let cam = viewsynth::world::demo_camera(width, height);
        let (rgb, depth) = viewsynth::world::render(&cam);
        let refocus = RefocusSource::new(rgb, depth, cam.k)?;
        let targets = TargetSpec {
            scales: DEFAULT_SCALES.to_vec(),
            size: None,
            principal: None,
        }
        .targets(&cam)?;
        let (frame, mid, _) = scene_frame(&StereoRig::demo(width, height), conv, kind);
        let (l, r, _) = crate::bench::matcher::synthetic_pair(width.max(128), height.max(64))?;
        let reproject = crate::eval::reproject::scene_cases(width, height, 0.064, conv, kind)?
            .into_iter()
            .next()
            .ok_or_else(|| viewsynth::Error::param("passes", "no reprojection case"))?;
        let rig = OdsRig::demo();
        let face = (width / 4).max(16);
        let faces = (
            scene_faces(&rig, Side::Left, face, 110.0)?,
            scene_faces(&rig, Side::Right, face, 110.0)?,
        );
        let camera = GlCamera {
            view: frame.left.view,
            proj: frame.left.proj,
            width,
            height,
            conv,
        };
        Ok(PassInputs {
            width,
            height,
            conv,
            refocus,
            targets,
            frame,
            mid,
            pair: (l, r),
            reproject,
            faces,
            scene: viewsynth::world::builtin("demo")?,
            camera,
        })
    }
}

/// Registered programs the lab has no case for yet, each with why: a program added to the
/// shader library must get a case in [`PassCase::all`] or a line here
/// (`every_registered_program_has_a_lab_case`, the add-a-pass recipe in ARCHITECTURE.md).
pub const PROGRAMS_WITHOUT_A_CASE: &[(&str, &str)] = &[
    (
        "refocus/colour_everywhere",
        "only under --rgb-everywhere, which the refocus cases leave off",
    ),
    ("cyclopean/densify", "the two-image --fill path; no lab case yet"),
    ("cyclopean/fill", "--fill; no lab case yet"),
    ("cyclopean/temporal_reproject", "--sequence history; no lab case yet"),
    ("cyclopean/temporal_compose", "--sequence history; no lab case yet"),
    (
        "cyclopean/matcher_confidence",
        "only where confidence is asked for; the matcher case is not",
    ),
    (
        "cyclopean/matcher_sgm_downsample",
        "the semi-global matcher; the matcher case is census",
    ),
    (
        "cyclopean/matcher_sgm_cost",
        "the semi-global matcher; the matcher case is census",
    ),
    (
        "cyclopean/matcher_sgm_path",
        "the semi-global matcher; the matcher case is census",
    ),
    (
        "cyclopean/matcher_sgm_winner",
        "the semi-global matcher; the matcher case is census",
    ),
    (
        "cyclopean/matcher_trust",
        "the checked semi-global matcher's matched/inferred split; the matcher case is census",
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// The registered programs (by name) that neither a case of [`PassCase::all`] runs nor
    /// [`PROGRAMS_WITHOUT_A_CASE`] lists, and the names those two give that are not registered.
    fn programs_without_a_case() -> (Vec<&'static str>, Vec<&'static str>) {
        use std::collections::BTreeSet;
        let registered: BTreeSet<&'static str> = viewsynth::pass::ShaderProgram::all(Conventions::default())
            .iter()
            .map(|p| p.kind.name())
            .collect();
        let named: BTreeSet<&'static str> = PassCase::all()
            .iter()
            .flat_map(|c| c.programs().iter().copied())
            .chain(PROGRAMS_WITHOUT_A_CASE.iter().map(|(name, _)| *name))
            .collect();
        (
            registered.difference(&named).copied().collect(),
            named.difference(&registered).copied().collect(),
        )
    }

    #[test]
    fn every_registered_program_has_a_lab_case() {
        let (missing, unknown) = programs_without_a_case();
        assert!(
            missing.is_empty(),
            "programs with no lab case (PassCase) and no line in PROGRAMS_WITHOUT_A_CASE: {missing:?}"
        );
        assert!(
            unknown.is_empty(),
            "program names the lab gives that are not registered: {unknown:?}"
        );
    }
}
