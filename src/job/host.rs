//! What a running job needs from the program around it: a GPU, opened only when the job is
//! about to render (after its inputs are read and checked), and someone to tell things to.

use super::ArgError;
use crate::gpu::{DeviceChoice, Gpu};
use crate::io::{DepthSummary, DisparitySummary};
use crate::pass::GpuPolicy;
use crate::vulkan::{Vk, VulkanContext, VulkanDeviceChoice};
use crate::Message;
use std::path::Path;

/// Which GPU a job renders on (`--device`, `--require-gpu`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GpuRequest {
    /// The EGL device.
    pub device: DeviceChoice,
    /// Whether a software renderer is refused.
    pub policy: GpuPolicy,
}

impl GpuRequest {
    /// `device` as `--device` takes it: `auto`, `surfaceless` or an index from `viewsynth info`.
    pub fn new(device: &str, require_hardware: bool) -> Result<Self, ArgError> {
        let device = device
            .parse()
            .map_err(|e: crate::gpu::DeviceChoiceError| ArgError::Device {
                value: e.value,
                source: e.source,
            })?;
        Ok(GpuRequest {
            device,
            policy: GpuPolicy { require_hardware },
        })
    }

    /// Refuses a `--device` that `backend` has no such device for (surfaceless is an EGL
    /// platform): the command line contradicts itself, found before any work.
    pub fn check_backend(&self, backend: Backend) -> Result<(), ArgError> {
        if backend == Backend::Vulkan && self.device == DeviceChoice::Surfaceless {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::Device,
                crate::msg![
                    "surfaceless is an EGL choice: with ",
                    crate::Field::Backend,
                    " vulkan give auto or an index of \
                 `viewsynth info --backend vulkan`"
                ],
            )));
        }
        Ok(())
    }

    /// Opens the context (EGL display, GL 4.5+ core), refusing software under the policy.
    pub fn open(&self) -> crate::Result<Gpu> {
        Gpu::open(self.device, self.policy)
    }

    /// Opens the Vulkan device of the same `--device` (auto or an index of `viewsynth info
    /// --backend vulkan`) under the same policy (a CPU device counts as software).
    pub fn open_vulkan(&self) -> crate::Result<Vk> {
        let choice = match self.device {
            DeviceChoice::Auto => VulkanDeviceChoice::Auto,
            DeviceChoice::Index(i) => VulkanDeviceChoice::Index(i),
            DeviceChoice::Surfaceless => {
                return Err(crate::Error::param(
                    crate::Field::Device,
                    crate::msg![
                        "surfaceless is an EGL choice: with ",
                        crate::Field::Backend,
                        " vulkan give auto or an index of `viewsynth info --backend vulkan`"
                    ],
                ))
            }
        };
        VulkanContext::open(choice, self.policy)
    }
}

/// The rendering API of the commands that have two (`--backend`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Backend {
    /// OpenGL 4.5 over EGL.
    #[default]
    Gl,
    /// Vulkan 1.3 (ash): the same shaders compiled to SPIR-V, to compare with Vulkan renderers.
    Vulkan,
}

/// Something a job tells the person running it while it works.
#[derive(Debug)]
pub enum Event<'a> {
    /// An input depth map as decoded, in metres (before rendering; `hint` names the options
    /// that set the decoding, for the warnings the summary raises).
    InputDepth {
        /// The file.
        path: &'a Path,
        /// Size, valid fraction, min / median / max.
        summary: &'a DepthSummary,
        /// What to check when the summary looks wrong.
        hint: &'a Message,
    },
    /// An input disparity map as decoded, in pixels, with the pair's scale check (before
    /// rendering; the warnings name `--disparity-scale`).
    InputDisparity {
        /// The file.
        path: &'a Path,
        /// Size, valid fraction, min / median / max, the scale that fits the views.
        summary: &'a DisparitySummary,
    },
    /// A rectified pair given one eye's disparity: `eye`'s map was derived from the other's
    /// ([`crate::stereo::one_eye`]), known at this fraction of its pixels.
    DisparityDerived {
        /// The eye without a file.
        eye: crate::stereo::Eye,
        /// Fraction of its pixels the given eye's geometry reaches.
        known_fraction: f64,
    },
    /// `--depth-trunc` set this many pixels invalid.
    DepthTruncated {
        /// The limit in metres.
        limit_m: f64,
        /// Pixels beyond it.
        pixels: usize,
    },
    /// Two images alone: the disparity range the matcher searched, pixels.
    DisparityRange {
        /// Smallest disparity searched (may be negative).
        min: i32,
        /// Largest.
        max: i32,
        /// Estimated from the images (else both ends were given).
        estimated: bool,
    },
    /// Work of `total` items (targets, frames) starts.
    Started {
        /// What the items are, e.g. "refocus targets".
        what: &'static str,
        /// How many.
        total: u64,
    },
    /// One more item finished.
    Advanced,
    /// All items finished (or the stages of a long run).
    Finished,
}

/// The program around a job: opens the GPU when asked and hears the job's events.
pub trait Host {
    /// The GPU of the job's [`GpuRequest`]; called once, after the inputs are read.
    fn open_gpu(&self, request: &GpuRequest) -> crate::Result<Gpu>;
    /// The Vulkan device of the job's [`GpuRequest`] (`--backend vulkan`).
    fn open_vulkan(&self, request: &GpuRequest) -> crate::Result<Vk> {
        request.open_vulkan()
    }
    /// Something to tell the person running the job.
    fn event(&self, event: Event<'_>);
    /// A pass device on `backend` (`--backend`): GL through [`Host::open_gpu`], Vulkan through
    /// [`Host::open_vulkan`], each under the request's `--device` and `--require-gpu`.
    fn open_device(&self, request: &GpuRequest, backend: Backend) -> crate::Result<crate::pass::Device> {
        match backend {
            Backend::Gl => crate::pass::Device::gl(&self.open_gpu(request)?),
            Backend::Vulkan => crate::vulkan::VkExecutor::device(&self.open_vulkan(request)?),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{DeviceChoice, GpuRequest};

    #[test]
    fn device_is_auto_surfaceless_or_an_index() {
        assert_eq!(GpuRequest::new("auto", false).unwrap().device, DeviceChoice::Auto);
        assert_eq!(
            GpuRequest::new("surfaceless", false).unwrap().device,
            DeviceChoice::Surfaceless
        );
        let r = GpuRequest::new("2", true).unwrap();
        assert_eq!((r.device, r.policy.require_hardware), (DeviceChoice::Index(2), true));
        let e = GpuRequest::new("gpu0", false).unwrap_err().to_string();
        assert_eq!(e, "--device 'gpu0': expected auto, surfaceless or an index");
    }
}
