//! `reproject`: one view of a stereo rig (left eye, centre view or right eye) to the other
//! eye(s), on a parallel rig from intrinsics or from full eye matrices (`--cameras`). The
//! options become a [`ReprojectJob`]; running it writes each target's files all-or-none.

mod request;

pub use request::{RenderedTarget, ReprojectRequest, RigPlan, SourceView};

use super::error::{InContext, OptionsContext};
use super::{ArgError, Backend, Event, GpuRequest, Host, JobError, SourceIntrinsics};
use crate::camera::stereo::Eye;
use crate::convention::{Conventions, DepthPlanes};
use crate::depth::DepthEncoding;
use crate::io::{self, DepthDecode};
use crate::output::FileFormats;
use crate::pass::Timing;
use crate::reproject::{Geometry, ReprojectParams, ReprojectSource};
use crate::stereo::camera_file::CameraFile;
use crate::stereo::{FrameDepth, MiddleCamera};
use crate::view::ViewOutput;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What the source depth file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SourceDepth {
    /// View-space Z in metres.
    #[default]
    #[serde(alias = "metric")]
    ViewZ,
    /// Window depth written with `--near/--far` under the conventions.
    Device,
    /// Disparity in pixels of a rectified pair.
    Disparity,
}

impl SourceDepth {
    /// The `--depth-kind` value naming it.
    pub fn option_value(self) -> &'static str {
        match self {
            SourceDepth::ViewZ => "view-z",
            SourceDepth::Device => "device",
            SourceDepth::Disparity => "disparity",
        }
    }
}

/// The target view(s).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Target {
    /// The left eye.
    Left,
    /// The right eye.
    #[default]
    Right,
    /// Both eyes (from the centre view).
    Both,
    /// The middle camera of a camera file (`--cameras`).
    Centre,
}

/// The reprojection method as chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MethodChoice {
    /// Fixed-point walk along the row.
    Shift,
    /// Every segment tested.
    #[default]
    ShiftScan,
    /// The cyclopean 3-D walk with one eye.
    Gather3d,
}

/// The reproject options as given: the files, the source camera and the request.
#[derive(Debug, Clone, Default)]
pub struct ReprojectOptions {
    /// Source colour.
    pub color: PathBuf,
    /// Source depth.
    pub depth: PathBuf,
    /// Raw units per unit of the depth file.
    pub depth_scale: Option<f64>,
    /// The `.npz` array to read.
    pub npz_key: Option<String>,
    /// `--intrinsics FILE`.
    pub intrinsics_file: Option<PathBuf>,
    /// `--fx --fy --cx --cy`.
    pub intrinsics: [Option<f64>; 4],
    /// Full eye matrices instead of a rig.
    pub cameras: Option<PathBuf>,
    /// Every setting the Python binding gives too (its outputs are the files' outputs).
    pub request: ReprojectRequest,
    /// The file formats ([`super::file_formats`]).
    pub files: FileFormats,
    /// Output folder.
    pub out_dir: PathBuf,
    /// Conventions of the GPU passes and of device depth.
    pub conventions: Conventions,
    /// The GPU to render on.
    pub gpu: GpuRequest,
    /// `--backend`: the API the passes run on.
    pub backend: Backend,
}

/// The views and their geometry, checked; the parts that need the source's size wait for it.
// One per job: the size difference between the variants costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
enum Views {
    /// A parallel rig from intrinsics.
    Rig(RigViews),
    /// Full eye matrices from a camera file: the source eye to the other eye or the middle
    /// camera (`to` None).
    Cameras { path: PathBuf, from: Eye, to: Option<Eye> },
}

/// [`Views::Rig`]: the checked rig, the source intrinsics and the conventions.
#[derive(Debug, Clone)]
struct RigViews {
    plan: RigPlan,
    intrinsics: SourceIntrinsics,
    conventions: Conventions,
}

/// A checked reprojection.
#[derive(Debug, Clone)]
pub struct ReprojectJob {
    color: PathBuf,
    depth: PathBuf,
    decode: DepthDecode,
    npz_key: Option<String>,
    depth_option: SourceDepth,
    views: Views,
    params: ReprojectParams,
    files: FileFormats,
    out_dir: PathBuf,
    gpu: GpuRequest,
    backend: Backend,
}

/// One target rendered.
#[derive(Debug)]
pub struct TargetReport {
    /// The target eye (None: the camera file's middle camera).
    pub to: Option<Eye>,
    /// Its valid fraction.
    pub coverage: f64,
    /// Render time.
    pub timing: Timing,
    /// Set-up and shader compile, milliseconds.
    pub setup_ms: f64,
}

/// What a reprojection wrote.
#[derive(Debug)]
pub struct ReprojectReport {
    /// The source view (None: the centre).
    pub from: Option<Eye>,
    /// The method's label.
    pub method: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Each target.
    pub targets: Vec<TargetReport>,
    /// The files written.
    pub written: Vec<PathBuf>,
}

/// The name of a view in file names and messages.
pub fn view_name(view: Option<Eye>) -> &'static str {
    match view {
        Some(Eye::Left) => "left",
        Some(Eye::Right) => "right",
        None => "centre",
    }
}

/// Device depth written with `near`/`far` (`what` names the depth in the error).
pub(crate) fn device_depth(near: Option<f64>, far: Option<f64>, what: &'static str) -> Result<DepthEncoding, ArgError> {
    let (Some(near), Some(far)) = (near, far) else {
        return Err(ArgError::DevicePlanesMissing(what));
    };
    let kind = DepthEncoding::Device {
        planes: DepthPlanes { near, far },
    };
    kind.validate()
        .for_options(crate::msg![crate::Field::Near, "/", crate::Field::Far])?;
    Ok(kind)
}

impl ReprojectJob {
    /// Checks the options against each other and the library's rules.
    pub fn new(mut o: ReprojectOptions) -> Result<Self, ArgError> {
        o.gpu.check_backend(o.backend)?;
        super::check_npz_key(o.npz_key.as_deref(), &[&o.depth])?;
        o.files.outputs = o.request.outputs();
        if o.cameras.is_some() {
            // Full matrices leave one method; a different one given is refused below.
            o.request.method.get_or_insert(MethodChoice::Gather3d);
        }
        // The mask is always rendered: the coverage reported is measured on it.
        let params = o.request.params()?;
        let views = match &o.cameras {
            Some(path) => camera_file_views(&o, path)?,
            None => rig_views(&o)?,
        };
        super::cyclopean::check_scale(crate::Field::DepthScale, o.depth_scale)?;
        let eyes = match &views {
            Views::Rig(rig) => rig.plan.targets().iter().map(|&e| Some(e)).collect(),
            Views::Cameras { to, .. } => vec![*to],
        };
        let writes = |name: &str| {
            eyes.iter()
                .any(|&e| crate::output::ViewNames::tagged(view_name(e)).may_write(name))
        };
        let mut inputs = vec![
            (crate::Field::Color.into(), o.color.as_path()),
            (crate::Field::Depth.into(), o.depth.as_path()),
        ];
        inputs.extend(
            o.intrinsics_file
                .as_deref()
                .map(|p| (crate::Field::Intrinsics.into(), p)),
        );
        inputs.extend(o.cameras.as_deref().map(|p| (crate::Field::Cameras.into(), p)));
        crate::output::check_out_dir(&o.out_dir, writes, &replaced(), &inputs).map_err(ArgError::Invalid)?;
        Ok(ReprojectJob {
            decode: DepthDecode {
                scale: o.depth_scale,
                ..Default::default()
            },
            color: o.color,
            depth: o.depth,
            npz_key: o.npz_key,
            depth_option: o.request.depth_kind,
            views,
            params,
            files: o.files,
            out_dir: o.out_dir,
            gpu: o.gpu,
            backend: o.backend,
        })
    }

    /// `--out-dir`.
    pub fn out_dir(&self) -> &Path {
        &self.out_dir
    }

    /// Reads the source, renders every target and writes the files all-or-none.
    pub fn run(&self, host: &dyn Host) -> Result<ReprojectReport, JobError> {
        // Read and check the source and place the targets before the folder or the GPU is
        // touched.
        let (src, from, targets) = match &self.views {
            Views::Rig(rig) => {
                let src = self.rig_source(host, rig)?;
                let targets = rig
                    .plan
                    .geometries(rig.intrinsics.k, src.color.width, src.color.height)?;
                (src, rig.plan.from(), targets)
            }
            Views::Cameras { path, from, to } => {
                let (src, targets) = self.camera_file_setup(host, path, *from, *to)?;
                (src, Some(*from), targets)
            }
        };
        let out_dir = io::OutDir::prepare(&self.out_dir)?;
        let gpu = host.open_device(&self.gpu, self.backend)?;
        let results = request::render_targets(&gpu, &src, &targets, self.params)?;
        let (width, height) = (src.color.width, src.color.height);
        // Every target's files through the output layer, all or none.
        let mut set = out_dir.file_set()?.replacing(replaced());
        let mut reports = Vec::with_capacity(results.len());
        for RenderedTarget {
            to,
            out,
            timing,
            setup_ms,
        } in results
        {
            let coverage = out.coverage();
            let view = ViewOutput {
                width,
                height,
                color: out.color,
                depth: out.depth,
                mask: Some(io::Mask::new(width, height, out.mask)?),
                timing: Some(timing),
                exact: None,
            };
            crate::output::write_view(
                &mut set,
                &crate::output::ViewNames::tagged(view_name(to)),
                &view,
                &self.files,
            )?;
            reports.push(TargetReport {
                to,
                coverage,
                timing,
                setup_ms,
            });
        }
        let written = set.commit()?;
        Ok(ReprojectReport {
            from,
            method: self.params.method.label(),
            width,
            height,
            targets: reports,
            written,
        })
    }

    /// The source colour and depth, checked to agree in size and to hold valid depth as
    /// `what` says.
    fn load_source(
        &self,
        host: &dyn Host,
        depth_kind: DepthEncoding,
        conv: Conventions,
        what: &str,
    ) -> Result<ReprojectSource, JobError> {
        // Sizes and the pixel budget from the headers before either file is decoded.
        io::check_rgbd_sizes(&self.color, &self.depth)?;
        let src = ReprojectSource {
            color: io::load_rgb(&self.color)?,
            depth: io::load_depth_with_key(&self.depth, self.npz_key.as_deref(), &self.decode)?,
            depth_kind,
            conv,
        };
        src.validate()
            .within(|| format!("{} and {}", self.color.display(), self.depth.display()))?;
        host.event(Event::InputDepth {
            path: &self.depth,
            summary: &src.depth_kind.summary(&src.conv, &src.depth),
            // reproject decodes device depth under its own options (cyclopean and compare name
            // theirs): the hint names them, runnable as written.
            hint: &if matches!(src.depth_kind, DepthEncoding::Device { .. }) {
                crate::msg![
                    format!("read as {what}: set `"),
                    crate::Field::Ndc,
                    "`, `",
                    crate::Field::ReversedZ,
                    "` and `",
                    crate::Field::Near,
                    "/",
                    crate::Field::Far,
                    "` as the renderer wrote it"
                ]
            } else {
                crate::msg![format!("read as {what}")]
            },
        });
        src.require_valid_depth(what)
            .map_err(|e| crate::Error::decode(&self.depth, e.to_string()))?;
        Ok(src)
    }

    /// The source on the parallel rig, its size checked against an intrinsics file.
    fn rig_source(&self, host: &dyn Host, rig: &RigViews) -> Result<ReprojectSource, JobError> {
        let what = format!(
            "--depth-kind {} (check --depth-kind, --depth-scale, --near/--far, conventions)",
            self.depth_option.option_value()
        );
        let src = self.load_source(host, rig.plan.depth_kind(), rig.conventions, &what)?;
        rig.intrinsics.check_size(src.color.width, src.color.height)?;
        Ok(src)
    }

    /// The source eye and the target (the other eye, or the middle camera when `to` is None)
    /// from full GL matrices (3-D gather only).
    #[allow(clippy::type_complexity)]
    fn camera_file_setup(
        &self,
        host: &dyn Host,
        path: &Path,
        from: Eye,
        to: Option<Eye>,
    ) -> Result<(ReprojectSource, Vec<(Option<Eye>, Geometry)>), JobError> {
        let file = CameraFile::load(path)?;
        let source = match from {
            Eye::Left => &file.left,
            Eye::Right => &file.right,
        };
        let conv = file.conventions;
        let depth_kind = match file.depth_kind {
            FrameDepth::ViewZ => DepthEncoding::ViewZ,
            FrameDepth::Device => DepthEncoding::Device {
                planes: DepthPlanes::from_gl_projection(&source.proj, &conv)
                    .within(|| format!("{}: {} projection", path.display(), view_name(Some(from))))?,
            },
        };
        let what = format!(
            "{:?} depth under {} (from {})",
            file.depth_kind,
            conv.label(),
            path.display()
        );
        let src = self.load_source(host, depth_kind, conv, &what)?;
        // The target is rendered at the source's size: its camera must be for that size.
        let name = self.color.display().to_string();
        source.check_size(&name, src.color.width, src.color.height)?;
        let target = match to {
            Some(eye) => {
                let cam = if eye == Eye::Left { &file.left } else { &file.right };
                cam.check_size(&name, src.color.width, src.color.height)?;
                MiddleCamera {
                    view: cam.view,
                    proj: cam.proj,
                    width: src.color.width,
                    height: src.color.height,
                }
            }
            None => {
                let (middle, _) = file.middle_and_fixation().within(|| path.display().to_string())?;
                if (middle.width, middle.height) != (src.color.width, src.color.height) {
                    return Err(crate::Error::SizeMismatch {
                        message: format!(
                            "{}: the middle camera is {}x{} but {name} is {}x{}",
                            path.display(),
                            middle.width,
                            middle.height,
                            src.color.width,
                            src.color.height
                        ),
                    }
                    .into());
                }
                middle
            }
        };
        let geometry = Geometry::Matrices {
            source_view: source.view,
            source_proj: source.proj,
            target,
        };
        Ok((src, vec![(to, geometry)]))
    }
}

/// The rig: the source intrinsics, then the request's checks ([`ReprojectRequest::rig`]).
fn rig_views(o: &ReprojectOptions) -> Result<Views, ArgError> {
    if o.intrinsics_file.is_none() && o.intrinsics.iter().all(Option::is_none) {
        return Err(ArgError::MissingIntrinsicsOrCameras);
    }
    let intrinsics = SourceIntrinsics::resolve(o.intrinsics_file.as_deref(), o.intrinsics)?;
    Ok(Views::Rig(RigViews {
        plan: o.request.rig(intrinsics.k.fx)?,
        intrinsics,
        conventions: o.conventions,
    }))
}

/// The camera file's checks: an eye to the other, 3-D gather, the file's own conventions.
fn camera_file_views(o: &ReprojectOptions, path: &Path) -> Result<Views, ArgError> {
    let r = &o.request;
    let Some(from) = r.from.eye() else {
        return Err(ArgError::CameraFileFromCentre);
    };
    let to = match r.to {
        Target::Left => Some(Eye::Left),
        Target::Right => Some(Eye::Right),
        Target::Centre => None,
        Target::Both => return Err(ArgError::BothFromEye),
    };
    if to == Some(from) {
        return Err(ArgError::TargetIsSource);
    }
    if r.method != Some(MethodChoice::Gather3d) {
        return Err(ArgError::CameraFileNeedsGather);
    }
    // The file carries both; a flag that differs from its default would be silently overridden.
    if r.depth_kind != SourceDepth::ViewZ || o.conventions != Conventions::default() {
        return Err(ArgError::CameraFileOverridden);
    }
    Ok(Views::Cameras {
        path: path.to_path_buf(),
        from,
        to,
    })
}

/// What a run's set replaces: the files the previous run's record lists (the one deletion rule,
/// [`io::Replaces`]).
fn replaced() -> io::Replaces {
    io::Replaces::recorded("reproject")
}

#[cfg(test)]
mod tests {
    use super::{
        ArgError, MethodChoice, ReprojectJob, ReprojectOptions, ReprojectRequest, SourceDepth, SourceView, Target,
    };

    fn rig_options() -> ReprojectOptions {
        ReprojectOptions {
            color: "c.png".into(),
            depth: "d.exr".into(),
            intrinsics: [Some(500.0), Some(500.0), Some(320.0), Some(240.0)],
            request: ReprojectRequest {
                baseline: Some(0.1),
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// The rig options with the request changed by `change`.
    fn with(change: impl FnOnce(&mut ReprojectRequest)) -> ReprojectOptions {
        let mut o = rig_options();
        change(&mut o.request);
        o
    }

    #[test]
    fn a_rig_needs_intrinsics_a_baseline_or_separation_and_another_view() {
        assert!(ReprojectJob::new(rig_options()).is_ok());
        let no_k = ReprojectOptions {
            intrinsics: [None; 4],
            ..rig_options()
        };
        assert!(matches!(
            ReprojectJob::new(no_k),
            Err(ArgError::MissingIntrinsicsOrCameras)
        ));
        let no_rig = with(|r| r.baseline = None);
        assert!(matches!(ReprojectJob::new(no_rig), Err(ArgError::NoRig)));
        let itself = with(|r| r.to = Target::Left);
        assert!(matches!(ReprojectJob::new(itself), Err(ArgError::TargetIsSource)));
        let both = with(|r| r.to = Target::Both);
        assert!(matches!(ReprojectJob::new(both), Err(ArgError::BothFromEye)));
    }

    #[test]
    fn planes_go_with_device_depth_only() {
        let planes = with(|r| (r.near, r.far) = (Some(0.1), Some(10.0)));
        assert!(matches!(ReprojectJob::new(planes), Err(ArgError::PlanesWithoutDevice)));
        let device = with(|r| r.depth_kind = SourceDepth::Device);
        assert!(matches!(
            ReprojectJob::new(device),
            Err(ArgError::DevicePlanesMissing(_))
        ));
        let reversed = with(|r| (r.depth_kind, r.near, r.far) = (SourceDepth::Device, Some(10.0), Some(1.0)));
        let e = ReprojectJob::new(reversed).unwrap_err();
        assert!(e.to_string().starts_with("--near/--far"), "{e}");
    }

    #[test]
    fn a_camera_file_takes_an_eye_to_the_other_by_3d_gather_under_its_own_conventions() {
        let mut cams = with(|r| r.baseline = None);
        cams.cameras = Some("cameras.json".into());
        cams.intrinsics = [None; 4];
        // gather3d is the default with a camera file, and may be named.
        assert!(ReprojectJob::new(cams.clone()).is_ok());
        let mut named = cams.clone();
        named.request.method = Some(MethodChoice::Gather3d);
        assert!(ReprojectJob::new(named).is_ok());
        for to in [Target::Left, Target::Centre] {
            let mut other = cams.clone();
            other.request.to = to;
            let r = ReprojectJob::new(other);
            assert_eq!(r.is_ok(), to == Target::Centre, "--to {to:?} from the left eye");
        }
        let mut shift = cams.clone();
        shift.request.method = Some(MethodChoice::ShiftScan);
        assert!(matches!(ReprojectJob::new(shift), Err(ArgError::CameraFileNeedsGather)));
        let mut centre = cams.clone();
        centre.request.from = SourceView::Centre;
        assert!(matches!(ReprojectJob::new(centre), Err(ArgError::CameraFileFromCentre)));
        let mut conv = cams;
        conv.conventions.reversed_z = true;
        assert!(matches!(ReprojectJob::new(conv), Err(ArgError::CameraFileOverridden)));
    }
}
