//! A headless Vulkan backend (through `ash`, loader opened at run time) for comparing our
//! outputs with a real Vulkan run of the same shaders: the conventions the GL passes emulate
//! (`glClipControl`, row flips) are native here.
//!
//! - `context`: instance, physical-device list (type CPU = software, e.g. lavapipe), device
//!   choice and the `--require-gpu` rule, the logical device and synchronous submits.
//! - `resources`: host-visible buffers (uploads, indices, readback) and device-local images.
//! - `pipeline`: SPIR-V variants compiled by build.rs from the GL sources (looked up by the GL
//!   preamble) and graphics pipelines with dynamic rendering.
//! - `executor`: runs the backend-neutral pass descriptions (`crate::pass`) of every
//!   capability (refocus, cyclopean, reproject, stitch, the scene ray tracer), from the same
//!   GLSL as the GL executor.
//! - `flight`: one in-flight submission's objects (command buffer, fence, parameter blocks,
//!   descriptor pool, staging arena, readback buffers), reused once waited for.
//! - `targets`: the colour attachments the passes render into and their readback copies.

mod context;
mod devices;
mod executor;
mod flight;
mod pipeline;
mod resources;
mod targets;

pub use context::{
    auto_pick, check_policy, list_devices, Vk, VkCensus, VulkanContext, VulkanDeviceChoice, VulkanDeviceInfo,
};
pub use executor::VkExecutor;
