//! `cyclopean`: the middle (spectator) view of a stereo pair, from a rectified pair with
//! disparities or from any pair with depth and a camera file. The options become a
//! [`CyclopeanJob`]; running it writes `middle_{rgb,depth,mask}` (and, two images alone,
//! `{left,right}_confidence.exr`) all-or-none.

use super::{ArgError, Backend, Event, GpuRequest, Host, JobError};
use crate::convention::{Conventions, DepthPlanes};
use crate::cyclopean::pipeline::{CyclopeanPlan, Framed, InputName, Reused, StereoInput, StereoKind, Synthesised};
use crate::depth::DepthEncoding;
use crate::io::{self, DepthDecode, DepthMap, DepthSummary, RgbImage};
use crate::pass::Device;
use crate::stereo::camera_file::CameraFile;
use crate::stereo::one_eye::other_eye_disparity;
use crate::stereo::{Eye, EyeInput, FrameDepth};
use std::path::{Path, PathBuf};

mod request;
mod sequence;

pub use request::{CyclopeanRequest, StereoGiven};
pub use sequence::{load_sequence, CyclopeanSequenceJob, SequenceFrame, MAX_SEQUENCE_FRAMES};

/// The files of each eye's matcher confidence (`--confidence`), left then right.
pub const CONFIDENCE_FILES: [&str; 2] = ["left_confidence.exr", "right_confidence.exr"];

/// Whether `name` is one this command may write into its folder: a pair's files and a
/// sequence's frames all start with `middle_`, beside the confidence files. No input may have
/// such a name there.
pub(crate) fn owned_name(name: &str) -> bool {
    name.starts_with("middle_") || CONFIDENCE_FILES.contains(&name)
}

/// What a run's set replaces: the files the previous run's record lists (the one deletion rule,
/// [`io::Replaces`]), never a file merely named as this command names its outputs.
pub(crate) fn replaced() -> io::Replaces {
    io::Replaces::recorded("cyclopean")
}

/// The cyclopean options as given: the files, how to decode them, and the request.
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
    /// Every setting the Python binding gives too.
    pub request: CyclopeanRequest,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The GPU to render on.
    pub gpu: GpuRequest,
    /// GL, or Vulkan (every method).
    pub backend: Backend,
}

/// A checked cyclopean run.
#[derive(Debug, Clone)]
pub struct CyclopeanJob {
    left_rgb: PathBuf,
    right_rgb: PathBuf,
    /// Left and right disparity or depth files (none: two images alone). Disparities may give
    /// one eye only: the other's is derived ([`crate::stereo::one_eye`]).
    maps: Option<(Option<PathBuf>, Option<PathBuf>)>,
    cameras: Option<PathBuf>,
    decode: DepthDecode,
    npz_key: Option<String>,
    plan: CyclopeanPlan,
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
    /// Frames rendered (1 without a sequence).
    pub frames: usize,
    /// Fraction of pixels some eye saw (the mean over a sequence's frames).
    pub valid_fraction: f64,
    /// Render wall time (the sum over a sequence's frames).
    pub render_ms: f64,
    /// The files written.
    pub written: Vec<PathBuf>,
}

impl CyclopeanJob {
    /// Checks the options: one input set-up, the files' decoding options for it, and the
    /// request ([`CyclopeanRequest::plan`]).
    pub fn new(o: CyclopeanOptions) -> Result<Self, ArgError> {
        o.gpu.check_backend(o.backend)?;
        let kind = StereoGiven {
            left_disparity: o.left_disparity.is_some(),
            right_disparity: o.right_disparity.is_some(),
            left_depth: o.left_depth.is_some(),
            right_depth: o.right_depth.is_some(),
            cameras: o.cameras.is_some(),
        }
        .kind()?;
        let (maps, scale) = match kind {
            StereoKind::Images => {
                for (flag, given) in [
                    (crate::Field::DisparityScale, o.disparity_scale.is_some()),
                    (crate::Field::DepthScale, o.depth_scale.is_some()),
                    (crate::Field::NpzKey, o.npz_key.is_some()),
                ] {
                    if given {
                        return Err(ArgError::DecodeWithoutMaps(flag));
                    }
                }
                (None, None)
            }
            StereoKind::Disparity => {
                if o.depth_scale.is_some() {
                    return Err(ArgError::DepthScaleWithDisparity);
                }
                check_scale(crate::Field::DisparityScale, o.disparity_scale)?;
                let maps = (o.left_disparity.clone(), o.right_disparity.clone());
                (Some(maps), Some(o.disparity_scale.unwrap_or(1.0)))
            }
            StereoKind::Cameras => {
                if o.disparity_scale.is_some() {
                    return Err(ArgError::RigOptionWithCameraFile(crate::Field::DisparityScale));
                }
                check_scale(crate::Field::DepthScale, o.depth_scale)?;
                (Some((o.left_depth.clone(), o.right_depth.clone())), o.depth_scale)
            }
        };
        let map_files: Vec<crate::output::NamedPath<'_>> = maps
            .iter()
            .flat_map(|(l, r)| {
                [
                    (crate::msg![crate::Field::LeftDepth, "/disparity"], l),
                    (crate::msg![crate::Field::RightDepth, "/disparity"], r),
                ]
            })
            .filter_map(|(flag, p)| Some((flag, p.as_deref()?)))
            .collect();
        if !map_files.is_empty() {
            let files: Vec<&Path> = map_files.iter().map(|f| f.1).collect();
            super::check_npz_key(o.npz_key.as_deref(), &files)?;
        }
        let plan = o.request.plan(kind)?;
        let mut inputs = vec![
            (crate::Field::LeftRgb.into(), o.left_rgb.as_path()),
            (crate::Field::RightRgb.into(), o.right_rgb.as_path()),
        ];
        inputs.extend(map_files);
        inputs.extend(o.cameras.as_deref().map(|c| (crate::Field::Cameras.into(), c)));
        crate::output::check_out_dir(&o.out_dir, owned_name, &replaced(), &inputs).map_err(ArgError::Invalid)?;
        Ok(CyclopeanJob {
            left_rgb: o.left_rgb,
            right_rgb: o.right_rgb,
            maps,
            cameras: o.cameras,
            decode: DepthDecode {
                scale,
                ..Default::default()
            },
            npz_key: o.npz_key,
            plan,
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
        // The GPU before the folder: two images alone are matched on it, and a refused input
        // leaves no folder behind.
        let device = host.open_device(&self.gpu, self.backend)?;
        let view = self.render(&device, host, None)?;
        let out_dir = io::OutDir::prepare(&self.out_dir)?;
        let mut set = out_dir.file_set()?.replacing(replaced());
        crate::output::write_view(
            &mut set,
            &crate::output::ViewNames::tagged("middle"),
            &view.done.view,
            &self.formats(),
        )?;
        let maps: Vec<_> = CONFIDENCE_FILES
            .into_iter()
            .zip(view.confidence.iter().flatten())
            .collect();
        crate::output::write_float_exrs(&mut set, &maps)?;
        let written = set.commit()?;
        Ok(CyclopeanReport {
            width: view.size.0,
            height: view.size.1,
            frames: 1,
            valid_fraction: view.done.coverage,
            render_ms: view.done.view.timing.map_or(0.0, |t| t.wall_ms),
            written,
        })
    }

    /// The file formats of the plan's outputs.
    pub(crate) fn formats(&self) -> crate::output::FileFormats {
        crate::output::FileFormats {
            outputs: self.plan.outputs(),
            ..Default::default()
        }
    }

    /// Reads the pair (sizes checked from the headers before anything is decoded).
    fn input(&self) -> crate::Result<StereoInput> {
        Ok(match &self.maps {
            None => {
                let (l, r) = (
                    io::rgb_dimensions(&self.left_rgb)?,
                    io::rgb_dimensions(&self.right_rgb)?,
                );
                if l != r {
                    return Err(crate::Error::SizeMismatch {
                        message: format!(
                            "left {} is {}x{} but right {} is {}x{} (from their headers; nothing decoded)",
                            self.left_rgb.display(),
                            l.0,
                            l.1,
                            self.right_rgb.display(),
                            r.0,
                            r.1
                        ),
                    });
                }
                StereoInput::Images {
                    left: io::load_rgb(&self.left_rgb)?,
                    right: io::load_rgb(&self.right_rgb)?,
                }
            }
            Some((left_map, right_map)) => {
                // An eye without a map is checked against the other eye's map (one pair size).
                let given = left_map.as_ref().or(right_map.as_ref()).ok_or_else(|| {
                    crate::Error::param(crate::Field::LeftDisparity, "neither eye's disparity or depth is given")
                })?;
                let eye = |rgb: &Path, map: Option<&PathBuf>| -> crate::Result<(RgbImage, Option<DepthMap>)> {
                    io::check_rgbd_sizes(rgb, map.unwrap_or(given))?;
                    let depth = map
                        .map(|m| io::load_depth_with_key(m, self.npz_key.as_deref(), &self.decode))
                        .transpose()?;
                    Ok((io::load_rgb(rgb)?, depth))
                };
                let (left_rgb, left_d) = eye(&self.left_rgb, left_map.as_ref())?;
                let (right_rgb, right_d) = eye(&self.right_rgb, right_map.as_ref())?;
                let (left_d, right_d) = match (left_d, right_d) {
                    (Some(l), Some(r)) => (l, r),
                    (Some(l), None) => {
                        let r = other_eye_disparity(&l, Eye::Left);
                        (l, r)
                    }
                    (None, Some(r)) => (other_eye_disparity(&r, Eye::Right), r),
                    (None, None) => unreachable!("`given` is one of the two maps"),
                };
                let (left, right) = ((left_rgb, left_d), (right_rgb, right_d));
                match &self.cameras {
                    None => StereoInput::Disparity { left, right },
                    Some(path) => StereoInput::Cameras {
                        left,
                        right,
                        cameras: Box::new(CameraFile::load(path)?),
                    },
                }
            }
        })
    }

    /// Reads the pair and renders its view on `device`, writing nothing: the view the job would
    /// write, as the lab's report scores it beside its peers.
    pub fn render_only(&self, device: &Device, host: &dyn Host) -> crate::Result<Synthesised> {
        Ok(self.render(device, host, None)?.done)
    }

    /// Reads the pair and renders its view on `device` (with a sequence's renderers, if any).
    pub(crate) fn render(
        &self,
        device: &Device,
        host: &dyn Host,
        mut reuse: Option<&mut Reused>,
    ) -> crate::Result<RenderedView> {
        let input = self.input()?;
        if let (StereoInput::Disparity { left, right }, Some((left_map, right_map))) = (&input, &self.maps) {
            tell_disparities(
                host,
                [left_map.as_deref(), right_map.as_deref()],
                (left, right),
                self.decode.scale.unwrap_or(1.0),
            );
        }
        let left_map = self
            .maps
            .as_ref()
            .and_then(|m| m.0.as_deref().or(m.1.as_deref()))
            .unwrap_or(self.left_rgb.as_path());
        let names = [
            InputName::File(&self.left_rgb),
            InputName::File(&self.right_rgb),
            InputName::File(left_map),
            InputName::File(self.cameras.as_deref().unwrap_or(left_map)),
        ];
        let Framed {
            frame,
            mid,
            fixation,
            confidence,
            range,
            dense,
        } = self.plan.frame(device, input, names, reuse.as_deref_mut())?;
        if let Some((range, estimated)) = range {
            host.event(Event::DisparityRange {
                min: range.min,
                max: range.max,
                estimated,
            });
        }
        if let (Some(cameras), Some((Some(left_map), Some(right_map)))) = (&self.cameras, &self.maps) {
            for (path, eye) in [(left_map, &frame.left), (right_map, &frame.right)] {
                // cyclopean takes the conventions and planes from the file alone (--ndc and
                // the like are refused with --cameras): the hint names the file's keys.
                let hint = crate::msg![
                    format!(
                        "read as {} depth under {}: check its depth_kind, conventions (ndc_depth, reversed_z) \
                         and each eye's proj or near/far (docs/formats.md); for integer depth files, `",
                        frame.depth_kind.name(),
                        cameras.display()
                    ),
                    crate::Field::DepthScale,
                    " S` (raw units per metre)"
                ];
                host.event(Event::InputDepth {
                    path,
                    summary: &depth_summary(eye, frame.depth_kind, &frame.conv)?,
                    hint: &hint,
                });
            }
        }
        let done = self
            .plan
            .synthesise(device, &frame, &mid, fixation, dense.as_ref(), reuse)?;
        Ok(RenderedView {
            done,
            confidence,
            size: (mid.width, mid.height),
        })
    }
}

/// One view rendered, before it is written.
pub(crate) struct RenderedView {
    pub(crate) done: Synthesised,
    confidence: Option<[DepthMap; 2]>,
    size: (u32, u32),
}

/// Each given disparity map's summary, with the pair's photometric scale check (cheap: a
/// subsample), told to the host: a wrong `--disparity-scale` renders a plausible wrong view at
/// exit 0. An eye without a file (`None`) had its map derived: the host is told so, and the
/// scale check uses the given map alone (the derived one would only repeat it).
fn tell_disparities(
    host: &dyn Host,
    paths: [Option<&Path>; 2],
    (left, right): (&(RgbImage, DepthMap), &(RgbImage, DepthMap)),
    scale: f64,
) {
    let unknown = |m: &DepthMap| DepthMap {
        data: vec![0.0; m.data.len()],
        ..m.clone()
    };
    let fit_map = |path: Option<&Path>, m: &DepthMap| if path.is_some() { m.clone() } else { unknown(m) };
    let fit = io::fit_disparity_scale(
        (&left.0, &fit_map(paths[0], &left.1)),
        (&right.0, &fit_map(paths[1], &right.1)),
        scale,
    );
    let eyes = [(Eye::Left, left), (Eye::Right, right)];
    for (path, (eye, (_, map))) in paths.into_iter().zip(eyes) {
        match path {
            Some(path) => host.event(Event::InputDisparity {
                path,
                summary: &io::DisparitySummary::of(map, scale, fit),
            }),
            None => {
                let known = map.data.iter().filter(|d| d.is_finite() && **d != 0.0).count();
                host.event(Event::DisparityDerived {
                    eye,
                    known_fraction: known as f64 / map.data.len().max(1) as f64,
                });
            }
        }
    }
}

/// An eye's depth as view Z in metres, summarised (device depth checked for a degenerate decoding).
fn depth_summary(eye: &EyeInput, kind: FrameDepth, conv: &Conventions) -> crate::Result<DepthSummary> {
    let input = match kind {
        FrameDepth::ViewZ => DepthEncoding::ViewZ,
        FrameDepth::Device => DepthEncoding::Device {
            planes: DepthPlanes::from_gl_projection(&eye.proj, conv)?,
        },
    };
    Ok(input.summary(conv, &eye.depth))
}

/// A scale option, when given, must be finite and > 0 (refused by its own name, before any
/// input is read).
pub(crate) fn check_scale(option: crate::Field, value: Option<f64>) -> Result<(), ArgError> {
    match value {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(ArgError::Scale { option, value: v }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::request::dominant;
    use super::{ArgError, CyclopeanJob, CyclopeanOptions, CyclopeanRequest};
    use crate::cyclopean::CyclopeanMethod;
    use crate::stereo::gather::Blend;
    use crate::stereo::Eye;

    fn disparity_options(request: CyclopeanRequest) -> CyclopeanOptions {
        CyclopeanOptions {
            left_rgb: "l.png".into(),
            right_rgb: "r.png".into(),
            left_disparity: Some("ld.pgm".into()),
            right_disparity: Some("rd.pgm".into()),
            request,
            ..Default::default()
        }
    }

    #[test]
    fn method_options_need_their_method() {
        let o = disparity_options(CyclopeanRequest {
            blend: Some(Blend::Soft),
            ..Default::default()
        });
        assert!(matches!(
            CyclopeanJob::new(o),
            Err(ArgError::GatherOptionOnly(crate::Field::Blend))
        ));
        // A lone --refine-steps picks the method, so its options are accepted.
        let o = disparity_options(CyclopeanRequest {
            refine_steps: Some(0),
            blend: Some(Blend::Soft),
            ..Default::default()
        });
        assert_eq!(CyclopeanJob::new(o).unwrap().plan.method(), CyclopeanMethod::Seed);
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
                backend: Backend::Vulkan,
                ..disparity_options(CyclopeanRequest {
                    method,
                    ..Default::default()
                })
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
        let job = CyclopeanJob::new(disparity_options(CyclopeanRequest::default())).unwrap();
        assert!(!job.plan.outputs().depth && job.plan.outputs().rgb);
        let o = disparity_options(CyclopeanRequest {
            outputs: Some(crate::output::OutputSet::parse("depth").unwrap()),
            ..Default::default()
        });
        assert!(matches!(CyclopeanJob::new(o), Err(ArgError::DepthOutputNotMetric)));
    }

    #[test]
    fn focal_and_baseline_come_together() {
        let o = disparity_options(CyclopeanRequest {
            focal: Some(700.0),
            ..Default::default()
        });
        assert!(matches!(
            CyclopeanJob::new(o),
            Err(ArgError::RigPartner(crate::Field::Focal, crate::Field::Baseline))
        ));
    }

    #[test]
    fn one_input_set_up_at_a_time() {
        let both = CyclopeanOptions {
            cameras: Some("c.json".into()),
            left_depth: Some("l.exr".into()),
            right_depth: Some("r.exr".into()),
            ..disparity_options(CyclopeanRequest::default())
        };
        assert!(matches!(CyclopeanJob::new(both), Err(ArgError::DisparityAndDepth)));
        // One eye's disparity is a set-up of its own (the other eye's is derived).
        for (left, right) in [(true, false), (false, true)] {
            let one = CyclopeanOptions {
                left_disparity: left.then(|| "ld.pgm".into()),
                right_disparity: right.then(|| "rd.pgm".into()),
                ..disparity_options(CyclopeanRequest::default())
            };
            assert!(CyclopeanJob::new(one).is_ok());
        }
    }
}
