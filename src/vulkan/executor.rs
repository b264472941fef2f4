//! The Vulkan executor: runs the same [`Draw`]s as the GL executor (src/pass/gl.rs), from the
//! same GLSL compiled to SPIR-V by build.rs, looked up by the GL preamble.
//!
//! Interface (every `*_params.glsl`): descriptor set 0 holds the parameter block at binding 0
//! (a read-only storage buffer: shaders/common/vulkan.glsl says why), the sampled images at
//! bindings 1..=7 (combined image samplers, nearest, clamp to edge), exactly the GL bindings,
//! then the storage images at 8 + k and the storage buffers at 12 + k (GL's image unit and
//! buffer binding k: shaders/common/bindings.glsl). One host-visible buffer carries every
//! step's block at 256-byte offsets (the largest `minStorageBufferOffsetAlignment` the spec
//! allows). Pipelines are cached per program, output
//! set and binding counts; targets per size and output set (the last few). Each run is one
//! submission of a [`Flight`] (flight.rs: command buffer, fence, parameter buffer, descriptor
//! pool, staging arena, host readback buffers), reused once waited for, so several runs can be
//! in flight and a steady state creates nothing. A run's command buffer starts with a full
//! barrier (runs share attachments and images with those before them), then the image writes
//! queued for it ([`Executor::write_image`]), then its steps: consecutive draws in one dynamic
//! rendering, a full memory barrier between other steps, attachments moved to GENERAL after the
//! draws (so compute steps may rewrite them), then the copies into the flight's host buffers;
//! `wait` waits for its fence. Objects freed while a run is in flight are kept until none is.
//! Created images live in GENERAL; uploaded ones are read-only.
//!
//! Rows: memory rows mean what they mean under GL (NDC y = -1 and `gl_FragCoord.y` = 0.5 are
//! memory row 0 in both APIs), so images are uploaded in the same memory order and the rows are
//! flipped to top-down on the way out, as the GL executor does on the GPU.

use super::context::{vk_err, Vk};
use super::flight::{Flight, MAX_SAMPLED};
use super::pipeline::{Pipeline, PipelineDesc};
use super::resources::{sampled_image, sampler_and_set_layout, Buffer, Image};
use super::targets::ColorTargets;
use crate::error::{Error, Result};
use crate::pass::{
    Api, BufferId, Dispatch, Executor, Format, Groups, ImageData, ImageId, Rendered, Slots, Step, StorageImage, Target,
    Ticket,
};
use crate::pass::{ShaderProgram, Timing};
use ash::vk;
use std::time::Instant;

/// Targets kept for reuse.
const KEPT_TARGETS: usize = 4;
/// Parameter blocks start at multiples of this (the spec's upper bound on the device limit).
const BLOCK_ALIGNMENT: usize = 256;

fn vk_format(f: Format) -> vk::Format {
    match f {
        Format::Rgba8 => vk::Format::R8G8B8A8_UNORM,
        Format::R32F => vk::Format::R32_SFLOAT,
        Format::R8 => vk::Format::R8_UNORM,
        Format::R32Ui => vk::Format::R32_UINT,
        Format::R8Ui => vk::Format::R8_UINT,
        Format::Rgba32F => vk::Format::R32G32B32A32_SFLOAT,
    }
}

/// Binding of storage image k (shaders/common/bindings.glsl).
const STORAGE_IMAGE_BASE: u32 = 8;
/// Binding of storage buffer k.
const STORAGE_BUFFER_BASE: u32 = 12;

/// Binding counts of a step: sampled images, storage images, storage buffers.
type Counts = (usize, usize, usize);

/// A descriptor set layout (UBO + the counts' bindings) and its pipeline layout.
struct Layout {
    counts: Counts,
    set: vk::DescriptorSetLayout,
    pipeline: vk::PipelineLayout,
}

/// The depth test of a graphics pipeline: compare op and GL's NDC depth range.
type DepthKey = Option<(vk::CompareOp, bool)>;

fn depth_key(conv: Option<crate::pass::Conventions>) -> DepthKey {
    conv.map(|c| {
        // As the GL executor's DrawState::depth_tested: LEQUAL, GEQUAL under reversed-Z, with
        // depth clamp (set by the pipeline when a depth test is on).
        let op = if c.reversed_z {
            vk::CompareOp::GREATER_OR_EQUAL
        } else {
            vk::CompareOp::LESS_OR_EQUAL
        };
        (op, c.ndc_depth == crate::convention::NdcDepthRange::MinusOneToOne)
    })
}

/// A target's colour attachments and its depth buffer, if any.
struct CachedTarget {
    key: (u32, u32, Vec<Option<Format>>, bool),
    color: ColorTargets,
    depth: Option<Image>,
}

struct CachedPipeline {
    program: ShaderProgram,
    depth: DepthKey,
    /// The target's outputs (graphics pipelines; empty for compute).
    outputs: Vec<Option<Format>>,
    counts: Counts,
    pipeline: Pipeline,
}

/// An image on the device and the layout it is kept in.
struct StoredImage {
    image: Image,
    layout: vk::ImageLayout,
    format: Format,
}

/// Passes on a Vulkan device.
pub struct VkExecutor {
    vk: Vk,
    sampler: vk::Sampler,
    layouts: Vec<Layout>,
    pipelines: Vec<CachedPipeline>,
    targets: Vec<CachedTarget>,
    images: Slots<StoredImage>,
    buffers: Slots<Buffer>,
    /// Submissions, reused once waited for; a ticket is a flight's index.
    flights: Vec<Flight>,
    /// The flight the next submit uses (image writes are queued into it first).
    open: Option<usize>,
    /// Objects freed while runs were in flight, each with the last run submitted before it
    /// was freed: dropped once every run up to that one has been waited for. (Dropping only
    /// when no run at all was in flight kept every grave of a stream that always keeps one in
    /// flight: memory grew with every frame.)
    graveyard: Vec<(u64, Grave)>,
    /// Runs submitted so far (a flight's `serial` is its run's number).
    submitted: u64,
}

/// An object a run in flight may still use.
#[allow(dead_code)] // held only to be dropped later
enum Grave {
    Image(StoredImage),
    Buffer(Buffer),
    Target(CachedTarget),
}

fn bindings((samplers, images, buffers): Counts) -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
    let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT | vk::ShaderStageFlags::COMPUTE;
    let one = |binding: u32, ty: vk::DescriptorType| {
        vk::DescriptorSetLayoutBinding::default()
            .binding(binding)
            .descriptor_type(ty)
            .descriptor_count(1)
            .stage_flags(stages)
    };
    // The parameter block is a storage buffer (see PARAM_BLOCK in shaders/common/vulkan.glsl).
    let mut b = vec![one(0, vk::DescriptorType::STORAGE_BUFFER)];
    b.extend((1..=samplers as u32).map(|i| one(i, vk::DescriptorType::COMBINED_IMAGE_SAMPLER)));
    b.extend((0..images as u32).map(|i| one(STORAGE_IMAGE_BASE + i, vk::DescriptorType::STORAGE_IMAGE)));
    b.extend((0..buffers as u32).map(|i| one(STORAGE_BUFFER_BASE + i, vk::DescriptorType::STORAGE_BUFFER)));
    b
}

/// What a draw or dispatch binds, backend-neutral.
struct Binds<'a> {
    program: ShaderProgram,
    params: &'a [u8],
    images: &'a [ImageId],
    storage_images: &'a [StorageImage],
    buffers: &'a [BufferId],
}

impl<'a> Binds<'a> {
    fn of(step: &'a Step) -> Option<Binds<'a>> {
        match step {
            Step::Draw(d) => Some(Binds {
                program: d.program,
                params: d.params,
                images: d.images,
                storage_images: &[],
                buffers: d.buffers,
            }),
            Step::Dispatch(d) => Some(Binds {
                program: d.program,
                params: d.params,
                images: d.images,
                storage_images: d.storage_images,
                buffers: d.buffers,
            }),
            _ => None,
        }
    }

    fn counts(&self) -> Counts {
        (self.images.len(), self.storage_images.len(), self.buffers.len())
    }
}

impl VkExecutor {
    /// An executor on `vk`.
    pub fn new(vk: &Vk) -> Result<Self> {
        let (sampler, set) = sampler_and_set_layout(vk, &bindings((0, 0, 0)))?;
        let mut me = VkExecutor {
            vk: vk.clone(),
            sampler,
            layouts: Vec::new(),
            pipelines: Vec::new(),
            targets: Vec::new(),
            images: Slots::default(),
            buffers: Slots::default(),
            flights: Vec::new(),
            open: None,
            graveyard: Vec::new(),
            submitted: 0,
        };
        me.push_layout((0, 0, 0), set)?;
        Ok(me)
    }

    /// A [`crate::pass::Device`] running on `vk`.
    pub fn device(vk: &Vk) -> Result<crate::pass::Device> {
        Ok(crate::pass::Device::new(VkExecutor::new(vk)?))
    }

    fn push_layout(&mut self, counts: Counts, set: vk::DescriptorSetLayout) -> Result<usize> {
        let sets = [set];
        // SAFETY: plain object creation; on failure the set layout, owned by no one yet, goes.
        let pipeline = unsafe {
            match self
                .vk
                .device
                .create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().set_layouts(&sets), None)
            {
                Ok(p) => p,
                Err(r) => {
                    self.vk.device.destroy_descriptor_set_layout(set, None);
                    return Err(vk_err("vkCreatePipelineLayout")(r));
                }
            }
        };
        self.layouts.push(Layout { counts, set, pipeline });
        Ok(self.layouts.len() - 1)
    }

    fn layout(&mut self, counts: Counts) -> Result<usize> {
        if let Some(i) = self.layouts.iter().position(|l| l.counts == counts) {
            return Ok(i);
        }
        let b = bindings(counts);
        // SAFETY: plain object creation; handed to push_layout, which owns it from then on.
        let set = unsafe {
            self.vk
                .device
                .create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&b), None)
                .map_err(vk_err("vkCreateDescriptorSetLayout"))?
        };
        self.push_layout(counts, set)
    }

    /// The pipeline (graphics with `target`'s outputs, or compute) and layout of a step.
    fn pipeline(
        &mut self,
        binds: &Binds,
        outputs: Option<&[Option<Format>]>,
        depth: DepthKey,
    ) -> Result<(usize, usize)> {
        let counts = binds.counts();
        if counts.0 > MAX_SAMPLED {
            return Err(Error::Vulkan(format!(
                "{}: more than {MAX_SAMPLED} sampled images",
                binds.program.kind.name()
            )));
        }
        let layout = self.layout(counts)?;
        let outputs_key = outputs.map_or(Vec::new(), <[_]>::to_vec);
        let found = self.pipelines.iter().position(|p| {
            p.program == binds.program && p.outputs == outputs_key && p.counts == counts && p.depth == depth
        });
        if let Some(i) = found {
            return Ok((i, layout));
        }
        if !binds.program.kind.on_vulkan() {
            return Err(Error::Vulkan(format!(
                "{} is not compiled for Vulkan (shaders/programs.rs)",
                binds.program.kind.name()
            )));
        }
        let preamble = binds.program.preamble();
        let raw_layout = self.layouts[layout].pipeline;
        let pipeline = match outputs {
            Some(outputs) => {
                let formats: Vec<vk::Format> = outputs
                    .iter()
                    .map(|f| f.map_or(vk::Format::UNDEFINED, vk_format))
                    .collect();
                let desc = PipelineDesc {
                    program: binds.program.kind.name(),
                    preamble: &preamble,
                    color_formats: &formats,
                    depth: depth.map(|(op, _)| op),
                    ndc_minus_one_to_one: depth.is_some_and(|(_, gl_range)| gl_range),
                };
                Pipeline::new(&self.vk, raw_layout, &desc)?
            }
            None => Pipeline::compute(&self.vk, raw_layout, binds.program.kind.name(), &preamble)?,
        };
        self.vk.name(pipeline.raw, binds.program.kind.name());
        self.pipelines.push(CachedPipeline {
            program: binds.program,
            depth,
            outputs: outputs_key,
            counts,
            pipeline,
        });
        Ok((self.pipelines.len() - 1, layout))
    }

    fn target(&mut self, t: &Target) -> Result<usize> {
        let key = (t.width, t.height, t.outputs.clone(), t.depth_test.is_some());
        if let Some(i) = self.targets.iter().position(|c| c.key == key) {
            return Ok(i);
        }
        if self.targets.len() >= KEPT_TARGETS {
            let old = self.targets.remove(0);
            self.bury(Grave::Target(old));
        }
        let formats: Vec<Option<vk::Format>> = t.outputs.iter().map(|f| f.map(vk_format)).collect();
        let color = ColorTargets::with_slots(&self.vk, t.width, t.height, &formats)?;
        let depth = t
            .depth_test
            .map(|_| {
                Image::new(
                    &self.vk,
                    t.width,
                    t.height,
                    super::pipeline::DEPTH_FORMAT,
                    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                )
            })
            .transpose()?;
        self.targets.push(CachedTarget { key, color, depth });
        Ok(self.targets.len() - 1)
    }

    /// Keep `grave` until every run submitted so far has been waited for (dropped at once
    /// when none is in flight).
    fn bury(&mut self, grave: Grave) {
        if self.flights.iter().any(|f| f.busy) {
            self.graveyard.push((self.submitted, grave));
        }
        self.sweep();
    }

    /// Drop the graves no run in flight can still use: those freed after the oldest busy run
    /// was submitted are kept, the rest go.
    fn sweep(&mut self) {
        match self.flights.iter().filter(|f| f.busy).map(|f| f.serial).min() {
            Some(oldest) => self.graveyard.retain(|(last, _)| *last >= oldest),
            None => self.graveyard.clear(),
        }
    }

    /// The flight the next submit uses: the open one, else a free one, else a new one.
    fn open_flight(&mut self) -> Result<usize> {
        if let Some(i) = self.open {
            return Ok(i);
        }
        let i = match self.flights.iter().position(|f| !f.busy) {
            Some(i) => i,
            None => {
                self.flights.push(Flight::new(&self.vk)?);
                self.flights.len() - 1
            }
        };
        let f = &mut self.flights[i];
        f.writes.clear();
        f.staging_used = 0;
        self.open = Some(i);
        Ok(i)
    }

    fn stored(&self, id: ImageId, program: &str) -> Result<&StoredImage> {
        self.images
            .get(id.0)
            .ok_or_else(|| Error::Vulkan(format!("{program}: image {} was freed", id.0)))
    }

    fn buffer(&self, id: BufferId) -> Result<&Buffer> {
        self.buffers
            .get(id.0)
            .ok_or_else(|| Error::Vulkan(format!("pass buffer {} was freed", id.0)))
    }

    fn store_image(&mut self, stored: StoredImage) -> ImageId {
        ImageId(self.images.insert(stored))
    }

    /// One descriptor set for a step: its block at `offset`, images, storage images, buffers.
    fn write_set(
        &self,
        pool: vk::DescriptorPool,
        binds: &Binds,
        layout: usize,
        params: (vk::Buffer, u64, u64),
        target: Option<&ColorTargets>,
    ) -> Result<vk::DescriptorSet> {
        let d = &self.vk.device;
        let name = binds.program.kind.name();
        let layouts = [self.layouts[layout].set];
        // SAFETY: the pool has room for one set per step (reset_pool); the writes reference
        // locals that outlive the call, and objects that live until the submit is waited for.
        unsafe {
            let set = d
                .allocate_descriptor_sets(
                    &vk::DescriptorSetAllocateInfo::default()
                        .descriptor_pool(pool)
                        .set_layouts(&layouts),
                )
                .map_err(vk_err("vkAllocateDescriptorSets"))?[0];
            let buffer_info = [vk::DescriptorBufferInfo::default()
                .buffer(params.0)
                .offset(params.1)
                .range(params.2)];
            let sampled = binds
                .images
                .iter()
                .map(|id| {
                    let s = self.stored(*id, name)?;
                    Ok([vk::DescriptorImageInfo::default()
                        .sampler(self.sampler)
                        .image_view(s.image.view)
                        .image_layout(s.layout)])
                })
                .collect::<Result<Vec<_>>>()?;
            let storage = binds
                .storage_images
                .iter()
                .map(|s| {
                    let view = match s {
                        StorageImage::Image(id) => self.stored(*id, name)?.image.view,
                        StorageImage::Output(i) => target
                            .and_then(|t| t.view(*i))
                            .ok_or_else(|| Error::Vulkan(format!("{name}: no output {i} to store to")))?,
                    };
                    Ok([vk::DescriptorImageInfo::default()
                        .image_view(view)
                        .image_layout(vk::ImageLayout::GENERAL)])
                })
                .collect::<Result<Vec<_>>>()?;
            let buffers = binds
                .buffers
                .iter()
                .map(|id| {
                    let b = self.buffer(*id)?;
                    Ok([vk::DescriptorBufferInfo::default()
                        .buffer(b.raw)
                        .offset(0)
                        .range(vk::WHOLE_SIZE)])
                })
                .collect::<Result<Vec<_>>>()?;
            let mut writes = vec![vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(0)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .buffer_info(&buffer_info)];
            for (i, info) in sampled.iter().enumerate() {
                writes.push(
                    vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(i as u32 + 1)
                        .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                        .image_info(info),
                );
            }
            for (i, info) in storage.iter().enumerate() {
                writes.push(
                    vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(STORAGE_IMAGE_BASE + i as u32)
                        .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                        .image_info(info),
                );
            }
            for (i, info) in buffers.iter().enumerate() {
                writes.push(
                    vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(STORAGE_BUFFER_BASE + i as u32)
                        .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                        .buffer_info(info),
                );
            }
            d.update_descriptor_sets(&writes, &[]);
            Ok(set)
        }
    }
}

/// Every earlier write (shader, transfer, attachment) before every later access.
fn full_barrier(d: &ash::Device, cb: vk::CommandBuffer) {
    let all = vk::MemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
        .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE);
    // SAFETY: recording into `cb` outside any rendering.
    unsafe {
        d.cmd_pipeline_barrier(
            cb,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::DependencyFlags::empty(),
            &[all],
            &[],
            &[],
        )
    }
}

impl Executor for VkExecutor {
    fn api(&self) -> Api {
        Api::Vulkan
    }

    fn max_image_side(&self) -> u32 {
        self.vk.info().max_image_dimension_2d
    }

    fn upload(&mut self, image: &ImageData) -> Result<ImageId> {
        let img = sampled_image(
            &self.vk,
            image.width,
            image.height,
            vk_format(image.format),
            image.bytes,
        )?;
        self.vk.name(img.raw, image.label);
        Ok(self.store_image(StoredImage {
            image: img,
            layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            format: image.format,
        }))
    }

    fn create_image(&mut self, width: u32, height: u32, format: Format, label: &str) -> Result<ImageId> {
        use vk::ImageUsageFlags as U;
        let usage = U::SAMPLED | U::STORAGE | U::TRANSFER_DST | U::TRANSFER_SRC;
        let image = Image::new(&self.vk, width, height, vk_format(format), usage)?;
        self.vk.name(image.raw, label);
        // Kept in GENERAL for its whole life: sampled, stored and cleared there.
        self.vk.run_commands(|cb| {
            image.transition(
                cb,
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::GENERAL,
                vk::PipelineStageFlags::TOP_OF_PIPE,
                vk::AccessFlags::empty(),
                vk::PipelineStageFlags::ALL_COMMANDS,
                vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE,
            )
        })?;
        Ok(self.store_image(StoredImage {
            image,
            layout: vk::ImageLayout::GENERAL,
            format,
        }))
    }

    fn free(&mut self, id: ImageId) {
        if let Some(image) = self.images.take(id.0) {
            self.bury(Grave::Image(image));
        }
        // Writes still queued for it must not land in the next image given its id.
        for f in &mut self.flights {
            f.writes.retain(|(w, _)| *w != id);
        }
    }

    fn create_buffer(&mut self, words: usize, label: &str) -> Result<BufferId> {
        use vk::BufferUsageFlags as U;
        let b = Buffer::new(
            &self.vk,
            words * 4,
            U::STORAGE_BUFFER | U::INDIRECT_BUFFER | U::TRANSFER_DST,
        )?;
        self.vk.name(b.raw, label);
        Ok(BufferId(self.buffers.insert(b)))
    }

    fn free_buffer(&mut self, id: BufferId) {
        if let Some(buffer) = self.buffers.take(id.0) {
            self.bury(Grave::Buffer(buffer));
        }
    }

    fn upload_indices(&mut self, indices: &[u32], label: &str) -> Result<BufferId> {
        let bytes: &[u8] = bytemuck::cast_slice(indices);
        let b = Buffer::new(&self.vk, bytes.len(), vk::BufferUsageFlags::INDEX_BUFFER)?;
        b.write(bytes);
        self.vk.name(b.raw, label);
        Ok(BufferId(self.buffers.insert(b)))
    }

    fn write_image(&mut self, id: ImageId, bytes: &[u8]) -> Result<()> {
        let stored = self
            .images
            .get(id.0)
            .ok_or_else(|| Error::Vulkan(format!("write_image: image {} was freed", id.0)))?;
        let need = stored.image.width as usize * stored.image.height as usize * stored.format.texel_bytes();
        if stored.layout != vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL {
            return Err(Error::Vulkan(format!(
                "write_image: image {} was created for storage, not uploaded",
                id.0
            )));
        }
        if bytes.len() != need {
            return Err(Error::Vulkan(format!(
                "write_image: {} bytes for an uploaded image of {need}",
                bytes.len()
            )));
        }
        // Into the next submission's own staging arena: runs in flight keep reading theirs.
        let f = self.open_flight()?;
        let offset = self.flights[f].stage(bytes)?;
        self.flights[f].writes.push((id, offset));
        Ok(())
    }

    fn renderer(&self) -> String {
        format!("Vulkan: {}", self.vk.info().name)
    }

    fn submit(&mut self, target: Option<&Target>, steps: &[Step]) -> Result<Ticket> {
        let f = self.open_flight()?;
        self.record_flight(f, target, steps)?;
        // Submitted with the writes queued for it; on an error they stay queued for the next.
        self.open = None;
        Ok(Ticket(f))
    }

    fn is_ready(&mut self, ticket: Ticket) -> bool {
        self.flights.get(ticket.0).is_none_or(Flight::finished)
    }

    fn wait(&mut self, ticket: Ticket) -> Result<Rendered> {
        let f = self
            .flights
            .get_mut(ticket.0)
            .filter(|f| f.busy)
            .ok_or_else(|| Error::Vulkan(format!("pass run {} was not submitted or was waited for", ticket.0)))?;
        let waited = f.wait_fence();
        f.busy = false;
        waited?;
        let outputs = (0..f.outputs.len())
            .map(|i| f.read_output(i))
            .collect::<Result<Vec<_>>>()?;
        let timing = Timing {
            gpu_ms: None,
            wall_ms: f.submit_ms,
        };
        self.sweep();
        Ok(Rendered {
            outputs,
            timing,
            size: (0, 0),
            api: Api::Vulkan,
        })
    }
}

impl VkExecutor {
    /// Record `steps` (after the writes queued for it) into flight `f` and submit it.
    fn record_flight(&mut self, f: usize, target: Option<&Target>, steps: &[Step]) -> Result<()> {
        let t0 = Instant::now();
        // Pipelines and layouts, then the target.
        let mut chosen = Vec::with_capacity(steps.len());
        for step in steps {
            chosen.push(match Binds::of(step) {
                Some(b) => {
                    let outputs = match step {
                        Step::Draw(_) => Some(
                            target
                                .ok_or_else(|| Error::Vulkan("a draw without a target".into()))?
                                .outputs
                                .as_slice(),
                        ),
                        _ => None,
                    };
                    Some(self.pipeline(&b, outputs, depth_key(target.and_then(|t| t.depth_test)))?)
                }
                None => None,
            });
        }
        let t = target.map(|t| self.target(t)).transpose()?;
        // Every step's block at its aligned offset in one buffer (grown when needed).
        let block_bytes = steps
            .iter()
            .filter_map(Binds::of)
            .map(|b| b.params.len().max(16))
            .max()
            .unwrap_or(16);
        let slot = block_bytes.div_ceil(BLOCK_ALIGNMENT) * BLOCK_ALIGNMENT;
        let total = slot * steps.len().max(1);
        let mut blocks = vec![0u8; total];
        for (k, b) in steps
            .iter()
            .enumerate()
            .filter_map(|(k, s)| Binds::of(s).map(|b| (k, b)))
        {
            blocks[k * slot..k * slot + b.params.len()].copy_from_slice(b.params);
        }
        // The flight is not in flight, so its buffers are free to overwrite.
        let params = self.flights[f].params(total)?;
        params.write(&blocks);
        let params_raw = params.raw;
        self.flights[f].reset_pool(steps.len())?;
        match target {
            Some(t) => self.flights[f].readback(t.width, t.height, &t.outputs)?,
            None => self.flights[f].readback(0, 0, &[])?,
        }
        self.flights[f].rows = target.map_or(crate::convention::RowOrder::TopDown, |t| t.rows);
        let pool = self.flights[f].pool;
        let targets = t.map(|t| &self.targets[t].color);
        let depth_image = t.and_then(|t| self.targets[t].depth.as_ref());
        let clear_depth = target
            .and_then(|t| t.depth_test)
            .map_or(1.0, |c| c.clear_depth() as f32);
        let mut sets = Vec::with_capacity(steps.len());
        for (k, step) in steps.iter().enumerate() {
            sets.push(match (Binds::of(step), chosen[k]) {
                (Some(b), Some((_, layout))) => Some(self.write_set(
                    pool,
                    &b,
                    layout,
                    (params_raw, (k * slot) as u64, block_bytes as u64),
                    targets,
                )?),
                _ => None,
            });
        }
        // Raw handles the recording needs (checked above).
        let mut raw_steps = Vec::with_capacity(steps.len());
        for step in steps {
            raw_steps.push(match step {
                Step::Clear { image, bits } => {
                    let s = self.stored(*image, "clear")?;
                    Some((s.image.raw, s.format, *bits))
                }
                _ => None,
            });
        }
        let buffer_raw = |id: BufferId| -> Result<vk::Buffer> { Ok(self.buffer(id)?.raw) };
        // Indirect and written buffers resolved before recording.
        let mut step_buffers = Vec::with_capacity(steps.len());
        for step in steps {
            step_buffers.push(match step {
                Step::WriteBuffer { buffer, .. } => Some(buffer_raw(*buffer)?),
                Step::Dispatch(Dispatch {
                    groups: Groups::Indirect { buffer, .. },
                    ..
                }) => Some(buffer_raw(*buffer)?),
                _ => None,
            });
        }
        let mut index_buffers = Vec::with_capacity(steps.len());
        for step in steps {
            index_buffers.push(match step {
                Step::Draw(draw) => match draw.indices {
                    Some(id) => {
                        let b = self.buffer(id)?;
                        if b.size < 12 * draw.triangles as usize {
                            return Err(Error::Vulkan(format!(
                                "{}: {} triangles from {} bytes of indices",
                                draw.program.kind.name(),
                                draw.triangles,
                                b.size
                            )));
                        }
                        Some(b.raw)
                    }
                    None => None,
                },
                _ => None,
            });
        }
        // The image writes queued for this run.
        let mut writes = Vec::with_capacity(self.flights[f].writes.len());
        for &(id, offset) in &self.flights[f].writes {
            writes.push((&self.stored(id, "write_image")?.image, offset));
        }
        let d = &self.vk.device;
        let pipelines = &self.pipelines;
        let layouts = &self.layouts;
        let flight = &self.flights[f];
        let destinations: Vec<Option<&Buffer>> = flight.readback.iter().map(Option::as_ref).collect();
        self.vk.submit_commands(flight.cb, flight.fence, |cb| {
            // Runs before this one (other flights) used the same attachments and images.
            full_barrier(d, cb);
            if let Some(staging) = &flight.staging {
                for (image, offset) in &writes {
                    image.record_upload_at(cb, staging, *offset);
                }
            }
            let mut rendering = false;
            if let (Some(targets), false) = (targets, steps.iter().any(|s| matches!(s, Step::Draw(_)))) {
                // No draws (no kept triangles, or compute steps storing to the outputs): the
                // target is still cleared, before the steps so that what they store survives.
                targets.record_begin(cb, None);
                targets.record_end_to_general(cb);
            }
            for (k, step) in steps.iter().enumerate() {
                let draw = matches!(step, Step::Draw(_));
                if rendering && !draw {
                    targets.expect("draws have a target").record_end_to_general(cb);
                    rendering = false;
                }
                if k > 0 && !(draw && matches!(steps[k - 1], Step::Draw(_))) {
                    full_barrier(d, cb);
                }
                // SAFETY: recording into `cb`; every handle lives until the submit has been
                // waited for; draws inside the rendering begun here, the rest outside it.
                unsafe {
                    match step {
                        Step::Clear { .. } => {
                            let (image, format, bits) = raw_steps[k].expect("resolved above");
                            let value = match format {
                                Format::R32Ui => vk::ClearColorValue { uint32: [bits; 4] },
                                _ => vk::ClearColorValue {
                                    float32: [f32::from_bits(bits); 4],
                                },
                            };
                            d.cmd_clear_color_image(
                                cb,
                                image,
                                vk::ImageLayout::GENERAL,
                                &value,
                                &[super::resources::range(vk::ImageAspectFlags::COLOR)],
                            );
                        }
                        Step::WriteBuffer { words, .. } => {
                            let buffer = step_buffers[k].expect("resolved above");
                            d.cmd_update_buffer(cb, buffer, 0, bytemuck::cast_slice(words));
                        }
                        Step::Draw(draw) => {
                            let targets = targets.expect("draws have a target");
                            if !rendering {
                                let attachment =
                                    depth_image.map(|dpt| super::targets::depth_attachment(cb, dpt, clear_depth));
                                targets.record_begin(cb, attachment.as_ref());
                                rendering = true;
                            }
                            let (p, l) = chosen[k].expect("chosen above");
                            let [x, y, w, h] = draw.viewport;
                            let viewport = vk::Viewport {
                                x: x as f32,
                                y: y as f32,
                                width: w as f32,
                                height: h as f32,
                                min_depth: 0.0,
                                max_depth: 1.0,
                            };
                            let scissor = vk::Rect2D {
                                offset: vk::Offset2D {
                                    x: x as i32,
                                    y: y as i32,
                                },
                                extent: vk::Extent2D { width: w, height: h },
                            };
                            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipelines[p].pipeline.raw);
                            d.cmd_bind_descriptor_sets(
                                cb,
                                vk::PipelineBindPoint::GRAPHICS,
                                layouts[l].pipeline,
                                0,
                                &[sets[k].expect("written above")],
                                &[],
                            );
                            d.cmd_set_viewport(cb, 0, &[viewport]);
                            d.cmd_set_scissor(cb, 0, &[scissor]);
                            match index_buffers[k] {
                                Some(indices) => {
                                    d.cmd_bind_index_buffer(cb, indices, 0, vk::IndexType::UINT32);
                                    d.cmd_draw_indexed(cb, 3 * draw.triangles, 1, 0, 0, 0);
                                }
                                None => d.cmd_draw(cb, 3 * draw.triangles, 1, 0, 0),
                            }
                        }
                        Step::Dispatch(dispatch) => {
                            let (p, l) = chosen[k].expect("chosen above");
                            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, pipelines[p].pipeline.raw);
                            d.cmd_bind_descriptor_sets(
                                cb,
                                vk::PipelineBindPoint::COMPUTE,
                                layouts[l].pipeline,
                                0,
                                &[sets[k].expect("written above")],
                                &[],
                            );
                            match dispatch.groups {
                                Groups::Fixed([x, y]) => d.cmd_dispatch(cb, x, y, 1),
                                Groups::Indirect { offset_words, .. } => d.cmd_dispatch_indirect(
                                    cb,
                                    step_buffers[k].expect("resolved above"),
                                    4 * offset_words as u64,
                                ),
                            }
                        }
                    }
                }
            }
            if let Some(targets) = targets {
                if rendering {
                    targets.record_end_to_general(cb);
                }
                full_barrier(d, cb);
                targets.record_readback(cb, &destinations);
            }
        })?;
        let flight = &mut self.flights[f];
        flight.busy = true;
        self.submitted += 1;
        flight.serial = self.submitted;
        flight.submit_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }
}

impl Drop for VkExecutor {
    fn drop(&mut self) {
        // Flights first: each waits for its submission before anything it uses goes.
        self.flights.clear();
        self.graveyard.clear();
        self.pipelines.clear();
        self.targets.clear();
        self.images = Slots::default();
        self.buffers = Slots::default();
        let d = &self.vk.device;
        // SAFETY: owned handles (null ones are ignored by Vulkan); no submit is pending.
        unsafe {
            for l in &self.layouts {
                d.destroy_pipeline_layout(l.pipeline, None);
                d.destroy_descriptor_set_layout(l.set, None);
            }
            d.destroy_sampler(self.sampler, None);
        }
    }
}
