//! `viewsynth scene` options and their conversion into a checked library job.

use crate::options::{BackendArg, ConventionArgs, GpuArgs};
use clap::Args;
use std::path::PathBuf;
use viewsynth::io;
use viewsynth::job::scene::{SceneJob, SceneOptions};
use viewsynth::job::{finite_value, ArgError};

#[derive(Args)]
pub(crate) struct SceneArgs {
    /// `demo`, `boxes`, or a scene JSON file of planes, spheres and boxes.
    #[arg(long, default_value = "demo")]
    scene: String,
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    width: u32,
    #[arg(long, default_value_t = 480, value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    height: u32,
    /// Interocular distance in metres.
    #[arg(long, default_value_t = 0.064, value_parser = finite_value)]
    ipd: f64,
    #[command(flatten)]
    conv: ConventionArgs,
    /// Output folder (created if missing).
    #[arg(long, default_value = "out/scene")]
    out_dir: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
    /// Rendering API: gl, or vulkan (the same shaders as SPIR-V on a Vulkan 1.3 device;
    /// --device an index of `viewsynth info --backend vulkan`).
    #[arg(long, value_enum, default_value = "gl")]
    backend: BackendArg,
}

impl TryFrom<SceneArgs> for SceneJob {
    type Error = ArgError;
    fn try_from(a: SceneArgs) -> Result<Self, ArgError> {
        SceneJob::new(SceneOptions {
            scene: a.scene,
            width: a.width,
            height: a.height,
            ipd: a.ipd,
            conventions: a.conv.into(),
            out_dir: a.out_dir,
            gpu: a.gpu.try_into()?,
            backend: a.backend.into(),
        })
    }
}
