//! `cyclopean`: the middle (spectator) view of a stereo pair, from a rectified pair with
//! disparities or from any pair with depth and a camera file. The options become a
//! [`CyclopeanJob`]; running it writes `middle_{rgb,depth,mask}` all-or-none.

use super::{ArgError, Backend, Event, GpuRequest, Host, JobError};
use crate::convention::{Conventions, DepthPlanes};
use crate::cyclopean::camera_file::{CameraFile, EyeCameras};
use crate::cyclopean::disparity_frame::{disparity_frame, DisparityRig};
use crate::cyclopean::fill::{Filler, FILLED};
use crate::cyclopean::forward::ForwardWarp;
use crate::cyclopean::render::CyclopeanRenderer;
use crate::cyclopean::splat::{SplatParams, SplatRenderer};
use crate::cyclopean::{
    Blend, CyclopeanOutputs, CyclopeanParams, Eye, EyeInput, FrameDepth, MiddleCamera, StereoFrame,
};
use crate::depth::DepthEncoding;
use crate::io::{self, DepthDecode, DepthMap, DepthSummary, RgbImage};
use crate::refocus::{BreakRule, OutputSet};
use crate::view::ViewOutput;
use std::path::{Path, PathBuf};

/// How the middle view is synthesised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CyclopeanMethod {
    /// Splat each eye's surfaces, refine each pixel on the surface it sees, merge the eyes.
    SplatGather,
    /// Seed 000: one reconstruction step from the fixation depth.
    Seed,
    /// The seed's step, `--refine-steps` refinement steps and a projection check.
    Refine,
    /// Each eye's depth mesh rendered into the view, the nearest surface wins.
    Forward,
}

impl CyclopeanMethod {
    /// The name `--method` takes.
    pub fn name(self) -> &'static str {
        match self {
            CyclopeanMethod::SplatGather => "splat-gather",
            CyclopeanMethod::Seed => "seed",
            CyclopeanMethod::Refine => "refine",
            CyclopeanMethod::Forward => "forward",
        }
    }
}

/// The cyclopean options as given.
#[derive(Debug, Clone, Default)]
pub struct CyclopeanOptions {
    /// Left eye colour.
    pub left_rgb: PathBuf,
    /// Right eye colour.
    pub right_rgb: PathBuf,
    /// Left disparity (rectified pair).
    pub left_disparity: Option<PathBuf>,
    /// Right disparity.
    pub right_disparity: Option<PathBuf>,
    /// Raw disparity units per pixel.
    pub disparity_scale: Option<f64>,
    /// Right principal point minus left, pixels.
    pub doffs: f64,
    /// Focal length, pixels (with `baseline`: metric depth).
    pub focal: Option<f64>,
    /// Baseline, metres.
    pub baseline: Option<f64>,
    /// Where the view sits between the eyes (0 left, 1 right).
    pub position: Option<f64>,
    /// Left depth (with a camera file).
    pub left_depth: Option<PathBuf>,
    /// Right depth.
    pub right_depth: Option<PathBuf>,
    /// The camera file.
    pub cameras: Option<PathBuf>,
    /// Raw units per unit of depth for integer depth files.
    pub depth_scale: Option<f64>,
    /// The `.npz` array to read.
    pub npz_key: Option<String>,
    /// The method, when given.
    pub method: Option<CyclopeanMethod>,
    /// Seed/refine: reconstruction steps.
    pub refine_steps: Option<u32>,
    /// Seed/refine: how the eyes are blended.
    pub blend: Option<Blend>,
    /// Seed/refine: depth disagreement treated as different surfaces.
    pub z_threshold: Option<f64>,
    /// Seed/refine: `left:W` or `right:W`.
    pub dominant: Option<String>,
    /// `--outputs`, when given.
    pub outputs: Option<String>,
    /// `--fill`: holes filled from the background side (mask 128 there); off, holes stay.
    pub fill: bool,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The GPU to render on.
    pub gpu: GpuRequest,
    /// GL, or Vulkan (every method).
    pub backend: Backend,
}

/// Where the stereo pair and its geometry come from.
#[derive(Debug, Clone)]
enum Input {
    /// A rectified pair with disparities; without a calibration only f B matters.
    Disparity(DisparityInput),
    /// Depth per eye and the camera file with their matrices.
    CameraFile(CameraFileInput),
}

/// [`Input::Disparity`]: the disparity files and the rig.
#[derive(Debug, Clone)]
struct DisparityInput {
    left: PathBuf,
    right: PathBuf,
    scale: f64,
    focal: Option<f64>,
    baseline: Option<f64>,
    doffs: f64,
    position: f64,
}

/// [`Input::CameraFile`]: the camera file and each eye's depth file.
#[derive(Debug, Clone)]
struct CameraFileInput {
    cameras: PathBuf,
    left: PathBuf,
    right: PathBuf,
    depth_scale: Option<f64>,
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
            params.method = crate::cyclopean::Method::Refine { steps: self.steps };
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

/// A checked cyclopean run.
#[derive(Debug, Clone)]
pub struct CyclopeanJob {
    left_rgb: PathBuf,
    right_rgb: PathBuf,
    input: Input,
    npz_key: Option<String>,
    method: CyclopeanMethod,
    gather: Option<GatherSettings>,
    outputs: OutputSet,
    fill: bool,
    out_dir: PathBuf,
    gpu: GpuRequest,
    backend: Backend,
}

/// What a cyclopean run wrote.
#[derive(Debug)]
pub struct CyclopeanReport {
    /// View width.
    pub width: u32,
    /// View height.
    pub height: u32,
    /// Fraction of pixels some eye saw.
    pub valid_fraction: f64,
    /// Render wall time.
    pub render_ms: f64,
    /// The files written.
    pub written: Vec<PathBuf>,
}

fn dominant(d: &str) -> Result<(Eye, f64), ArgError> {
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

impl CyclopeanJob {
    /// Checks the options against each other: one input set-up, method options with their
    /// method, outputs the input can give.
    pub fn new(o: CyclopeanOptions) -> Result<Self, ArgError> {
        let method = match (o.method, o.refine_steps) {
            (Some(m), _) => m,
            (None, Some(0)) => CyclopeanMethod::Seed,
            (None, Some(_)) => CyclopeanMethod::Refine,
            (None, None) => CyclopeanMethod::SplatGather,
        };
        let gathers = matches!(method, CyclopeanMethod::Seed | CyclopeanMethod::Refine);
        if !gathers {
            for (flag, given) in [
                ("--refine-steps", o.refine_steps.is_some()),
                ("--blend", o.blend.is_some()),
                ("--z-threshold", o.z_threshold.is_some()),
                ("--dominant", o.dominant.is_some()),
            ] {
                if given {
                    return Err(ArgError::GatherOptionOnly(flag));
                }
            }
        }
        let (input, metric_depth) = match (&o.left_disparity, &o.cameras) {
            (Some(left), _) => {
                let Some(right) = o.right_disparity.clone() else {
                    return Err(ArgError::RightDisparityMissing);
                };
                super::check_npz_key(o.npz_key.as_deref(), &[left, &right])?;
                if o.depth_scale.is_some() {
                    return Err(ArgError::DepthScaleWithDisparity);
                }
                check_scale("--disparity-scale", o.disparity_scale)?;
                if !o.doffs.is_finite() {
                    return Err(ArgError::Invalid(crate::Error::param(
                        "--doffs",
                        format!("{} must be finite", o.doffs),
                    )));
                }
                // The bounds of focal lengths everywhere (intrinsics, flags, files); a baseline is
                // a length, held to the options' magnitude.
                use crate::camera::{MAX_INTRINSIC, MIN_FOCAL_PX};
                let min_baseline = f64::from(crate::depth::MIN_DEPTH_VALUE);
                for (flag, v, lo) in [
                    ("--focal", o.focal, MIN_FOCAL_PX),
                    ("--baseline", o.baseline, min_baseline),
                ] {
                    if let Some(v) = v.filter(|v| !(v.is_finite() && (lo..=MAX_INTRINSIC).contains(v))) {
                        return Err(ArgError::Invalid(crate::Error::param(
                            flag,
                            format!("{v} must be in [{lo:e}, {MAX_INTRINSIC:e}]"),
                        )));
                    }
                }
                if let Some(p) = o.position.filter(|p| !(0.0..=1.0).contains(p)) {
                    return Err(ArgError::Invalid(crate::Error::param(
                        "--position",
                        format!("{p} outside [0, 1] (0 = left eye, 1 = right eye)"),
                    )));
                }
                let input = Input::Disparity(DisparityInput {
                    left: left.clone(),
                    right,
                    scale: o.disparity_scale.unwrap_or(1.0),
                    focal: o.focal,
                    baseline: o.baseline,
                    doffs: o.doffs,
                    position: o.position.unwrap_or(0.5),
                });
                (input, o.focal.is_some())
            }
            (None, Some(cameras)) => {
                for (flag, given) in [
                    ("--position", o.position.is_some()),
                    ("--focal", o.focal.is_some()),
                    ("--disparity-scale", o.disparity_scale.is_some()),
                    ("--doffs", o.doffs != 0.0),
                ] {
                    if given {
                        return Err(ArgError::RigOptionWithCameraFile(flag));
                    }
                }
                let (Some(left), Some(right)) = (o.left_depth.clone(), o.right_depth.clone()) else {
                    return Err(ArgError::CameraFileWithoutDepth);
                };
                super::check_npz_key(o.npz_key.as_deref(), &[&left, &right])?;
                check_scale("--depth-scale", o.depth_scale)?;
                let input = Input::CameraFile(CameraFileInput {
                    cameras: cameras.clone(),
                    left,
                    right,
                    depth_scale: o.depth_scale,
                });
                (input, true)
            }
            (None, None) => return Err(ArgError::NoStereoInput),
        };
        let outputs = match &o.outputs {
            Some(list) => OutputSet::parse(list)?,
            None => OutputSet {
                rgb: true,
                depth: metric_depth,
                mask: true,
            },
        };
        if outputs.depth && !metric_depth {
            return Err(ArgError::DepthOutputNotMetric);
        }
        let gather = match gathers {
            true => Some(GatherSettings {
                refine: method == CyclopeanMethod::Refine,
                steps: o.refine_steps.unwrap_or(3),
                blend: o.blend.unwrap_or(Blend::Hard),
                z_threshold: o.z_threshold,
                dominant: o.dominant.as_deref().map(dominant).transpose()?,
            }),
            false => None,
        };
        Ok(CyclopeanJob {
            left_rgb: o.left_rgb,
            right_rgb: o.right_rgb,
            input,
            npz_key: o.npz_key,
            method,
            gather,
            outputs,
            fill: o.fill,
            out_dir: o.out_dir,
            gpu: o.gpu,
            backend: o.backend,
        })
    }

    /// `--out-dir`.
    pub fn out_dir(&self) -> &Path {
        &self.out_dir
    }

    /// Reads the pair, renders the view and writes the requested files all-or-none.
    pub fn run(&self, host: &dyn Host) -> Result<CyclopeanReport, JobError> {
        let (frame, mid, fixation) = match &self.input {
            Input::Disparity(input) => self.disparity_setup(input)?,
            Input::CameraFile(input) => self.camera_file_setup(input, host)?,
        };
        frame.validate()?;
        let params = self.gather.map(|g| g.params(fixation)).transpose()?;
        let out_dir = io::OutDir::prepare(&self.out_dir)?;
        // The fill reads both planes whatever is written.
        let wanted = CyclopeanOutputs {
            color: self.outputs.rgb || self.fill,
            depth: self.outputs.depth || self.fill,
        };
        let device = host.open_device(&self.gpu, self.backend)?;
        let (mut out, timing) = match (self.method, params) {
            (CyclopeanMethod::Seed | CyclopeanMethod::Refine, Some(p)) => {
                CyclopeanRenderer::with_outputs(&device, &frame, p, wanted)?.render(&mid)?
            }
            (CyclopeanMethod::Forward, _) => ForwardWarp::new(&device, &frame, &BreakRule::default())?.render(&mid)?,
            _ => SplatRenderer::new(&device, &frame, SplatParams::default(), wanted)?.render(&mid)?,
        };
        if self.fill {
            out = Filler::new(&device)?.fill(&out, mid.width, mid.height)?;
        }
        // The mask: 1 where an eye (or the history) gave the pixel, MASK_FILLED where it was filled.
        let mask = io::Mask::new(
            mid.width,
            mid.height,
            out.sources
                .iter()
                .map(|&s| match s {
                    0 => 0,
                    FILLED => io::MASK_FILLED,
                    _ => 1,
                })
                .collect(),
        )?;
        let valid = out.sources.iter().filter(|s| **s != 0 && **s != FILLED).count();
        let view = ViewOutput {
            width: mid.width,
            height: mid.height,
            color: out.color,
            depth: out.depth,
            mask: Some(mask),
            timing: Some(timing),
            exact: None,
        };
        let formats = io::FileFormats {
            outputs: self.outputs,
            ..Default::default()
        };
        let mut set = out_dir.file_set()?;
        io::write_view(&mut set, &io::ViewNames::tagged("middle"), &view, &formats)?;
        let written = set.commit()?;
        Ok(CyclopeanReport {
            width: mid.width,
            height: mid.height,
            valid_fraction: valid as f64 / out.sources.len() as f64,
            render_ms: timing.wall_ms,
            written,
        })
    }

    /// A rectified pair: the frame, the view, and the fixation the seed/refine methods start
    /// from (the median depth the left eye saw).
    fn disparity_setup(&self, input: &DisparityInput) -> Result<(StereoFrame, MiddleCamera, f64), JobError> {
        let DisparityInput {
            left,
            right,
            scale,
            focal,
            baseline,
            doffs,
            position,
        } = input;
        let decode = DepthDecode {
            scale: Some(*scale),
            ..Default::default()
        };
        let eye = |rgb: &Path, disparity: &Path| -> crate::Result<(RgbImage, DepthMap)> {
            io::check_rgbd_sizes(rgb, disparity)?;
            Ok((
                io::load_rgb(rgb)?,
                io::load_depth_with_key(disparity, self.npz_key.as_deref(), &decode)?,
            ))
        };
        let l = eye(&self.left_rgb, left)?;
        let r = eye(&self.right_rgb, right)?;
        // Without a calibration only f B matters for the view; any nominal values do.
        let rig = DisparityRig {
            focal_px: focal.unwrap_or(l.0.width as f64),
            baseline: baseline.unwrap_or(0.1),
            doffs: *doffs,
            position: *position,
        };
        let known = l.1.data.iter().any(|&d| d.is_finite() && d > 0.0);
        let (frame, mid) = disparity_frame(l, r, &rig, Conventions::default())?;
        // f B / d outside the usable depths makes holes (the one depth rule); all of them is the
        // rig's fault, said by name rather than a silent 0 % valid view.
        if known && !frame.left.depth.data.iter().any(|z| z.is_finite() && *z > 0.0) {
            return Err(crate::Error::param(
                "--focal/--baseline",
                format!(
                    "f B / disparity = {:e} m / px puts every known disparity of {} outside the usable depths [{:e}, {:e}] m",
                    rig.focal_px * rig.baseline,
                    left.display(),
                    crate::depth::MIN_DEPTH_VALUE,
                    crate::depth::MAX_DEPTH_VALUE
                ),
            )
            .into());
        }
        let fixation = crate::cyclopean::disparity_frame::median_fixation(&frame)
            .ok_or_else(|| crate::Error::decode(left, "no known disparity (all 0 or non-finite)"))?;
        Ok((frame, mid, fixation))
    }

    /// Depth per eye placed by the camera file.
    fn camera_file_setup(
        &self,
        input: &CameraFileInput,
        host: &dyn Host,
    ) -> Result<(StereoFrame, MiddleCamera, f64), JobError> {
        let CameraFileInput {
            cameras,
            left,
            right,
            depth_scale,
        } = input;
        let cams = CameraFile::load(cameras)?;
        let (mid, fixation) = cams.middle_and_fixation()?;
        let decode = DepthDecode {
            scale: *depth_scale,
            ..Default::default()
        };
        let eye = |rgb: &Path, depth: &Path, cam: &EyeCameras| -> crate::Result<EyeInput> {
            // Sizes and the pixel budget from the headers before either file is decoded.
            io::check_rgbd_sizes(rgb, depth)?;
            let color = io::load_rgb(rgb)?;
            cam.check_size(&rgb.display().to_string(), color.width, color.height)?;
            Ok(EyeInput {
                color,
                depth: io::load_depth_with_key(depth, self.npz_key.as_deref(), &decode)?,
                view: cam.view,
                proj: cam.proj,
            })
        };
        let frame = StereoFrame {
            left: eye(&self.left_rgb, left, &cams.left)?,
            right: eye(&self.right_rgb, right, &cams.right)?,
            depth_kind: cams.depth_kind,
            conv: cams.conventions,
        };
        for (path, eye) in [(left, &frame.left), (right, &frame.right)] {
            let hint = format!(
                "read as {:?} depth (check depth_kind and the projections in {}, and --depth-scale)",
                frame.depth_kind,
                cameras.display()
            );
            host.event(Event::InputDepth {
                path,
                summary: &DepthSummary::of(&view_z_in_metres(eye, frame.depth_kind, &frame.conv)?),
                hint: &hint,
            });
        }
        Ok((frame, mid, fixation))
    }
}

/// An eye's depth as view Z in metres (0 where invalid), for the input summary.
fn view_z_in_metres(eye: &EyeInput, kind: FrameDepth, conv: &Conventions) -> crate::Result<DepthMap> {
    let input = match kind {
        FrameDepth::ViewZ => DepthEncoding::ViewZ,
        FrameDepth::Device => DepthEncoding::Device {
            planes: DepthPlanes::from_gl_projection(&eye.proj, conv)?,
        },
    };
    Ok(input.view_z_map(conv, &eye.depth))
}

/// A scale option, when given, must be finite and > 0 (refused by its own name, before any
/// input is read).
pub(crate) fn check_scale(option: &'static str, value: Option<f64>) -> Result<(), ArgError> {
    match value {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(ArgError::Scale { option, value: v }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::{dominant, ArgError, Blend, CyclopeanJob, CyclopeanMethod, CyclopeanOptions, Eye};

    fn disparity_options() -> CyclopeanOptions {
        CyclopeanOptions {
            left_rgb: "l.png".into(),
            right_rgb: "r.png".into(),
            left_disparity: Some("ld.pgm".into()),
            right_disparity: Some("rd.pgm".into()),
            ..Default::default()
        }
    }

    #[test]
    fn method_options_need_their_method() {
        let o = CyclopeanOptions {
            blend: Some(Blend::Soft),
            ..disparity_options()
        };
        assert!(matches!(
            CyclopeanJob::new(o),
            Err(ArgError::GatherOptionOnly("--blend"))
        ));
        // A lone --refine-steps picks the method, so its options are accepted.
        let o = CyclopeanOptions {
            refine_steps: Some(0),
            blend: Some(Blend::Soft),
            ..disparity_options()
        };
        assert_eq!(CyclopeanJob::new(o).unwrap().method, CyclopeanMethod::Seed);
    }

    #[test]
    fn vulkan_backend_takes_every_method() {
        use super::Backend;
        for method in [
            None,
            Some(CyclopeanMethod::SplatGather),
            Some(CyclopeanMethod::Seed),
            Some(CyclopeanMethod::Refine),
            Some(CyclopeanMethod::Forward),
        ] {
            let o = CyclopeanOptions {
                method,
                backend: Backend::Vulkan,
                ..disparity_options()
            };
            assert_eq!(CyclopeanJob::new(o).unwrap().backend, Backend::Vulkan);
        }
    }

    #[test]
    fn dominant_eye_is_parsed_once_and_named_on_error() {
        assert_eq!(dominant("right:0.7").unwrap(), (Eye::Right, 0.7));
        assert!(matches!(dominant("0.7"), Err(ArgError::DominantForm(_))));
        assert!(matches!(dominant("centre:0.7"), Err(ArgError::DominantEye(_))));
        let e = dominant("left:heavy").unwrap_err();
        assert!(matches!(e, ArgError::DominantWeight { .. }), "{e}");
    }

    #[test]
    fn uncalibrated_disparity_gives_no_metric_depth() {
        let job = CyclopeanJob::new(disparity_options()).unwrap();
        assert!(!job.outputs.depth && job.outputs.rgb);
        let o = CyclopeanOptions {
            outputs: Some("depth".into()),
            ..disparity_options()
        };
        assert!(matches!(CyclopeanJob::new(o), Err(ArgError::DepthOutputNotMetric)));
    }
}
