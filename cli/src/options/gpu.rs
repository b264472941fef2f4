//! `--device` and `--require-gpu`, shared by every rendering command.

use clap::Args;
use viewsynth::job::{ArgError, GpuRequest};

#[derive(Args, Clone)]
#[command(next_help_heading = super::GPU)]
pub(crate) struct GpuArgs {
    /// EGL device: auto (CUDA_VISIBLE_DEVICES match, else the first hardware device, else the
    /// software one, else Mesa surfaceless), an index from `viewsynth info`, or `surfaceless`.
    #[arg(long, default_value = "auto")]
    device: String,
    /// Fail (exit 1) when the renderer is software (llvmpipe, softpipe) instead of warning.
    ///
    /// VIEWSYNTH_REQUIRE_GPU=1 does the same.
    #[arg(long)]
    require_gpu: bool,
}

impl GpuArgs {
    /// A device other than auto, or `--require-gpu`.
    pub(crate) fn is_explicit(&self) -> bool {
        self.require_gpu || self.device != "auto"
    }
}

impl TryFrom<GpuArgs> for GpuRequest {
    type Error = ArgError;
    fn try_from(a: GpuArgs) -> Result<Self, ArgError> {
        GpuRequest::new(&a.device, a.require_gpu)
    }
}
