//! `viewsynth stitch` options (the face-folder convention is in the help) and their conversion
//! into a checked library job.

use crate::options::{BackendArg, ConventionArgs, GpuArgs};
use crate::options::{GPU, INPUTS, METHOD, OUTPUTS, TARGETS};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use viewsynth::io;
use viewsynth::job::stitch::{FaceDepth, StitchJob, StitchOptions, StitchRequest};
use viewsynth::job::{finite_or_inf, finite_value, ArgError};
use viewsynth::stitch::Method;

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum StitchMethodArg {
    /// Linear feather over the overlap.
    Blend,
    /// Stitch with border weight: in the overlap, each face's sample is displaced along its
    /// depth towards the other face's eye by a fixed angular weight.
    BorderWeight,
    /// Depth-aware reprojection along the ODS ray.
    Reproject,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub(crate) enum FaceDepthArg {
    /// View-space Z in metres; 0 / NaN / inf = background.
    #[value(alias = "metric")]
    ViewZ,
    /// Window depth in [0, 1] from a depth buffer; the far value is background.
    Device,
}

/// The example under `viewsynth stitch --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  # ODS 360 of the built-in scene, scored against its ray-traced truth
  viewsynth stitch --scene demo --face-size 128 --width 512 --height 256 --truth --out-dir out/ods
  # your own cube faces (here the ones `viewsynth scene --cube-faces` writes)
  viewsynth scene --cube-faces 128 --out-dir out/faces
  viewsynth stitch --faces out/faces --fov 110 --width 512 --height 256 --per-eye --out-dir out/ods_faces";

#[derive(Args)]
pub(crate) struct StitchArgs {
    /// Ray-trace the faces of a built-in scene (only `demo`, the scene of the ODS rig).
    #[arg(help_heading = INPUTS, long, required_unless_present = "faces", conflicts_with = "faces")]
    scene: Option<String>,
    /// Folder with the 12 faces: {left,right}_{pz,nz,px,nx,up,down}.png (colour) and
    /// {left,right}_{pz,nz,px,nx,up,down}_depth.{exr,npy,npz,pfm,png} (view-space Z,
    /// 0/NaN/inf = background; integer PNG with --depth-scale);
    /// see README for the poses and orientations.
    #[arg(help_heading = INPUTS, long)]
    faces: Option<PathBuf>,
    /// Face field of view in degrees, in (90, 178) (default 90 + 2 x overlap).
    #[arg(help_heading = INPUTS, long, value_parser = finite_value)]
    fov: Option<f64>,
    /// Face side in pixels with --scene.
    #[arg(help_heading = INPUTS, long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    face_size: u32,
    /// Raw units per metre for integer face depth files.
    #[arg(help_heading = INPUTS, long, value_parser = finite_value)]
    depth_scale: Option<f64>,
    /// Array of .npz face depth files to read (default: the only array, else the first
    /// floating-point one).
    #[arg(help_heading = INPUTS, long, value_name = "NAME", requires = "faces")]
    npz_key: Option<String>,
    /// What the face depth files hold (with --faces): view-z, or device depth written with
    /// --near/--far under --ndc and --reversed-z (converted to view Z before stitching).
    #[arg(help_heading = INPUTS, long, value_enum, default_value = "view-z")]
    depth_kind: FaceDepthArg,
    /// Near plane of device-depth faces (metres).
    #[arg(help_heading = INPUTS, long, value_parser = finite_value)]
    near: Option<f64>,
    /// Far plane of device-depth faces (metres; may be inf).
    #[arg(help_heading = INPUTS, long, value_parser = finite_or_inf)]
    far: Option<f64>,
    /// Equirect width per eye.
    #[arg(help_heading = TARGETS, long, default_value_t = StitchRequest::default().width, value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    width: u32,
    /// Equirect height per eye (the top-bottom image is twice as high).
    #[arg(help_heading = TARGETS, long, default_value_t = StitchRequest::default().height, value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    height: u32,
    /// Interpupillary distance (metres, the faces' units).
    #[arg(help_heading = TARGETS, long, default_value_t = StitchRequest::default().ipd, value_parser = finite_value)]
    ipd: f64,
    /// Seam band half-width in degrees, in (0, (fov - 90) / 2] (default (fov - 90) / 2 with
    /// --fov, else 10).
    #[arg(help_heading = METHOD, long, value_parser = finite_value)]
    overlap: Option<f64>,
    /// Stitching method: blend (feather the overlap), border-weight, or reproject (depth-aware
    /// along the ODS ray; the default).
    #[arg(help_heading = METHOD, long, value_enum, default_value = "reproject")]
    method: StitchMethodArg,
    /// Latitude (deg) above which the eye radius fades to 0 at the poles.
    #[arg(help_heading = METHOD, long, default_value_t = StitchRequest::default().pole_fade, value_parser = finite_value)]
    pole_fade: f64,
    /// Outputs to produce: any of rgb (or color), depth. depth: each eye's distance in metres
    /// along the pixel's ODS ray, from its origin on the viewing circle to the surface (0 =
    /// sky), written as float32 EXR [default: rgb].
    #[arg(help_heading = OUTPUTS, long)]
    outputs: Option<String>,
    /// Also write each eye's equirect (ods_left.png, ods_right.png; with depth also
    /// ods_left_depth.exr, ods_right_depth.exr).
    #[arg(help_heading = OUTPUTS, long)]
    per_eye: bool,
    /// With --scene: ray-trace the ODS ground truth and print PSNR on the seam band and the
    /// whole image.
    #[arg(help_heading = OUTPUTS, long)]
    truth: bool,
    /// Output folder (created if missing): ods_top_bottom.png (left eye on top) and, with
    /// depth in --outputs, ods_top_bottom_depth.exr; with --per-eye also each eye's files.
    #[arg(help_heading = OUTPUTS, long)]
    out_dir: PathBuf,
    /// Conventions of device-depth faces; the row order also sets the GPU pass's memory order.
    #[command(flatten)]
    conv: ConventionArgs,
    #[command(flatten)]
    gpu: GpuArgs,
    /// Rendering API: gl, or vulkan (the same shaders as SPIR-V on a Vulkan 1.3 device;
    /// --device an index of `viewsynth info --backend vulkan`).
    #[arg(help_heading = GPU, long, value_enum, default_value = "gl")]
    backend: BackendArg,
}

impl StitchArgs {
    /// The settings the Python binding gives too, as the library's request.
    pub(crate) fn request(&self) -> Result<StitchRequest, ArgError> {
        let (ndc, reversed_z, _) = self.conv.parts();
        Ok(StitchRequest {
            fov: self.fov,
            overlap: self.overlap,
            method: match self.method {
                StitchMethodArg::Blend => Method::Blend,
                StitchMethodArg::BorderWeight => Method::BorderWeight,
                StitchMethodArg::Reproject => Method::Reproject,
            },
            width: self.width,
            height: self.height,
            ipd: self.ipd,
            pole_fade: self.pole_fade,
            depth_kind: match self.depth_kind {
                FaceDepthArg::ViewZ => FaceDepth::ViewZ,
                FaceDepthArg::Device => FaceDepth::Device,
            },
            near: self.near,
            far: self.far,
            ndc,
            reversed_z,
            outputs: crate::options::parse_outputs(self.outputs.as_deref())?,
        })
    }
}

impl TryFrom<StitchArgs> for StitchJob {
    type Error = ArgError;
    fn try_from(a: StitchArgs) -> Result<Self, ArgError> {
        let request = a.request()?;
        StitchJob::new(StitchOptions {
            scene: a.scene,
            faces: a.faces,
            face_size: a.face_size,
            depth_scale: a.depth_scale,
            npz_key: a.npz_key,
            request,
            rows: a.conv.parts().2,
            per_eye: a.per_eye,
            truth: a.truth,
            out_dir: a.out_dir,
            gpu: a.gpu.try_into()?,
            backend: a.backend.into(),
        })
    }
}
