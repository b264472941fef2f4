//! The `vulkan` module of a build without the `vulkan` cargo feature (`cargo build
//! --no-default-features`): no ash, no SPIR-V, no glslangValidator at build time. It keeps the
//! backend's public surface so that every command and report compiles unchanged; opening a
//! Vulkan device fails with an error that says how to get one, and nothing else can be reached
//! without a device (the types hold an uninhabited value).

#[path = "vulkan/devices.rs"]
mod devices;

pub use devices::{auto_pick, check_policy, VulkanDeviceChoice, VulkanDeviceInfo};

use crate::error::{Error, Result};
use crate::pass::GpuPolicy;
use std::convert::Infallible;
use std::rc::Rc;

fn off() -> Error {
    Error::Vulkan(
        "this viewsynth was built without the `vulkan` cargo feature (it is on by default; \
         rebuild without --no-default-features, with glslang-tools installed)"
            .into(),
    )
}

/// Stands in for an open device: none can exist in this build.
pub struct VulkanContext(Infallible);

/// Shared handle to a [`VulkanContext`].
pub type Vk = Rc<VulkanContext>;

impl VulkanContext {
    /// Always the error saying the build has no Vulkan.
    pub fn open(_choice: VulkanDeviceChoice, _policy: GpuPolicy) -> Result<Vk> {
        Err(off())
    }

    /// Unreachable: no context exists.
    pub fn info(&self) -> &VulkanDeviceInfo {
        match self.0 {}
    }
}

/// Always the error saying the build has no Vulkan.
pub fn list_devices() -> Result<Vec<VulkanDeviceInfo>> {
    Err(off())
}

/// The pass executor of the real backend; unreachable here.
pub struct VkExecutor(Infallible);

impl VkExecutor {
    /// Unreachable: needs a device.
    pub fn device(vk: &Vk) -> Result<crate::pass::Device> {
        match vk.0 {}
    }
}
