//! The API a Renderer renders on: this thread's shared EGL context (`context`), or a Vulkan
//! device and its pass executor. Every binding takes a `&Backend` where the library takes
//! `impl ToDevice`, so the same call runs on either.

use crate::context;
use crate::errors::{self, Kind};
use pyo3::PyResult;
use viewsynth::gpu::Gpu;
use viewsynth::pass::{Device, GpuPolicy, ToDevice};

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
    /// Open `backend` ("gl" or "vulkan") on `device` (the library's parse, as the CLI's
    /// --device), refusing software under the library's policy when `require_gpu` is set.
    pub(crate) fn open(device: &str, require_gpu: bool, backend: &str) -> PyResult<Backend> {
        let choice = context::parse_device(device)?;
        let policy = GpuPolicy {
            require_hardware: require_gpu,
        };
        match backend {
            "gl" => {
                let gpu = context::acquire(choice)?;
                // The library's check (GpuInfo.software, the hardware seen), on the shared context.
                if let Err(e) = policy.check(gpu.info()) {
                    context::release(gpu);
                    return Err(software_refused(device, e));
                }
                Ok(Backend::Gl(gpu))
            }
            "vulkan" => {
                // The CLI's --backend vulkan: the same device choice and software policy.
                let request = viewsynth::job::GpuRequest {
                    device: choice,
                    policy: policy.with_env().map_err(errors::from_library)?,
                };
                let vk = request.open_vulkan().map_err(errors::from_library)?;
                let device = viewsynth::vulkan::VkExecutor::device(&vk).map_err(errors::from_library)?;
                Ok(Backend::Vulkan(device, vk.info().clone()))
            }
            other => Err(errors::invalid(
                "backend",
                format!("'{other}': expected \"gl\" or \"vulkan\""),
            )),
        }
    }

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

/// The library's software refusal in the keyword's words (GpuUnavailableError naming
/// require_gpu), with what it saw of the host's hardware.
fn software_refused(device: &str, e: viewsynth::Error) -> pyo3::PyErr {
    match e {
        viewsynth::Error::SoftwareRenderer { renderer, seen, .. } => errors::raise(
            Kind::GpuUnavailable,
            format!("require_gpu=True but EGL device '{device}' gave the software renderer '{renderer}' ({seen})"),
            Some("require_gpu"),
        ),
        other => errors::from_library(other),
    }
}
