//! `viewsynth scene` options and their conversion into a checked library job.

use crate::options::{BackendArg, ConventionArgs, GpuArgs};
use crate::options::{GPU, INPUTS, OUTPUTS, TARGETS};
use clap::Args;
use std::path::PathBuf;
use viewsynth::io;
use viewsynth::job::scene::{SceneJob, SceneOptions};
use viewsynth::job::{finite_value, ArgError};

/// The example under `viewsynth scene --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  viewsynth scene --width 320 --height 240 --out-dir out/scene     # a stereo frame + cameras.json
  viewsynth scene --cube-faces 128 --out-dir out/faces             # also 6 faces per eye for stitch --faces
  viewsynth scene --width 320 --height 240 --frames 8 --out-dir out/seq  # a sequence for cyclopean --sequence";

#[derive(Args)]
pub(crate) struct SceneArgs {
    /// `demo`, `boxes`, or a scene JSON file of planes, spheres and boxes.
    #[arg(help_heading = INPUTS, long, default_value = "demo")]
    scene: String,
    /// Image width of each view, pixels.
    #[arg(help_heading = TARGETS, long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    width: u32,
    /// Image height of each view, pixels.
    #[arg(help_heading = TARGETS, long, default_value_t = 480, value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    height: u32,
    /// Interocular distance in metres.
    #[arg(help_heading = TARGETS, long, default_value_t = 0.064, value_parser = finite_value)]
    ipd: f64,
    /// Output folder (created if missing): {left,right,middle}_rgb.png, {left,right,middle}_view_z.exr,
    /// {left,right,middle}_device_depth.exr and cameras.json.
    #[arg(help_heading = OUTPUTS, long, default_value = "out/scene")]
    out_dir: PathBuf,
    /// Also write each eye's six cube faces, N x N pixels, as `viewsynth stitch --faces` reads
    /// them: {left,right}_{pz,nz,up,down,px,nx}.png and _depth.exr (view Z), ray-traced on the CPU
    /// from a 360 rig at --ipd, with stitch's default pole fade.
    #[arg(help_heading = OUTPUTS, long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=i64::from(io::MAX_DIMENSION)))]
    cube_faces: Option<u32>,
    /// Field of view of the cube faces, degrees, in (90, 178): give stitch the same --fov.
    #[arg(help_heading = OUTPUTS, long, default_value_t = 110.0, requires = "cube_faces", value_parser = finite_value)]
    face_fov: f64,
    /// Frames of a sequence: the head moves --dolly metres to its right per frame; each
    /// frame's files are prefixed 00000_, 00001_, ... and sequence.json lists them for
    /// `viewsynth cyclopean --sequence`.
    #[arg(help_heading = OUTPUTS, long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=i64::from(viewsynth::job::scene::MAX_SCENE_FRAMES)))]
    frames: u32,
    /// Metres the head moves to its right between frames (with --frames).
    #[arg(help_heading = OUTPUTS, long, default_value_t = 0.02, value_parser = finite_value)]
    dolly: f64,
    /// Metres to the head's right of the middle (spectator) camera and its truth view: 0
    /// halfway between the eyes; beyond half the IPD it looks past the right eye.
    #[arg(help_heading = TARGETS, long, default_value_t = 0.0, value_parser = finite_value)]
    spectator_offset: f64,
    #[command(flatten)]
    conv: ConventionArgs,
    #[command(flatten)]
    gpu: GpuArgs,
    /// Rendering API: gl, or vulkan (the same shaders as SPIR-V on a Vulkan 1.3 device;
    /// --device an index of `viewsynth info --backend vulkan`).
    #[arg(help_heading = GPU, long, value_enum, default_value = "gl")]
    backend: BackendArg,
}

impl TryFrom<SceneArgs> for SceneJob {
    type Error = ArgError;
    fn try_from(a: SceneArgs) -> Result<Self, ArgError> {
        SceneJob::new(SceneOptions {
            scene: a.scene,
            width: a.width,
            height: a.height,
            cube_faces: a.cube_faces,
            frames: a.frames,
            dolly: a.dolly,
            spectator_offset: a.spectator_offset,
            face_fov: a.face_fov,
            ipd: a.ipd,
            conventions: a.conv.into(),
            out_dir: a.out_dir,
            gpu: a.gpu.try_into()?,
            backend: a.backend.into(),
        })
    }
}
