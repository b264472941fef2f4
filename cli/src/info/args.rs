//! `viewsynth info` options.

use crate::options::{BackendArg, GpuArgs};
use crate::options::{GPU, OUTPUTS};
use clap::Args;
use viewsynth::job::{ArgError, GpuRequest};

/// The example under `viewsynth info --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  viewsynth info                    # the GPU, GL version, every EGL device and the one auto picks
  viewsynth info --json
  viewsynth info --backend vulkan   # the Vulkan devices";

#[derive(Args)]
pub(crate) struct InfoArgs {
    /// Print JSON instead of text.
    #[arg(help_heading = OUTPUTS, long)]
    json: bool,
    #[command(flatten)]
    gpu: GpuArgs,
    /// gl: the EGL/OpenGL context; vulkan: every Vulkan device and the one auto picks.
    #[arg(help_heading = GPU, long, value_enum, default_value = "gl")]
    backend: BackendArg,
}

/// `info` checked: the GPU to describe and how.
pub(crate) struct InfoRequest {
    pub gpu: GpuRequest,
    pub json: bool,
    pub backend: BackendArg,
    /// `--device` was given (not auto) or `--require-gpu`: open the Vulkan device too, so that
    /// `info --backend vulkan` refuses what a rendering command would.
    pub open_vulkan: bool,
}

impl TryFrom<InfoArgs> for InfoRequest {
    type Error = ArgError;
    fn try_from(a: InfoArgs) -> Result<Self, ArgError> {
        let gpu: GpuRequest = a.gpu.clone().try_into()?;
        gpu.check_backend(a.backend.into())?;
        Ok(InfoRequest {
            open_vulkan: a.gpu.is_explicit(),
            gpu,
            json: a.json,
            backend: a.backend,
        })
    }
}
