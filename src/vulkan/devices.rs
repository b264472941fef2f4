//! What a Vulkan device is and which one `auto` opens, without ash: shared by the backend and by
//! the stand-in a build without the `vulkan` feature gets (src/vulkan_off.rs), so `info` and
//! the policy read the same types either way.

use crate::error::{Error, Result};
use crate::pass::GpuPolicy;
use serde::Serialize;

/// What `viewsynth info --backend vulkan` prints about one physical device.
#[derive(Debug, Clone, Serialize)]
pub struct VulkanDeviceInfo {
    /// Position in the instance's physical-device list (what [`VulkanDeviceChoice::Index`] takes).
    pub index: usize,
    /// Device name reported by the driver.
    pub name: String,
    /// discrete-gpu, integrated-gpu, virtual-gpu, cpu or other.
    pub device_type: String,
    /// A CPU device (Mesa lavapipe, SwiftShader) renders in software.
    pub software: bool,
    /// Vulkan API version the device supports, "major.minor.patch".
    pub api_version: String,
    /// Driver name (VK_KHR_driver_properties).
    pub driver_name: String,
    /// Driver version text (VK_KHR_driver_properties).
    pub driver_info: String,
    /// PCI vendor ID.
    pub vendor_id: u32,
    /// Device ID within the vendor.
    pub device_id: u32,
    /// Largest 2D image side, pixels.
    pub max_image_dimension_2d: u32,
    /// VK_EXT_depth_clip_control: the GL NDC depth range [-1, 1] (the mesh pass needs it for
    /// the `--ndc gl` convention).
    pub depth_clip_control: bool,
    /// Fragment shaders may write storage buffers (the splat-gather draw lists its edge pixels).
    pub fragment_stores: bool,
    /// Vulkan 1.3 with dynamic rendering and depth clamp: what the passes need.
    pub usable: bool,
}

/// Which physical device to open.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VulkanDeviceChoice {
    /// First discrete, integrated, virtual GPU, else a CPU device (among the usable ones).
    #[default]
    Auto,
    /// An index of `list_devices()`.
    Index(usize),
}

/// Preference of `auto`: lower is better.
fn auto_rank(d: &VulkanDeviceInfo) -> u8 {
    match d.device_type.as_str() {
        "discrete-gpu" => 0,
        "integrated-gpu" => 1,
        "virtual-gpu" => 2,
        "cpu" => 4,
        _ => 3,
    }
}

/// The device `auto` opens: the best-ranked usable one (ties: the lower index).
pub fn auto_pick(devices: &[VulkanDeviceInfo]) -> Option<usize> {
    devices
        .iter()
        .filter(|d| d.usable)
        .min_by_key(|d| (auto_rank(d), d.index))
        .map(|d| d.index)
}

/// Refuse a software (CPU-type) device when the policy requires hardware, with the error the
/// GL side gives for llvmpipe.
pub fn check_policy(policy: &GpuPolicy, chosen: &VulkanDeviceInfo, all: &[VulkanDeviceInfo]) -> Result<()> {
    if !policy.require_hardware || !chosen.software {
        return Ok(());
    }
    let hardware: Vec<String> = all
        .iter()
        .filter(|d| !d.software)
        .map(|d| format!("Vulkan device {} '{}' ({})", d.index, d.name, d.device_type))
        .collect();
    let seen = if hardware.is_empty() {
        "no hardware Vulkan device is visible (in Docker: --gpus all -e NVIDIA_DRIVER_CAPABILITIES=graphics,utility)"
            .to_string()
    } else {
        format!("hardware visible but not used: {}", hardware.join("; "))
    };
    Err(Error::SoftwareRenderer {
        renderer: chosen.name.clone(),
        location: format!("Vulkan device {} ({})", chosen.index, chosen.device_type),
        seen,
    })
}
