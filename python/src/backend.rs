//! The API a Renderer renders on: this thread's shared EGL context (`context`), or a Vulkan
//! device and its pass executor. Every binding takes a `&Backend` where the library takes
//! `impl ToDevice`, so the same call runs on either.

use viewsynth::gpu::Gpu;
use viewsynth::pass::{Device, ToDevice};

/// A Renderer's API.
#[derive(Clone)]
pub(crate) enum Backend {
    /// OpenGL: the thread's shared context; each call opens its executor on it (so its GL objects
    /// go with the call, and `gl_objects()` sees only the readback pool between calls).
    Gl(Gpu),
    /// Vulkan: one executor for the Renderer's life (pipelines and targets cached across calls),
    /// and the device's description.
    Vulkan(Device, viewsynth::vulkan::VulkanDeviceInfo),
}

impl Backend {
    /// Refuse an image larger than this device renders, naming it.
    pub(crate) fn check_image_size(&self, name: &str, width: u32, height: u32) -> viewsynth::Result<()> {
        match self {
            Backend::Gl(gpu) => gpu.check_image_size(name, width, height),
            Backend::Vulkan(device, _) => device.check_image_size(name, width, height),
        }
    }
}

impl ToDevice for &Backend {
    fn to_device(self) -> viewsynth::Result<Device> {
        match self {
            Backend::Gl(gpu) => gpu.to_device(),
            Backend::Vulkan(device, _) => Ok(device.clone()),
        }
    }
}
