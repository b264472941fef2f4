//! Buffers and images, each with its own memory allocation and freed on drop (a handful per
//! pass: no sub-allocator). Buffers are host-visible and stay mapped: they carry uploads
//! (staging, indices) and readbacks; images are device-local.

use super::context::Vk;
use crate::error::{Error, Result};
use ash::vk;

/// A host-visible, host-coherent buffer, mapped for its whole life.
pub struct Buffer {
    vk: Vk,
    pub raw: vk::Buffer,
    memory: vk::DeviceMemory,
    ptr: *mut u8,
    pub size: usize,
    /// Bytes of its allocation (counted in the census until dropped).
    bytes: u64,
}

impl Buffer {
    pub fn new(vk: &Vk, size: usize, usage: vk::BufferUsageFlags) -> Result<Buffer> {
        let d = &vk.device;
        let size = size.max(4);
        // SAFETY: objects created here are destroyed on every error path and in Drop.
        unsafe {
            let info = vk::BufferCreateInfo::default()
                .size(size as u64)
                .usage(usage)
                .sharing_mode(vk::SharingMode::EXCLUSIVE);
            let raw = d
                .create_buffer(&info, None)
                .map_err(|r| Error::Vulkan(format!("vkCreateBuffer ({size} bytes): {r}")))?;
            let req = d.get_buffer_memory_requirements(raw);
            let host = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
            // Cached memory makes the readback's copy out fast where the device offers it.
            let index = vk
                .memory_type(req.memory_type_bits, host | vk::MemoryPropertyFlags::HOST_CACHED)
                .or_else(|| vk.memory_type(req.memory_type_bits, host));
            let Some(index) = index else {
                d.destroy_buffer(raw, None);
                return Err(Error::Vulkan("no host-visible coherent memory type".into()));
            };
            let memory = allocate(vk, &req, index, || d.destroy_buffer(raw, None))?;
            let mapped = d
                .bind_buffer_memory(raw, memory, 0)
                .and_then(|_| d.map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()));
            match mapped {
                Ok(ptr) => Ok(Buffer {
                    vk: vk.clone(),
                    raw,
                    memory,
                    ptr: ptr.cast(),
                    size,
                    bytes: req.size,
                }),
                Err(r) => {
                    d.destroy_buffer(raw, None);
                    d.free_memory(memory, None);
                    vk.count_bytes(req.size, true);
                    Err(Error::Vulkan(format!("binding/mapping buffer memory: {r}")))
                }
            }
        }
    }

    /// Copy `data` to the start of the buffer.
    pub fn write(&self, data: &[u8]) {
        assert!(data.len() <= self.size, "buffer write past its end");
        // SAFETY: the mapping spans `size` bytes and no GPU work using the buffer is pending
        // (every submit is waited for).
        unsafe { std::ptr::copy_nonoverlapping(data.as_ptr(), self.ptr, data.len()) }
    }

    /// Copy `data` to `offset` bytes into the buffer (no GPU work may be reading that range).
    pub fn write_at(&self, offset: usize, data: &[u8]) {
        assert!(offset + data.len() <= self.size, "buffer write past its end");
        // SAFETY: the mapping spans `size` bytes; the caller keeps the GPU off this range.
        unsafe { std::ptr::copy_nonoverlapping(data.as_ptr(), self.ptr.add(offset), data.len()) }
    }

    /// The first `len` bytes (after the GPU work writing them has been waited for).
    pub fn read(&self, len: usize) -> &[u8] {
        assert!(len <= self.size, "buffer read past its end");
        // SAFETY: as in write; coherent memory needs no invalidation.
        unsafe { std::slice::from_raw_parts(self.ptr, len) }
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: owned handles; no pending GPU work uses them.
        unsafe {
            self.vk.device.unmap_memory(self.memory);
            self.vk.device.destroy_buffer(self.raw, None);
            self.vk.device.free_memory(self.memory, None);
        }
        self.vk.count_bytes(self.bytes, true);
    }
}

/// A device-local 2-D image and its view.
pub struct Image {
    vk: Vk,
    pub raw: vk::Image,
    pub view: vk::ImageView,
    memory: vk::DeviceMemory,
    pub width: u32,
    pub height: u32,
    pub aspect: vk::ImageAspectFlags,
    /// Bytes of its allocation (counted in the census until dropped).
    bytes: u64,
}

impl Image {
    pub fn new(vk: &Vk, width: u32, height: u32, format: vk::Format, usage: vk::ImageUsageFlags) -> Result<Image> {
        let d = &vk.device;
        let aspect = if format == vk::Format::D32_SFLOAT {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        };
        // SAFETY: objects created here are destroyed on every error path and in Drop.
        unsafe {
            let info = vk::ImageCreateInfo::default()
                .image_type(vk::ImageType::TYPE_2D)
                .format(format)
                .extent(vk::Extent3D {
                    width,
                    height,
                    depth: 1,
                })
                .mip_levels(1)
                .array_layers(1)
                .samples(vk::SampleCountFlags::TYPE_1)
                .tiling(vk::ImageTiling::OPTIMAL)
                .usage(usage)
                .sharing_mode(vk::SharingMode::EXCLUSIVE)
                .initial_layout(vk::ImageLayout::UNDEFINED);
            let raw = d
                .create_image(&info, None)
                .map_err(|r| Error::Vulkan(format!("vkCreateImage {width}x{height} {format:?}: {r}")))?;
            let req = d.get_image_memory_requirements(raw);
            let Some(index) = vk.memory_type(req.memory_type_bits, vk::MemoryPropertyFlags::DEVICE_LOCAL) else {
                d.destroy_image(raw, None);
                return Err(Error::Vulkan("no device-local memory type for an image".into()));
            };
            let memory = allocate(vk, &req, index, || d.destroy_image(raw, None))?;
            let view_info = vk::ImageViewCreateInfo::default()
                .image(raw)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format)
                .subresource_range(range(aspect));
            let view = d
                .bind_image_memory(raw, memory, 0)
                .and_then(|_| d.create_image_view(&view_info, None));
            match view {
                Ok(view) => Ok(Image {
                    vk: vk.clone(),
                    raw,
                    view,
                    memory,
                    width,
                    height,
                    aspect,
                    bytes: req.size,
                }),
                Err(r) => {
                    d.destroy_image(raw, None);
                    d.free_memory(memory, None);
                    vk.count_bytes(req.size, true);
                    Err(Error::Vulkan(format!("binding image memory / creating its view: {r}")))
                }
            }
        }
    }

    /// Record a layout transition with a full barrier between the given stages and accesses.
    #[allow(clippy::too_many_arguments)]
    pub fn transition(
        &self,
        cb: vk::CommandBuffer,
        from: vk::ImageLayout,
        to: vk::ImageLayout,
        src_stage: vk::PipelineStageFlags,
        src_access: vk::AccessFlags,
        dst_stage: vk::PipelineStageFlags,
        dst_access: vk::AccessFlags,
    ) {
        let barrier = vk::ImageMemoryBarrier::default()
            .old_layout(from)
            .new_layout(to)
            .src_access_mask(src_access)
            .dst_access_mask(dst_access)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(self.raw)
            .subresource_range(range(self.aspect));
        // SAFETY: recording into a command buffer in the recording state.
        unsafe {
            self.vk.device.cmd_pipeline_barrier(
                cb,
                src_stage,
                dst_stage,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier],
            )
        }
    }

    /// The whole image as one buffer-image copy region (tightly packed rows).
    pub fn copy_region(&self) -> vk::BufferImageCopy {
        vk::BufferImageCopy::default()
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(self.aspect)
                    .mip_level(0)
                    .base_array_layer(0)
                    .layer_count(1),
            )
            .image_extent(vk::Extent3D {
                width: self.width,
                height: self.height,
                depth: 1,
            })
    }

    /// Record an upload from `staging` (tightly packed) that leaves the image readable by
    /// fragment and vertex shaders.
    pub fn record_upload(&self, cb: vk::CommandBuffer, staging: &Buffer) {
        self.record_upload_at(cb, staging, 0);
    }

    /// [`Self::record_upload`] from `offset` bytes into `staging`.
    pub fn record_upload_at(&self, cb: vk::CommandBuffer, staging: &Buffer, offset: usize) {
        use vk::{AccessFlags as A, ImageLayout as L, PipelineStageFlags as S};
        self.transition(
            cb,
            L::UNDEFINED,
            L::TRANSFER_DST_OPTIMAL,
            S::TOP_OF_PIPE,
            A::empty(),
            S::TRANSFER,
            A::TRANSFER_WRITE,
        );
        // SAFETY: recording; the buffer holds width x height texels of this format.
        unsafe {
            self.vk.device.cmd_copy_buffer_to_image(
                cb,
                staging.raw,
                self.raw,
                L::TRANSFER_DST_OPTIMAL,
                &[self.copy_region().buffer_offset(offset as u64)],
            )
        }
        self.transition(
            cb,
            L::TRANSFER_DST_OPTIMAL,
            L::SHADER_READ_ONLY_OPTIMAL,
            S::TRANSFER,
            A::TRANSFER_WRITE,
            S::VERTEX_SHADER | S::FRAGMENT_SHADER,
            A::SHADER_READ,
        );
    }
}

/// Allocate `req.size` bytes of memory type `index`; on failure `undo` (destroying the object
/// the memory was for) runs before the error is returned.
fn allocate(vk: &Vk, req: &vk::MemoryRequirements, index: u32, undo: impl FnOnce()) -> Result<vk::DeviceMemory> {
    let alloc = vk::MemoryAllocateInfo::default()
        .allocation_size(req.size)
        .memory_type_index(index);
    vk.count(super::context::Created::Allocation);
    // SAFETY: plain allocation; the caller owns the memory and frees it in its Drop.
    let memory = unsafe { vk.device.allocate_memory(&alloc, None) }.map_err(|r| {
        undo();
        Error::Vulkan(format!("vkAllocateMemory ({} bytes): {r}", req.size))
    })?;
    vk.count_bytes(req.size, false);
    Ok(memory)
}

pub fn range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(aspect)
        .base_mip_level(0)
        .level_count(1)
        .base_array_layer(0)
        .layer_count(1)
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: owned handles; no pending GPU work uses them.
        unsafe {
            self.vk.device.destroy_image_view(self.view, None);
            self.vk.device.destroy_image(self.raw, None);
            self.vk.device.free_memory(self.memory, None);
        }
        self.vk.count_bytes(self.bytes, true);
    }
}

/// An image filled with `texels` (tightly packed rows of `format`), ready for sampling.
pub fn sampled_image(vk: &Vk, width: u32, height: u32, format: vk::Format, texels: &[u8]) -> Result<Image> {
    let image = Image::new(
        vk,
        width,
        height,
        format,
        vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
    )?;
    let staging = Buffer::new(vk, texels.len(), vk::BufferUsageFlags::TRANSFER_SRC)?;
    staging.write(texels);
    vk.run_commands(|cb| image.record_upload(cb, &staging))?;
    Ok(image)
}

/// The passes' sampler (nearest, clamp-to-edge: the grid's border ring reads its edge texels, as
/// under GL; passes reading with texelFetch never filter) and a descriptor set layout of
/// `bindings`, made together so that a failure of the second destroys the first. The caller owns
/// both and destroys them in its Drop.
pub(crate) fn sampler_and_set_layout(
    vk: &Vk,
    bindings: &[vk::DescriptorSetLayoutBinding],
) -> Result<(vk::Sampler, vk::DescriptorSetLayout)> {
    let d = &vk.device;
    let sampler_info = vk::SamplerCreateInfo::default()
        .mag_filter(vk::Filter::NEAREST)
        .min_filter(vk::Filter::NEAREST)
        .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
        .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .max_lod(0.0);
    // SAFETY: plain object creation on a live device; on the layout's failure the sampler,
    // owned by no one yet, is destroyed here.
    unsafe {
        let sampler = d
            .create_sampler(&sampler_info, None)
            .map_err(|r| Error::Vulkan(format!("vkCreateSampler: {r}")))?;
        match d.create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(bindings), None) {
            Ok(layout) => Ok((sampler, layout)),
            Err(r) => {
                d.destroy_sampler(sampler, None);
                Err(Error::Vulkan(format!("vkCreateDescriptorSetLayout: {r}")))
            }
        }
    }
}
