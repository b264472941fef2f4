//! `--backend gl|vulkan` (refocus, info).

use clap::ValueEnum;
use viewsynth::job::Backend;

/// Rendering API.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum BackendArg {
    /// OpenGL 4.5 over EGL.
    Gl,
    /// Vulkan 1.3 (ash): the same shaders compiled to SPIR-V, to compare with Vulkan renderers.
    Vulkan,
}

impl From<BackendArg> for Backend {
    fn from(b: BackendArg) -> Self {
        match b {
            BackendArg::Gl => Backend::Gl,
            BackendArg::Vulkan => Backend::Vulkan,
        }
    }
}
