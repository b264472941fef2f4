//! `viewsynth reproject` options and their conversion into a checked library job.

use crate::options::{BackendArg, ConventionArgs, FileOutputArgs, GpuArgs, IntrinsicsArgs};
use crate::options::{GPU, INPUTS, INTRINSICS, METHOD, OUTPUTS, TARGETS};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use viewsynth::job::reproject::{
    MethodChoice, ReprojectJob, ReprojectOptions, ReprojectRequest, SourceDepth, SourceView, Target,
};
use viewsynth::job::{file_formats, finite_or_inf, finite_value, ArgError};

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub(crate) enum ReprojectDepthArg {
    /// View-space Z (distance along the optical axis) in metres; <= 0, NaN, inf = no depth.
    #[value(alias = "metric")]
    ViewZ,
    /// Window depth in [0, 1] from a depth buffer, written with --near/--far under --ndc,
    /// --reversed-z; the far value is background.
    Device,
    /// Disparity in pixels of a rectified pair (Middlebury): Z = baseline * focal / (d + doffs);
    /// d <= 0 = unknown.
    Disparity,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub(crate) enum FromArg {
    Left,
    #[value(alias = "center")]
    Centre,
    Right,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub(crate) enum ToArg {
    Left,
    Right,
    /// Both eyes (from the centre view only).
    Both,
    /// The middle camera of --cameras (writes centre_*).
    #[value(alias = "middle")]
    Centre,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum ReprojectMethodArg {
    /// Fixed-point walk along the row (--steps) from two starts, verified by segment coverage.
    Shift,
    /// Exact: every segment the frame's depth range allows is tested, the nearest wins.
    ShiftScan,
    /// The cyclopean 3-D walk with one eye (--steps), from two starts.
    Gather3d,
}

/// The example under `viewsynth reproject --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  # the TUM frame as seen by a right eye 64 mm to the right
  viewsynth reproject --color ../shared/data/rgbd_open3d_testdata/TUM_color.png \\
      --depth ../shared/data/rgbd_open3d_testdata/TUM_depth.png --depth-scale 5000 \\
      --fx 525 --fy 525 --cx 319.5 --cy 239.5 --baseline 0.064 --out-dir out/tum_right";

#[derive(Args)]
pub(crate) struct ReprojectArgs {
    /// Source colour (PNG, JPEG, PPM, EXR), rows top-down.
    #[arg(help_heading = INPUTS, long, visible_alias = "rgb")]
    color: PathBuf,
    /// Source depth (EXR, NPY, NPZ, 16-bit PNG/PGM with --depth-scale, PFM), holding --depth-kind.
    #[arg(help_heading = INPUTS, long)]
    depth: PathBuf,
    /// What --depth holds: view-z (alias metric, metres), device (window depth, with --near/--far,
    /// --ndc and --reversed-z) or disparity (pixels, with --baseline and --focal/--doffs).
    #[arg(help_heading = INPUTS, long, value_enum, default_value = "view-z")]
    depth_kind: ReprojectDepthArg,
    /// Raw units per unit of the depth file for integer files (1000 for mm, 4 for Middlebury 2003
    /// disparity PGMs); divides float depth too when given.
    #[arg(help_heading = INPUTS, long, value_parser = finite_value)]
    depth_scale: Option<f64>,
    /// Array of an .npz depth file to read (default: the only array, else the first
    /// floating-point one).
    #[arg(help_heading = INPUTS, long, value_name = "NAME")]
    npz_key: Option<String>,
    /// Near plane (metres) the device depth was written with (--depth-kind device).
    #[arg(help_heading = INPUTS, long, value_parser = finite_value)]
    near: Option<f64>,
    /// Far plane (metres; may be inf) the device depth was written with (--depth-kind device).
    #[arg(help_heading = INPUTS, long, value_parser = finite_or_inf)]
    far: Option<f64>,
    /// Full eye matrices instead of a rig: a cameras.json as `viewsynth scene` writes it (left and
    /// right GL view and projection, conventions, depth kind: those of the file apply).
    ///
    /// The source is --from's eye; the target (--to) the other eye or the file's middle camera
    /// (--to centre, alias middle). Renders by the 3-D gather (--method gather3d, the default
    /// here; a shift method is refused).
    #[arg(help_heading = INPUTS, long, conflicts_with_all = ["intrinsics", "fx", "fy", "cx", "cy", "baseline", "separation", "near", "far", "focal"])]
    cameras: Option<PathBuf>,
    /// Source intrinsics (with a rig).
    #[command(flatten)]
    intrinsics: IntrinsicsArgs,
    /// Focal length (pixels) of the rectified rig and of disparity (default: --fx).
    #[arg(help_heading = INTRINSICS, long, value_parser = finite_value)]
    focal: Option<f64>,
    /// cx_right - cx_left in pixels (Middlebury's doffs) of the rectified rig and of disparity.
    #[arg(help_heading = INTRINSICS, long, default_value_t = ReprojectRequest::default().doffs, value_parser = finite_value)]
    doffs: f64,
    /// Rectified rig: distance between the eyes in metres (x_right = x_left + doffs - f B / Z).
    ///
    /// Also the baseline of --depth-kind disparity.
    #[arg(help_heading = TARGETS, long, value_parser = finite_value)]
    baseline: Option<f64>,
    /// A game-engine stereo rig instead of --baseline: separation = interaxial / screen width (texture
    /// units; the eyes move +-S/2 (1 - c/Z) in texture x), with --convergence.
    #[arg(help_heading = TARGETS, long, requires = "convergence", value_parser = finite_value)]
    separation: Option<f64>,
    /// Zero-parallax distance c in metres (with --separation).
    #[arg(help_heading = TARGETS, long, requires = "separation", value_parser = finite_value)]
    convergence: Option<f64>,
    /// The source view.
    #[arg(help_heading = TARGETS, long, value_enum, default_value = "left")]
    from: FromArg,
    /// The target view(s): an eye, both eyes (from centre), or centre (middle): --cameras' middle
    /// camera.
    #[arg(help_heading = TARGETS, long, value_enum, default_value = "right")]
    to: ToArg,
    /// How each target pixel finds its source: shift-scan (exact; the default on a rig), shift
    /// (fixed-point walk, --steps) or gather3d (the cyclopean 3-D walk, --steps; the default and
    /// only method with --cameras).
    #[arg(help_heading = METHOD, long, value_enum)]
    method: Option<ReprojectMethodArg>,
    /// Steps of the shift walk / 3-D gather (1..=16).
    #[arg(help_heading = METHOD, long, default_value_t = ReprojectRequest::default().steps, value_parser = clap::value_parser!(u32).range(1..=16))]
    steps: u32,
    /// A row segment breaks (an unseen surface) where |Z_a - Z_b| > tau_rel * min(Z_a, Z_b).
    #[arg(help_heading = METHOD, long, default_value_t = ReprojectRequest::default().tau_rel, value_parser = finite_value)]
    tau_rel: f64,
    #[command(flatten)]
    files: FileOutputArgs,
    /// Output folder (created if missing): per target (left, right), <target>_rgb.png
    /// (<target>_rgb.jpg, <target>_rgb.exr with --rgb-format), <target>_depth.exr,
    /// <target>_depth.npy, <target>_depth.png (those in --depth-format),
    /// <target>_depth_preview.png (--depth-preview), <target>_mask.png (those in --outputs).
    #[arg(help_heading = OUTPUTS, long)]
    out_dir: PathBuf,
    #[command(flatten)]
    conv: ConventionArgs,
    #[command(flatten)]
    gpu: GpuArgs,
    /// Rendering API: gl, or vulkan (the same shaders as SPIR-V on a Vulkan 1.3 device;
    /// --device an index of `viewsynth info --backend vulkan`).
    #[arg(help_heading = GPU, long, value_enum, default_value = "gl")]
    backend: BackendArg,
}

impl ReprojectArgs {
    /// The settings the Python binding gives too, as the library's request.
    pub(crate) fn request(&self) -> Result<ReprojectRequest, ArgError> {
        let outputs = self.files.outputs_given()?;
        Ok(ReprojectRequest {
            depth_kind: match self.depth_kind {
                ReprojectDepthArg::ViewZ => SourceDepth::ViewZ,
                ReprojectDepthArg::Device => SourceDepth::Device,
                ReprojectDepthArg::Disparity => SourceDepth::Disparity,
            },
            near: self.near,
            far: self.far,
            baseline: self.baseline,
            focal: self.focal,
            doffs: self.doffs,
            separation: self.separation,
            convergence: self.convergence,
            from: match self.from {
                FromArg::Left => SourceView::Left,
                FromArg::Centre => SourceView::Centre,
                FromArg::Right => SourceView::Right,
            },
            to: match self.to {
                ToArg::Left => Target::Left,
                ToArg::Right => Target::Right,
                ToArg::Both => Target::Both,
                ToArg::Centre => Target::Centre,
            },
            method: self.method.map(|m| match m {
                ReprojectMethodArg::Shift => MethodChoice::Shift,
                ReprojectMethodArg::ShiftScan => MethodChoice::ShiftScan,
                ReprojectMethodArg::Gather3d => MethodChoice::Gather3d,
            }),
            steps: self.steps,
            tau_rel: self.tau_rel,
            outputs,
        })
    }
}

impl TryFrom<ReprojectArgs> for ReprojectJob {
    type Error = ArgError;
    fn try_from(a: ReprojectArgs) -> Result<Self, ArgError> {
        let request = a.request()?;
        let files = file_formats(&a.files.options(request.outputs()))?;
        ReprojectJob::new(ReprojectOptions {
            color: a.color,
            depth: a.depth,
            depth_scale: a.depth_scale,
            npz_key: a.npz_key,
            intrinsics_file: a.intrinsics.intrinsics.clone(),
            intrinsics: a.intrinsics.values(),
            cameras: a.cameras,
            request,
            files,
            out_dir: a.out_dir,
            conventions: a.conv.into(),
            gpu: a.gpu.try_into()?,
            backend: a.backend.into(),
        })
    }
}
