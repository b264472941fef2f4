//! One in-flight submission of the executor: its command buffer and fence, the parameter blocks
//! and descriptor pool its steps bind, a staging arena for the image writes recorded ahead of
//! its steps, and the host buffers its outputs are copied into. A flight is reused once its run
//! has been waited for, so a steady stream of runs (as many in flight as the caller keeps)
//! allocates nothing: each object is only grown when a run needs more than the last.

use super::context::{vk_err, Vk};
use super::resources::Buffer;
use crate::convention::RowOrder;
use crate::error::Result;
use crate::pass::{Format, Texels};
use ash::vk;

/// A submission's objects and what its readback holds.
pub(super) struct Flight {
    vk: Vk,
    pub cb: vk::CommandBuffer,
    pub fence: vk::Fence,
    /// Every step's parameter block, at aligned offsets.
    pub params: Option<Buffer>,
    pub pool: vk::DescriptorPool,
    pool_sets: usize,
    /// Texels of the image writes queued for this flight, back to back.
    pub staging: Option<Buffer>,
    pub staging_used: usize,
    /// (image, byte offset in `staging`) of each queued write, in order.
    pub writes: Vec<(crate::pass::ImageId, usize)>,
    /// Per output location: a host buffer the attachment is copied into.
    pub readback: Vec<Option<Buffer>>,
    /// The run's outputs, size and row order (for turning the readback into top-down rows).
    pub outputs: Vec<Option<Format>>,
    pub size: (u32, u32),
    pub rows: RowOrder,
    /// Submitted and not yet waited for.
    pub busy: bool,
    /// The number of its run among the executor's submissions (valid while busy).
    pub serial: u64,
    /// Host time of recording and submitting.
    pub submit_ms: f64,
}

/// Descriptor sets a pool is made for, at least.
const MIN_SETS: usize = 4;
/// Sampled images a step binds, at most (bindings 1..=7).
pub(super) const MAX_SAMPLED: usize = 7;

impl Flight {
    pub fn new(vk: &Vk) -> Result<Self> {
        let (cb, fence) = vk.new_submit_slot()?;
        Ok(Flight {
            vk: vk.clone(),
            cb,
            fence,
            params: None,
            pool: vk::DescriptorPool::null(),
            pool_sets: 0,
            staging: None,
            staging_used: 0,
            writes: Vec::new(),
            readback: Vec::new(),
            outputs: Vec::new(),
            size: (0, 0),
            rows: RowOrder::TopDown,
            busy: false,
            serial: 0,
            submit_ms: 0.0,
        })
    }

    /// Append `bytes` to the staging arena (grown, keeping what is queued, when too small);
    /// their offset.
    pub fn stage(&mut self, bytes: &[u8]) -> Result<usize> {
        // Copies from a buffer need 4-byte aligned offsets for 4-byte texels; 16 covers RGBA32F.
        let offset = self.staging_used.div_ceil(16) * 16;
        let end = offset + bytes.len();
        if self.staging.as_ref().is_none_or(|b| b.size < end) {
            let grown = Buffer::new(&self.vk, end.next_power_of_two(), vk::BufferUsageFlags::TRANSFER_SRC)?;
            if let Some(old) = &self.staging {
                grown.write(old.read(self.staging_used));
            }
            self.staging = Some(grown);
        }
        let staging = self.staging.as_ref().expect("made above");
        staging.write_at(offset, bytes);
        self.staging_used = end;
        Ok(offset)
    }

    /// A parameter buffer of at least `bytes`.
    pub fn params(&mut self, bytes: usize) -> Result<&Buffer> {
        if self.params.as_ref().is_none_or(|b| b.size < bytes) {
            self.params = None;
            self.params = Some(Buffer::new(&self.vk, bytes, vk::BufferUsageFlags::STORAGE_BUFFER)?);
        }
        Ok(self.params.as_ref().expect("allocated above"))
    }

    /// Host buffers for `outputs` at `width` x `height` (kept when they already fit). A buffer
    /// of an output this run does not ask for is kept too (the run's target has no attachment
    /// there, so nothing is copied into it): runs that alternate output sets on one flight (the
    /// stereo matcher with and without its confidence) then allocate nothing.
    pub fn readback(&mut self, width: u32, height: u32, outputs: &[Option<Format>]) -> Result<()> {
        if self.readback.len() < outputs.len() {
            self.readback.resize_with(outputs.len(), || None);
        }
        for (slot, f) in self.readback.iter_mut().zip(outputs) {
            let Some(f) = f else { continue };
            let need = width as usize * height as usize * f.texel_bytes();
            if slot.as_ref().is_none_or(|b| b.size < need) {
                *slot = None;
                *slot = Some(Buffer::new(&self.vk, need, vk::BufferUsageFlags::TRANSFER_DST)?);
            }
        }
        self.outputs = outputs.to_vec();
        self.size = (width, height);
        Ok(())
    }

    /// Output `i`'s texels after the fence, rows top-down (files are top-down: a bottom-up
    /// memory order is flipped here, as GL does on the GPU), RGBA8 packed to RGB, the float
    /// formats into f32s (one copy out of the mapped buffer each).
    pub fn read_output(&self, i: usize) -> Result<Option<Texels>> {
        let Some(f) = self.outputs.get(i).copied().flatten() else {
            return Ok(None);
        };
        let Some(buffer) = self.readback.get(i).and_then(Option::as_ref) else {
            return Ok(None);
        };
        let (w, h) = self.size;
        let row_bytes = w as usize * f.texel_bytes();
        let mapped = buffer.read(row_bytes * h as usize);
        Ok(Some(match f {
            // Files hold RGB; the GL executor packs on the GPU, here while copying out.
            Format::Rgba8 => {
                let mut rgb = crate::alloc::try_with_capacity(mapped.len() / 4 * 3, "colour readback")?;
                for row in self.rows.top_down(mapped, row_bytes) {
                    rgb.extend(row.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]));
                }
                Texels::Bytes(rgb)
            }
            f if f.reads_as_floats() => {
                let mut floats = crate::alloc::try_with_capacity::<f32>(mapped.len() / 4, "depth readback")?;
                for row in self.rows.top_down(mapped, row_bytes) {
                    floats.extend(
                        row.chunks_exact(4)
                            .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]])),
                    );
                }
                Texels::Floats(floats)
            }
            _ => {
                let mut bytes = crate::alloc::try_with_capacity(mapped.len(), "readback")?;
                for row in self.rows.top_down(mapped, row_bytes) {
                    bytes.extend_from_slice(row);
                }
                Texels::Bytes(bytes)
            }
        }))
    }

    /// A descriptor pool with room for `sets` sets (reset, or made larger). A run without
    /// steps (a mesh that keeps no triangle) still gets a pool: the first run of a flight may
    /// be one, and resetting the null handle it starts with crashed the driver.
    pub fn reset_pool(&mut self, sets: usize) -> Result<()> {
        let d = &self.vk.device;
        let sets = sets.max(1);
        // SAFETY: the flight is not in flight, so no set of its pool is in use; the old pool is
        // destroyed before its handle is replaced; a null pool is never reset.
        unsafe {
            if self.pool != vk::DescriptorPool::null() && sets <= self.pool_sets {
                return d
                    .reset_descriptor_pool(self.pool, vk::DescriptorPoolResetFlags::empty())
                    .map_err(vk_err("vkResetDescriptorPool"));
            }
            d.destroy_descriptor_pool(self.pool, None);
            self.pool = vk::DescriptorPool::null();
            self.pool_sets = 0;
            let n = sets.next_power_of_two().max(MIN_SETS) as u32;
            let sizes = [
                vk::DescriptorPoolSize::default()
                    .ty(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .descriptor_count(MAX_SAMPLED as u32 * n),
                vk::DescriptorPoolSize::default()
                    .ty(vk::DescriptorType::STORAGE_IMAGE)
                    .descriptor_count(4 * n),
                vk::DescriptorPoolSize::default()
                    .ty(vk::DescriptorType::STORAGE_BUFFER)
                    // Four storage buffers a step and its parameter block.
                    .descriptor_count(5 * n),
            ];
            self.pool = d
                .create_descriptor_pool(
                    &vk::DescriptorPoolCreateInfo::default().max_sets(n).pool_sizes(&sizes),
                    None,
                )
                .map_err(vk_err("vkCreateDescriptorPool"))?;
            self.vk.count(super::context::Created::DescriptorPool);
            self.pool_sets = n as usize;
        }
        Ok(())
    }

    /// Whether the submission has finished (never blocks).
    pub fn finished(&self) -> bool {
        // SAFETY: a fence of this flight.
        !self.busy || unsafe { self.vk.device.get_fence_status(self.fence) }.unwrap_or(false)
    }

    /// Wait for the submission's fence.
    pub fn wait_fence(&self) -> Result<()> {
        if !self.busy {
            return Ok(());
        }
        // SAFETY: a fence of this flight, submitted.
        unsafe { self.vk.device.wait_for_fences(&[self.fence], true, u64::MAX) }.map_err(vk_err("vkWaitForFences"))
    }
}

impl Drop for Flight {
    fn drop(&mut self) {
        // A flight is dropped with its executor: wait for it before freeing what it uses.
        let _ = self.wait_fence();
        self.params = None;
        self.staging = None;
        self.readback.clear();
        // SAFETY: owned handles, no longer in use (waited for above).
        unsafe { self.vk.device.destroy_descriptor_pool(self.pool, None) };
        self.vk.free_submit_slot(self.cb, self.fence);
    }
}
