//! The Vulkan instance, the physical-device list and the logical device a pass renders on.
//!
//! The loader (libvulkan.so.1) is opened at run time, so a machine without it gets
//! `Error::Vulkan` naming the package, not a link failure. No surface, no window-system
//! extension: rendering is into offscreen images only. Device choice mirrors the EGL side:
//! `auto` takes the first discrete, then integrated, then virtual GPU, then a CPU (software)
//! device; `--require-gpu` refuses a CPU device with the same `Error::SoftwareRenderer`.

use crate::error::{Error, Result};
use crate::pass::GpuPolicy;
use ash::vk;
use std::ffi::CStr;
use std::rc::Rc;

pub use super::devices::{auto_pick, check_policy, VulkanDeviceChoice, VulkanDeviceInfo};

/// A Vulkan result as the library's error, naming the call that returned it.
pub(super) fn vk_err(what: &str) -> impl Fn(vk::Result) -> Error + '_ {
    move |r| Error::Vulkan(format!("{what}: {r}"))
}

fn version(v: u32) -> String {
    format!(
        "{}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    )
}

fn type_name(t: vk::PhysicalDeviceType) -> &'static str {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => "discrete-gpu",
        vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated-gpu",
        vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual-gpu",
        vk::PhysicalDeviceType::CPU => "cpu",
        _ => "other",
    }
}

struct Instance {
    // The entry keeps libvulkan loaded for as long as the instance lives.
    _entry: ash::Entry,
    raw: ash::Instance,
    /// VK_EXT_debug_utils was enabled: objects can carry names for RenderDoc and the validation
    /// layer's messages.
    debug_utils: bool,
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: every child object is destroyed before (VulkanContext::drop destroys the device
        // first; Instance is its last field).
        unsafe { self.raw.destroy_instance(None) }
    }
}

fn create_instance() -> Result<Instance> {
    // SAFETY: loads libvulkan.so.1 and resolves its entry points; no other global state.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| {
        Error::Vulkan(format!(
            "cannot load the Vulkan loader (libvulkan.so.1): {e}; install libvulkan1 and a driver \
             (Debian/Ubuntu: libvulkan1 mesa-vulkan-drivers; ci/install-deps.sh does)"
        ))
    })?;
    let app = vk::ApplicationInfo::default()
        .application_name(c"viewsynth")
        .engine_name(c"viewsynth")
        .api_version(vk::API_VERSION_1_3);
    // SAFETY: plain query of the loader's instance extensions.
    let debug_utils = unsafe { entry.enumerate_instance_extension_properties(None) }
        .unwrap_or_default()
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::debug_utils::NAME));
    let extensions = [ash::ext::debug_utils::NAME.as_ptr()];
    let mut info = vk::InstanceCreateInfo::default().application_info(&app);
    if debug_utils {
        info = info.enabled_extension_names(&extensions);
    }
    // SAFETY: valid create info; the one extension (when enabled) is one the loader listed.
    let raw = unsafe { entry.create_instance(&info, None) }.map_err(|r| {
        Error::Vulkan(format!(
            "vkCreateInstance: {r} (is a Vulkan driver installed? Debian/Ubuntu: mesa-vulkan-drivers)"
        ))
    })?;
    Ok(Instance {
        _entry: entry,
        raw,
        debug_utils,
    })
}

fn describe(instance: &ash::Instance, index: usize, pd: vk::PhysicalDevice) -> Result<VulkanDeviceInfo> {
    // SAFETY: pd comes from this instance; the chained structs outlive the calls.
    unsafe {
        let props = instance.get_physical_device_properties(pd);
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
        if props.api_version >= vk::API_VERSION_1_2 {
            instance.get_physical_device_properties2(pd, &mut props2);
        }
        let exts = instance
            .enumerate_device_extension_properties(pd)
            .map_err(vk_err("vkEnumerateDeviceExtensionProperties"))?;
        let has_clip_control = exts
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::depth_clip_control::NAME));
        let mut clip = vk::PhysicalDeviceDepthClipControlFeaturesEXT::default();
        let mut v13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut features = vk::PhysicalDeviceFeatures2::default().push_next(&mut v13);
        if has_clip_control {
            features = features.push_next(&mut clip);
        }
        if props.api_version >= vk::API_VERSION_1_3 {
            instance.get_physical_device_features2(pd, &mut features);
        }
        let depth_clamp = features.features.depth_clamp == vk::TRUE;
        let fragment_stores = features.features.fragment_stores_and_atomics == vk::TRUE;
        let text =
            |c: std::result::Result<&CStr, _>| c.map_or(String::new(), |s: &CStr| s.to_string_lossy().into_owned());
        Ok(VulkanDeviceInfo {
            index,
            name: text(props.device_name_as_c_str()),
            device_type: type_name(props.device_type).to_string(),
            software: props.device_type == vk::PhysicalDeviceType::CPU,
            api_version: version(props.api_version),
            driver_name: text(driver.driver_name_as_c_str()),
            driver_info: text(driver.driver_info_as_c_str()),
            vendor_id: props.vendor_id,
            device_id: props.device_id,
            max_image_dimension_2d: props.limits.max_image_dimension2_d,
            depth_clip_control: has_clip_control && clip.depth_clip_control == vk::TRUE,
            fragment_stores,
            usable: props.api_version >= vk::API_VERSION_1_3 && v13.dynamic_rendering == vk::TRUE && depth_clamp,
        })
    }
}

fn enumerate(instance: &ash::Instance) -> Result<Vec<(vk::PhysicalDevice, VulkanDeviceInfo)>> {
    // SAFETY: valid instance.
    let pds = unsafe { instance.enumerate_physical_devices() }.map_err(vk_err("vkEnumeratePhysicalDevices"))?;
    pds.into_iter()
        .enumerate()
        .map(|(i, pd)| Ok((pd, describe(instance, i, pd)?)))
        .collect()
}

/// Every Vulkan physical device the loader sees.
pub fn list_devices() -> Result<Vec<VulkanDeviceInfo>> {
    let instance = create_instance()?;
    Ok(enumerate(&instance.raw)?.into_iter().map(|(_, d)| d).collect())
}

/// An open logical device with one graphics queue and a command pool. Shared (`Vk`) by every
/// object created on it, so it outlives them.
pub struct VulkanContext {
    pub(crate) device: ash::Device,
    pub(crate) queue: vk::Queue,
    pool: vk::CommandPool,
    memory: vk::PhysicalDeviceMemoryProperties,
    info: VulkanDeviceInfo,
    /// The one command buffer and fence every submit reuses (made on first use): a steady
    /// stream of frames allocates neither.
    submit: std::cell::Cell<Option<(vk::CommandBuffer, vk::Fence)>>,
    /// What was created on the device so far.
    census: std::cell::Cell<VkCensus>,
    /// Object naming (VK_EXT_debug_utils), where the instance has it.
    names: Option<ash::ext::debug_utils::Device>,
    // Last: dropped after the device.
    _instance: Instance,
}

/// Objects created (and waits) on a device since it opened: a steady state adds nothing
/// (viewsynth_tests/tests/library/vulkan/passes.rs holds every pass to it, as gpu/census.rs does for GL).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct VkCensus {
    /// Graphics and compute pipelines.
    pub pipelines: usize,
    /// Device memory allocations (each image and buffer has its own).
    pub allocations: usize,
    /// Descriptor pools.
    pub descriptor_pools: usize,
    /// Command buffers allocated and fences created.
    pub submit_objects: usize,
    /// vkQueueWaitIdle / vkDeviceWaitIdle calls (never on the frame path).
    pub wait_idles: usize,
    /// Bytes of device memory allocated and not yet freed: what the objects above hold now.
    /// A steady state keeps it flat, whatever it frees and makes again (objects kept past
    /// their use, a growing arena or graveyard, show here even when no count moves).
    pub live_bytes: u64,
}

/// What [`VulkanContext::count`] adds to.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Created {
    Pipeline,
    Allocation,
    DescriptorPool,
    SubmitObject,
}

/// Shared handle to a [`VulkanContext`].
pub type Vk = Rc<VulkanContext>;

impl VulkanContext {
    /// Open `choice` under `policy` (plus `VIEWSYNTH_REQUIRE_GPU`).
    pub fn open(choice: VulkanDeviceChoice, policy: GpuPolicy) -> Result<Vk> {
        let policy = policy.with_env()?;
        let instance = create_instance()?;
        let devices = enumerate(&instance.raw)?;
        let infos: Vec<VulkanDeviceInfo> = devices.iter().map(|(_, d)| d.clone()).collect();
        let index = match choice {
            VulkanDeviceChoice::Auto => auto_pick(&infos).ok_or_else(|| {
                Error::Vulkan(if infos.is_empty() {
                    "no Vulkan physical device (install a driver: Debian/Ubuntu mesa-vulkan-drivers)".into()
                } else {
                    "no Vulkan device with version 1.3, dynamic rendering and depth clamp".into()
                })
            })?,
            VulkanDeviceChoice::Index(i) => {
                let d = infos.get(i).ok_or_else(|| {
                    Error::param(
                        "device",
                        format!("Vulkan device {i} does not exist ({} found)", infos.len()),
                    )
                })?;
                if !d.usable {
                    return Err(Error::param(
                        "device",
                        format!(
                            "Vulkan device {i} '{}' lacks version 1.3, dynamic rendering or depth clamp",
                            d.name
                        ),
                    ));
                }
                i
            }
        };
        let (pd, info) = devices[index].clone();
        check_policy(&policy, &info, &infos)?;
        let raw = &instance.raw;
        // SAFETY: pd belongs to this instance; every pointer in the create infos outlives the call.
        unsafe {
            let families = raw.get_physical_device_queue_family_properties(pd);
            let family = families
                .iter()
                .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
                .ok_or_else(|| Error::Vulkan(format!("device '{}' has no graphics queue", info.name)))?
                as u32;
            let priorities = [1.0f32];
            let queues = [vk::DeviceQueueCreateInfo::default()
                .queue_family_index(family)
                .queue_priorities(&priorities)];
            let mut ext_names = Vec::new();
            let mut clip = vk::PhysicalDeviceDepthClipControlFeaturesEXT::default().depth_clip_control(true);
            // maintenance4 (required of every Vulkan 1.3 device): glslang's compute SPIR-V for
            // Vulkan 1.3 declares its work-group size with LocalSizeId, which needs it.
            let mut v13 = vk::PhysicalDeviceVulkan13Features::default()
                .dynamic_rendering(true)
                .maintenance4(true);
            let base = vk::PhysicalDeviceFeatures::default()
                .depth_clamp(true)
                .fragment_stores_and_atomics(info.fragment_stores);
            let mut features = vk::PhysicalDeviceFeatures2::default()
                .features(base)
                .push_next(&mut v13);
            if info.depth_clip_control {
                ext_names.push(ash::ext::depth_clip_control::NAME.as_ptr());
                features = features.push_next(&mut clip);
            }
            let create = vk::DeviceCreateInfo::default()
                .queue_create_infos(&queues)
                .enabled_extension_names(&ext_names)
                .push_next(&mut features);
            let device = raw.create_device(pd, &create, None).map_err(vk_err("vkCreateDevice"))?;
            let queue = device.get_device_queue(family, 0);
            let pool_info = vk::CommandPoolCreateInfo::default()
                .queue_family_index(family)
                .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
            let pool = match device.create_command_pool(&pool_info, None) {
                Ok(p) => p,
                Err(r) => {
                    device.destroy_device(None);
                    return Err(Error::Vulkan(format!("vkCreateCommandPool: {r}")));
                }
            };
            let memory = raw.get_physical_device_memory_properties(pd);
            let names = instance
                .debug_utils
                .then(|| ash::ext::debug_utils::Device::new(raw, &device));
            Ok(Rc::new(VulkanContext {
                device,
                queue,
                pool,
                memory,
                info,
                submit: std::cell::Cell::new(None),
                census: std::cell::Cell::new(VkCensus::default()),
                names,
                _instance: instance,
            }))
        }
    }

    /// The physical device this context renders on.
    pub fn info(&self) -> &VulkanDeviceInfo {
        &self.info
    }

    /// A memory type index allowed by `bits` with `flags`, or None.
    pub(crate) fn memory_type(&self, bits: u32, flags: vk::MemoryPropertyFlags) -> Option<u32> {
        (0..self.memory.memory_type_count)
            .find(|&i| bits & (1 << i) != 0 && self.memory.memory_types[i as usize].property_flags.contains(flags))
    }

    /// Name `handle` for debuggers (RenderDoc) and the validation layer's messages, where
    /// VK_EXT_debug_utils is there (wgpu-hal's object labels); otherwise nothing.
    pub(crate) fn name<H: vk::Handle>(&self, handle: H, name: &str) {
        let (Some(names), Ok(name)) = (&self.names, std::ffi::CString::new(name)) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&name);
        // SAFETY: `handle` is a live object of this device; the name outlives the call.
        let _ = unsafe { names.set_debug_utils_object_name(&info) };
    }

    /// What was created on this device so far ([`VkCensus`]).
    pub fn census(&self) -> VkCensus {
        self.census.get()
    }

    /// Count `bytes` of device memory allocated (`freed`: given back).
    pub(crate) fn count_bytes(&self, bytes: u64, freed: bool) {
        let mut c = self.census.get();
        c.live_bytes = if freed {
            c.live_bytes.saturating_sub(bytes)
        } else {
            c.live_bytes + bytes
        };
        self.census.set(c);
    }

    /// Count one more created object.
    pub(crate) fn count(&self, what: Created) {
        let mut c = self.census.get();
        match what {
            Created::Pipeline => c.pipelines += 1,
            Created::Allocation => c.allocations += 1,
            Created::DescriptorPool => c.descriptor_pools += 1,
            Created::SubmitObject => c.submit_objects += 1,
        }
        self.census.set(c);
    }

    /// The reused command buffer and fence, made on first use.
    fn submit_objects(&self) -> Result<(vk::CommandBuffer, vk::Fence)> {
        if let Some(s) = self.submit.get() {
            return Ok(s);
        }
        // Owned by the context from then on (freed in Drop).
        let slot = self.new_submit_slot()?;
        self.submit.set(Some(slot));
        Ok(slot)
    }

    /// A command buffer and fence of a caller's own (an in-flight submission's), freed with
    /// [`Self::free_submit_slot`].
    pub(crate) fn new_submit_slot(&self) -> Result<(vk::CommandBuffer, vk::Fence)> {
        let d = &self.device;
        // SAFETY: plain allocation from the context's pool; on the fence's failure the command
        // buffer is freed here.
        unsafe {
            let alloc = vk::CommandBufferAllocateInfo::default()
                .command_pool(self.pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1);
            let cb = d
                .allocate_command_buffers(&alloc)
                .map_err(vk_err("vkAllocateCommandBuffers"))?[0];
            match d.create_fence(&vk::FenceCreateInfo::default(), None) {
                Ok(f) => {
                    self.count(Created::SubmitObject);
                    self.count(Created::SubmitObject);
                    Ok((cb, f))
                }
                Err(r) => {
                    d.free_command_buffers(self.pool, &[cb]);
                    Err(vk_err("vkCreateFence")(r))
                }
            }
        }
    }

    /// Free a slot of [`Self::new_submit_slot`]; its submission must have finished.
    pub(crate) fn free_submit_slot(&self, cb: vk::CommandBuffer, fence: vk::Fence) {
        // SAFETY: the caller's objects, not in use.
        unsafe {
            self.device.destroy_fence(fence, None);
            self.device.free_command_buffers(self.pool, &[cb]);
        }
    }

    /// Record `record` into `cb` and submit it, signalling `fence`; returns without waiting.
    /// Both must be free (their last submission waited for).
    pub(crate) fn submit_commands(
        &self,
        cb: vk::CommandBuffer,
        fence: vk::Fence,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<()> {
        let d = &self.device;
        // SAFETY: the command buffer and fence are not in use (their last submit was waited
        // for); the queue is used from this thread only (the context is not Send).
        unsafe {
            d.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty())
                .map_err(vk_err("vkResetCommandBuffer"))?;
            d.reset_fences(&[fence]).map_err(vk_err("vkResetFences"))?;
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(cb, &begin)
                .map_err(vk_err("vkBeginCommandBuffer"))?;
            record(cb);
            d.end_command_buffer(cb).map_err(vk_err("vkEndCommandBuffer"))?;
            let cbs = [cb];
            let submit = [vk::SubmitInfo::default().command_buffers(&cbs)];
            d.queue_submit(self.queue, &submit, fence)
                .map_err(vk_err("vkQueueSubmit"))
        }
    }

    /// Record `record` into the context's command buffer, submit it and wait for its fence.
    /// Synchronous: no submit is pending when this returns, so every object a recording used is
    /// free again.
    pub(crate) fn run_commands(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        let (cb, fence) = self.submit_objects()?;
        self.submit_commands(cb, fence, record)?;
        // SAFETY: the fence was just submitted with `cb`.
        unsafe { self.device.wait_for_fences(&[fence], true, u64::MAX) }.map_err(vk_err("vkWaitForFences"))
    }
}

impl Drop for VulkanContext {
    fn drop(&mut self) {
        // SAFETY: every object created on the device holds a Vk, so none is left; the device is
        // idle after the last synchronous submit, and waiting again is harmless.
        unsafe {
            let _ = self.device.device_wait_idle();
            if let Some((cb, fence)) = self.submit.get() {
                self.device.destroy_fence(fence, None);
                self.device.free_command_buffers(self.pool, &[cb]);
            }
            self.device.destroy_command_pool(self.pool, None);
            self.device.destroy_device(None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dev(index: usize, device_type: &str, usable: bool) -> VulkanDeviceInfo {
        VulkanDeviceInfo {
            index,
            name: format!("dev{index}"),
            device_type: device_type.into(),
            software: device_type == "cpu",
            api_version: "1.3.0".into(),
            driver_name: String::new(),
            driver_info: String::new(),
            vendor_id: 0,
            device_id: 0,
            max_image_dimension_2d: 16384,
            depth_clip_control: true,
            fragment_stores: true,
            usable,
        }
    }

    #[test]
    fn auto_prefers_hardware_over_the_cpu_device_whatever_the_order() {
        let list = [
            dev(0, "cpu", true),
            dev(1, "integrated-gpu", true),
            dev(2, "discrete-gpu", true),
        ];
        assert_eq!(auto_pick(&list), Some(2));
        let list = [dev(0, "cpu", true), dev(1, "discrete-gpu", false)];
        assert_eq!(auto_pick(&list), Some(0), "an unusable GPU is skipped");
        assert_eq!(auto_pick(&[dev(0, "cpu", false)]), None);
    }

    #[test]
    fn require_gpu_refuses_a_cpu_device_and_names_the_unused_hardware() {
        let require = GpuPolicy { require_hardware: true };
        let list = [dev(0, "cpu", true), dev(1, "discrete-gpu", true)];
        let err = check_policy(&require, &list[0], &list).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, Error::SoftwareRenderer { .. }), "{text}");
        assert!(
            text.contains("dev0") && text.contains("Vulkan device 1 'dev1'"),
            "{text}"
        );
        assert!(check_policy(&require, &list[1], &list).is_ok());
        assert!(check_policy(&GpuPolicy::default(), &list[0], &list).is_ok());
        let only_cpu = [dev(0, "cpu", true)];
        let text = check_policy(&require, &only_cpu[0], &only_cpu).unwrap_err().to_string();
        assert!(text.contains("no hardware Vulkan device is visible"), "{text}");
    }
}
