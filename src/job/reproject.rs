//! `reproject`: one view of a stereo rig (left eye, centre view or right eye) to the other
//! eye(s), on a parallel rig from intrinsics or from full eye matrices (`--cameras`). The
//! options become a [`ReprojectJob`]; running it writes each target's files all-or-none.

use super::error::{InContext, OptionsContext};
use super::{ArgError, Backend, Event, GpuRequest, Host, JobError, SourceIntrinsics};
use crate::camera::stereo::{Eye, StereoParams};
use crate::camera::PinholeCamera;
use crate::convention::{Conventions, DepthPlanes};
use crate::cyclopean::camera_file::CameraFile;
use crate::cyclopean::{FrameDepth, MiddleCamera};
use crate::depth::DepthEncoding;
use crate::gpu::Timing;
use crate::io::FileFormats;
use crate::io::{self, DepthDecode, DepthSummary};
use crate::reproject::render::Reprojector;
use crate::reproject::{
    Geometry, Method, ReprojectOutput, ReprojectOutputs, ReprojectParams, ReprojectSource, ShiftModel,
};
use crate::view::ViewOutput;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What the source depth file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SourceDepth {
    /// View-space Z in metres.
    #[default]
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Target {
    /// The left eye.
    Left,
    /// The right eye.
    #[default]
    Right,
    /// Both eyes (from the centre view).
    Both,
}

/// The reprojection method as chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MethodChoice {
    /// Fixed-point walk along the row.
    Shift,
    /// Every segment tested.
    #[default]
    ShiftScan,
    /// The cyclopean 3-D walk with one eye.
    Gather3d,
}

/// The reproject options as given.
#[derive(Debug, Clone, Default)]
pub struct ReprojectOptions {
    /// Source colour.
    pub color: PathBuf,
    /// Source depth.
    pub depth: PathBuf,
    /// What the depth holds.
    pub depth_kind: SourceDepth,
    /// Raw units per unit of the depth file.
    pub depth_scale: Option<f64>,
    /// The `.npz` array to read.
    pub npz_key: Option<String>,
    /// Near plane of device depth.
    pub near: Option<f64>,
    /// Far plane of device depth.
    pub far: Option<f64>,
    /// `--intrinsics FILE`.
    pub intrinsics_file: Option<PathBuf>,
    /// `--fx --fy --cx --cy`.
    pub intrinsics: [Option<f64>; 4],
    /// Full eye matrices instead of a rig.
    pub cameras: Option<PathBuf>,
    /// Rectified rig's baseline, metres.
    pub baseline: Option<f64>,
    /// Rectified rig's focal length, pixels (default fx).
    pub focal: Option<f64>,
    /// cx_right - cx_left, pixels.
    pub doffs: f64,
    /// Game-engine rig's separation.
    pub separation: Option<f64>,
    /// Game-engine rig's convergence distance.
    pub convergence: Option<f64>,
    /// The source view: an eye, or None for the centre.
    pub from: Option<Eye>,
    /// The target view(s).
    pub to: Target,
    /// The method.
    pub method: MethodChoice,
    /// Steps of the walk / gather.
    pub steps: u32,
    /// Segment break threshold.
    pub tau_rel: f64,
    /// Outputs and formats ([`super::file_formats`]).
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
    /// Full eye matrices from a camera file: the source eye to the other.
    Cameras { path: PathBuf, from: Eye, to: Eye },
}

/// [`Views::Rig`]: the source eye, its intrinsics and depth, the target eyes and their shifts.
#[derive(Debug, Clone)]
struct RigViews {
    from: Option<Eye>,
    intrinsics: SourceIntrinsics,
    targets: Vec<Eye>,
    depth_kind: DepthEncoding,
    /// Game-engine stereo, or None for the rectified rig below.
    seed: Option<StereoParams>,
    /// The rectified rig's shift per target (when no `seed`).
    rectified: Vec<ShiftModel>,
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
    /// The target eye.
    pub to: Eye,
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
    kind.validate().for_options("--near/--far")?;
    Ok(kind)
}

impl ReprojectJob {
    /// Checks the options against each other and the library's rules.
    pub fn new(o: ReprojectOptions) -> Result<Self, ArgError> {
        super::check_npz_key(o.npz_key.as_deref(), &[&o.depth])?;
        let method = match o.method {
            MethodChoice::Shift => Method::Shift { steps: o.steps },
            MethodChoice::ShiftScan => Method::ShiftScan,
            MethodChoice::Gather3d => Method::Gather3d { steps: o.steps },
        };
        // The mask is always rendered: the coverage reported is measured on it.
        let params = ReprojectParams {
            method,
            outputs: ReprojectOutputs {
                color: o.files.outputs.rgb,
                depth: o.files.outputs.depth,
            },
            tau_rel: o.tau_rel,
        };
        params.validate().for_options("--steps/--tau-rel")?;
        let views = match &o.cameras {
            Some(path) => camera_file_views(&o, path)?,
            None => rig_views(&o)?,
        };
        super::cyclopean::check_scale("--depth-scale", o.depth_scale)?;
        Ok(ReprojectJob {
            decode: DepthDecode {
                scale: o.depth_scale,
                ..Default::default()
            },
            color: o.color,
            depth: o.depth,
            npz_key: o.npz_key,
            depth_option: o.depth_kind,
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
        let (src, from, targets) = match &self.views {
            Views::Rig(rig) => self.rig_setup(host, rig)?,
            Views::Cameras { path, from, to } => self.camera_file_setup(host, path, *from, *to)?,
        };
        let (width, height) = (src.color.width, src.color.height);
        let out_dir = io::OutDir::prepare(&self.out_dir)?;

        let gpu = host.open_device(&self.gpu, self.backend)?;
        let mut results: Vec<(Eye, ReprojectOutput, Timing, f64)> = Vec::new();
        for (to, geometry) in &targets {
            let t0 = Instant::now();
            let mut r = Reprojector::new(&gpu, &src, geometry, self.params)?;
            let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
            let (out, timing) = r.render()?;
            results.push((*to, out, timing, setup_ms));
        }
        // Every target's files through the output layer, all or none.
        let mut set = out_dir.file_set()?;
        let mut reports = Vec::with_capacity(results.len());
        for (to, out, timing, setup_ms) in results {
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
            io::write_view(
                &mut set,
                &io::ViewNames::tagged(view_name(Some(to))),
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
            summary: &DepthSummary::of(&src.depth_kind.view_z_map(&src.conv, &src.depth)),
            hint: &format!("read as {what}"),
        });
        if src.inverse_depth_range().is_none() {
            return Err(crate::Error::decode(&self.depth, format!("no pixel holds valid depth as {what}")).into());
        }
        Ok(src)
    }

    /// The source and its targets on the parallel rig.
    #[allow(clippy::type_complexity)]
    fn rig_setup(
        &self,
        host: &dyn Host,
        rig: &RigViews,
    ) -> Result<(ReprojectSource, Option<Eye>, Vec<(Eye, Geometry)>), JobError> {
        let RigViews {
            from,
            intrinsics,
            targets,
            depth_kind,
            seed,
            rectified,
            conventions,
        } = rig;
        let what = format!(
            "--depth-kind {} (check --depth-kind, --depth-scale, --near/--far, conventions)",
            self.depth_option.option_value()
        );
        let src = self.load_source(host, *depth_kind, *conventions, &what)?;
        intrinsics.check_size(src.color.width, src.color.height)?;
        let camera = PinholeCamera {
            k: intrinsics.k,
            width: src.color.width,
            height: src.color.height,
        };
        camera.validate("source intrinsics")?;
        let from = *from;
        let mut geometries = Vec::new();
        for (i, &to) in targets.iter().enumerate() {
            let shift = match seed {
                Some(p) => ShiftModel::seed(p, camera.width, from, Some(to)),
                None => rectified[i],
            };
            shift.validate()?;
            geometries.push((to, Geometry::Rig { camera, shift }));
        }
        Ok((src, from, geometries))
    }

    /// The source eye and the other eye from full GL matrices (3-D gather only).
    #[allow(clippy::type_complexity)]
    fn camera_file_setup(
        &self,
        host: &dyn Host,
        path: &Path,
        from: Eye,
        to: Eye,
    ) -> Result<(ReprojectSource, Option<Eye>, Vec<(Eye, Geometry)>), JobError> {
        let file = CameraFile::load(path)?;
        let (source, target) = match from {
            Eye::Left => (&file.left, &file.right),
            Eye::Right => (&file.right, &file.left),
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
        // The target is rendered at the source's size: both cameras must be for that size.
        for cam in [source, target] {
            cam.check_size(&self.color.display().to_string(), src.color.width, src.color.height)?;
        }
        let geometry = Geometry::Matrices {
            source_view: source.view,
            source_proj: source.proj,
            target: MiddleCamera {
                view: target.view,
                proj: target.proj,
                width: src.color.width,
                height: src.color.height,
            },
        };
        Ok((src, Some(from), vec![(to, geometry)]))
    }
}

/// The rig's checks, in the order earlier releases made them.
fn rig_views(o: &ReprojectOptions) -> Result<Views, ArgError> {
    if o.intrinsics_file.is_none() && o.intrinsics.iter().all(Option::is_none) {
        return Err(ArgError::MissingIntrinsicsOrCameras);
    }
    let intrinsics = SourceIntrinsics::resolve(o.intrinsics_file.as_deref(), o.intrinsics)?;
    let targets = match (o.from, o.to) {
        (None, Target::Both) => vec![Eye::Left, Eye::Right],
        (_, Target::Both) => return Err(ArgError::BothFromEye),
        (Some(Eye::Left), Target::Left) | (Some(Eye::Right), Target::Right) => return Err(ArgError::TargetIsSource),
        (_, Target::Left) => vec![Eye::Left],
        (_, Target::Right) => vec![Eye::Right],
    };
    let focal = o.focal.unwrap_or(intrinsics.k.fx);
    let depth_kind = match o.depth_kind {
        SourceDepth::ViewZ => DepthEncoding::ViewZ,
        SourceDepth::Device => device_depth(o.near, o.far, "the depth buffer")?,
        SourceDepth::Disparity => {
            let Some(baseline) = o.baseline else {
                return Err(ArgError::DisparityWithoutBaseline);
            };
            let kind = DepthEncoding::Disparity {
                focal_px: focal,
                baseline,
                doffs: o.doffs,
            };
            kind.validate()
                .for_options("--depth-kind disparity: --focal/--baseline/--doffs")?;
            kind
        }
    };
    if o.depth_kind != SourceDepth::Device && (o.near.is_some() || o.far.is_some()) {
        return Err(ArgError::PlanesWithoutDevice);
    }
    let seed = match (o.separation, o.convergence) {
        (Some(s), Some(c)) => Some(StereoParams::new(s, c).for_options("--separation/--convergence")?),
        _ => None,
    };
    // --baseline places a rectified rig; with a game-engine rig it would be ignored, unless it
    // makes disparity depth metric.
    if seed.is_some() && o.baseline.is_some() && o.depth_kind != SourceDepth::Disparity {
        return Err(ArgError::RigConflict);
    }
    let rectified = match (seed, o.baseline) {
        (Some(_), _) => Vec::new(),
        (None, Some(b)) => targets
            .iter()
            .map(|&to| {
                ShiftModel::rectified(focal, b, o.doffs, o.from, Some(to)).for_options("--focal/--baseline/--doffs")
            })
            .collect::<Result<_, _>>()?,
        (None, None) => return Err(ArgError::NoRig),
    };
    Ok(Views::Rig(RigViews {
        from: o.from,
        intrinsics,
        targets,
        depth_kind,
        seed,
        rectified,
        conventions: o.conventions,
    }))
}

/// The camera file's checks: an eye to the other, 3-D gather, the file's own conventions.
fn camera_file_views(o: &ReprojectOptions, path: &Path) -> Result<Views, ArgError> {
    let (from, to) = match o.from {
        Some(Eye::Left) => (Eye::Left, Eye::Right),
        Some(Eye::Right) => (Eye::Right, Eye::Left),
        None => return Err(ArgError::CameraFileFromCentre),
    };
    if !matches!((o.to, to), (Target::Left, Eye::Left) | (Target::Right, Eye::Right)) {
        return Err(ArgError::CameraFileTarget(view_name(Some(to))));
    }
    if o.method != MethodChoice::Gather3d {
        return Err(ArgError::CameraFileNeedsGather);
    }
    // The file carries both; a flag that differs from its default would be silently overridden.
    if o.depth_kind != SourceDepth::ViewZ || o.conventions != Conventions::default() {
        return Err(ArgError::CameraFileOverridden);
    }
    Ok(Views::Cameras {
        path: path.to_path_buf(),
        from,
        to,
    })
}

#[cfg(test)]
mod tests {
    use super::{ArgError, Eye, MethodChoice, ReprojectJob, ReprojectOptions, SourceDepth, Target};

    fn rig_options() -> ReprojectOptions {
        ReprojectOptions {
            color: "c.png".into(),
            depth: "d.exr".into(),
            intrinsics: [Some(500.0), Some(500.0), Some(320.0), Some(240.0)],
            baseline: Some(0.1),
            from: Some(Eye::Left),
            steps: 3,
            tau_rel: 0.05,
            ..Default::default()
        }
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
        let no_rig = ReprojectOptions {
            baseline: None,
            ..rig_options()
        };
        assert!(matches!(ReprojectJob::new(no_rig), Err(ArgError::NoRig)));
        let itself = ReprojectOptions {
            to: Target::Left,
            ..rig_options()
        };
        assert!(matches!(ReprojectJob::new(itself), Err(ArgError::TargetIsSource)));
        let both = ReprojectOptions {
            to: Target::Both,
            ..rig_options()
        };
        assert!(matches!(ReprojectJob::new(both), Err(ArgError::BothFromEye)));
    }

    #[test]
    fn planes_go_with_device_depth_only() {
        let planes = ReprojectOptions {
            near: Some(0.1),
            far: Some(10.0),
            ..rig_options()
        };
        assert!(matches!(ReprojectJob::new(planes), Err(ArgError::PlanesWithoutDevice)));
        let device = ReprojectOptions {
            depth_kind: SourceDepth::Device,
            ..rig_options()
        };
        assert!(matches!(
            ReprojectJob::new(device),
            Err(ArgError::DevicePlanesMissing(_))
        ));
        let reversed = ReprojectOptions {
            depth_kind: SourceDepth::Device,
            near: Some(10.0),
            far: Some(1.0),
            ..rig_options()
        };
        let e = ReprojectJob::new(reversed).unwrap_err();
        assert!(e.to_string().starts_with("--near/--far"), "{e}");
    }

    #[test]
    fn a_camera_file_takes_an_eye_to_the_other_by_3d_gather_under_its_own_conventions() {
        let cams = ReprojectOptions {
            cameras: Some("cameras.json".into()),
            intrinsics: [None; 4],
            baseline: None,
            method: MethodChoice::Gather3d,
            ..rig_options()
        };
        assert!(ReprojectJob::new(cams.clone()).is_ok());
        let shift = ReprojectOptions {
            method: MethodChoice::ShiftScan,
            ..cams.clone()
        };
        assert!(matches!(ReprojectJob::new(shift), Err(ArgError::CameraFileNeedsGather)));
        let centre = ReprojectOptions {
            from: None,
            ..cams.clone()
        };
        assert!(matches!(ReprojectJob::new(centre), Err(ArgError::CameraFileFromCentre)));
        let mut conv = cams;
        conv.conventions.reversed_z = true;
        assert!(matches!(ReprojectJob::new(conv), Err(ArgError::CameraFileOverridden)));
    }
}
