//! The cyclopean gather pass (methods seed and refine) on Vulkan: src/cyclopean/render.rs's
//! full-screen draw of shaders/cyclopean/gather.frag, from the same GLSL (build.rs) with the
//! same inputs: each eye's colour and depth uploaded in memory row order, the matrices and
//! their inverses computed in f64 on the CPU and handed over as the same f32 numbers (here in a
//! uniform buffer, shaders/cyclopean/vulkan_interface.glsl, instead of loose uniforms).
//! Synchronous: one command buffer per middle view (the draw and the copies into host buffers),
//! waited for with a fence.
//!
//! Memory rows mean what they mean under GL (see refocus.rs): NDC y = -1 and `gl_FragCoord.y`
//! = 0.5 are memory row 0 in both APIs, so the shader sees the same pixels and
//! `RowOrder::BottomUp` images are flipped on upload and readback as under GL. The pass has no
//! depth attachment, so the NDC depth range only enters through the shader's defines.

use super::context::{vk_err, Vk};
use super::pipeline::{Pipeline, PipelineDesc};
use super::resources::{pool_with_one_set, sampled_image, sampler_and_set_layout, Buffer, Image};
use super::targets::ColorTargets;
use crate::camera::mat4::{self, Mat4};
use crate::convention::RowOrder;
use crate::cyclopean::{
    Blend, CyclopeanOutput, CyclopeanOutputs, CyclopeanParams, Eye, EyeInput, FrameDepth, Method, MiddleCamera,
    StereoFrame,
};
use crate::error::{Error, Result};
use crate::gpu::{ProgramKind, ShaderProgram, Timing};
use crate::io::{DepthMap, RgbImage};
use ash::vk;
use std::time::Instant;

/// The program's name in build.rs's SPIR-V table.
const PROGRAM: &str = "cyclopean/gather";
/// Attachment formats, in gather.frag's output locations: colour, middle depth, source bits.
const COLOR_FORMATS: [vk::Format; 3] = [vk::Format::R8G8B8A8_UNORM, vk::Format::R32_SFLOAT, vk::Format::R8_UNORM];
const TEXEL_BYTES: [usize; 3] = [4, 4, 1];
/// Bytes of the uniform block (std140 offsets in vulkan_interface.glsl).
const UNIFORM_BYTES: usize = 792;
/// Bindings 0..3: eye colour and depth (combined image samplers); 4: the uniform block.
const SAMPLERS: u32 = 4;

/// The `#define` preamble the GL backend gives the gather pass for this frame and these
/// parameters (`ShaderProgram::preamble`), which selects the SPIR-V variant.
pub fn preamble(frame: &StereoFrame, params: &CyclopeanParams) -> String {
    ShaderProgram::new(frame.conv, kind(frame, params)).preamble()
}

/// The program's switches, as render.rs picks them.
fn kind(frame: &StereoFrame, params: &CyclopeanParams) -> ProgramKind {
    ProgramKind::CyclopeanGather {
        depth_is_device: frame.depth_kind == FrameDepth::Device,
        refine: matches!(params.method, Method::Refine { .. }),
        blend_soft: params.blend == Blend::Soft,
    }
}

/// One eye on the device: colour (RGBA8) and depth (R32F) in memory row order, and its matrices.
struct EyeImages {
    color: Image,
    depth: Image,
    view: Mat4,
    proj: Mat4,
}

fn upload_eye(vk: &Vk, eye: &EyeInput, rows: RowOrder) -> Result<EyeImages> {
    let (w, h) = (eye.color.width, eye.color.height);
    crate::gpu::check_image_size("eye size", w.into(), h.into(), vk.info().max_image_dimension_2d)?;
    let rgba = crate::gpu::pixels::rgb_to_rgba(&eye.color.data);
    let depth = crate::gpu::pixels::f32_to_bytes(&eye.depth.data);
    Ok(EyeImages {
        color: sampled_image(
            vk,
            w,
            h,
            vk::Format::R8G8B8A8_UNORM,
            &rows.convert_rows(rgba, w as usize * 4),
        )?,
        depth: sampled_image(
            vk,
            w,
            h,
            vk::Format::R32_SFLOAT,
            &rows.convert_rows(depth, w as usize * 4),
        )?,
        view: eye.view,
        proj: eye.proj,
    })
}

/// A stereo frame on a Vulkan device, ready to render middle views with the gather pass.
pub struct VkCyclopean {
    vk: Vk,
    params: CyclopeanParams,
    outputs: CyclopeanOutputs,
    rows: RowOrder,
    sampler: vk::Sampler,
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    descriptor_pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    pipeline: Option<Pipeline>,
    left: EyeImages,
    right: EyeImages,
    uniforms: Buffer,
    target: Option<ColorTargets>,
}

impl VkCyclopean {
    /// All outputs (colour, depth, source bits).
    pub fn new(vk: &Vk, frame: &StereoFrame, params: CyclopeanParams) -> Result<Self> {
        Self::with_outputs(vk, frame, params, CyclopeanOutputs::default())
    }

    /// Only the requested colour/depth read back (the source bits always).
    pub fn with_outputs(
        vk: &Vk,
        frame: &StereoFrame,
        params: CyclopeanParams,
        outputs: CyclopeanOutputs,
    ) -> Result<Self> {
        frame.validate()?;
        params.validate()?;
        let d = &vk.device;
        let rows = frame.conv.row_order;
        let left = upload_eye(vk, &frame.left, rows)?;
        let right = upload_eye(vk, &frame.right, rows)?;
        let uniforms = Buffer::new(vk, UNIFORM_BYTES, vk::BufferUsageFlags::UNIFORM_BUFFER)?;
        let mut bindings: Vec<_> = (0..SAMPLERS)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::FRAGMENT)
            })
            .collect();
        bindings.push(
            vk::DescriptorSetLayoutBinding::default()
                .binding(SAMPLERS)
                .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::FRAGMENT),
        );
        // Owned by the returned value, whose Drop destroys them (on an error below, the partly
        // built value is dropped the same way). The pass reads with texelFetch only.
        let (sampler, set_layout) = sampler_and_set_layout(vk, &bindings)?;
        let mut me = VkCyclopean {
            vk: vk.clone(),
            params,
            outputs,
            rows,
            sampler,
            set_layout,
            layout: vk::PipelineLayout::null(),
            descriptor_pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            pipeline: None,
            left,
            right,
            uniforms,
            target: None,
        };
        // SAFETY: as above; handles stored in `me` as soon as they exist. The descriptor writes
        // reference locals that outlive the call.
        unsafe {
            let layouts = [set_layout];
            me.layout = d
                .create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts), None)
                .map_err(vk_err("vkCreatePipelineLayout"))?;
            let sizes = [
                vk::DescriptorPoolSize::default()
                    .ty(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .descriptor_count(SAMPLERS),
                vk::DescriptorPoolSize::default()
                    .ty(vk::DescriptorType::UNIFORM_BUFFER)
                    .descriptor_count(1),
            ];
            (me.descriptor_pool, me.set) = pool_with_one_set(vk, &sizes, set_layout)?;
            // The eyes and the uniform buffer never change: the set is written once.
            let images = [&me.left.color, &me.right.color, &me.left.depth, &me.right.depth];
            let infos: Vec<[vk::DescriptorImageInfo; 1]> = images
                .iter()
                .map(|i| {
                    [vk::DescriptorImageInfo::default()
                        .sampler(sampler)
                        .image_view(i.view)
                        .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)]
                })
                .collect();
            let buffer_info = [vk::DescriptorBufferInfo::default()
                .buffer(me.uniforms.raw)
                .offset(0)
                .range(UNIFORM_BYTES as u64)];
            let mut writes: Vec<_> = infos
                .iter()
                .enumerate()
                .map(|(b, info)| {
                    vk::WriteDescriptorSet::default()
                        .dst_set(me.set)
                        .dst_binding(b as u32)
                        .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                        .image_info(info)
                })
                .collect();
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(me.set)
                    .dst_binding(SAMPLERS)
                    .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                    .buffer_info(&buffer_info),
            );
            d.update_descriptor_sets(&writes, &[]);
        }
        let preamble = preamble(frame, &params);
        let desc = PipelineDesc {
            program: PROGRAM,
            preamble: &preamble,
            color_formats: &COLOR_FORMATS,
            depth: None,
            ndc_minus_one_to_one: false,
        };
        me.pipeline = Some(Pipeline::new(vk, me.layout, &desc)?);
        Ok(me)
    }

    /// The device this renderer runs on.
    pub fn vk(&self) -> &Vk {
        &self.vk
    }

    /// The attachments and host buffers of size w x h, allocated when the size changes.
    fn target(&mut self, w: u32, h: u32) -> Result<()> {
        if self.target.as_ref().is_none_or(|t| (t.width, t.height) != (w, h)) {
            self.target = None;
            self.target = Some(ColorTargets::new(&self.vk, w, h, &COLOR_FORMATS, &TEXEL_BYTES)?);
        }
        Ok(())
    }

    /// Render the middle view and read back the requested outputs, rows top-down.
    pub fn render(&mut self, mid: &MiddleCamera) -> Result<(CyclopeanOutput, Timing)> {
        let (w, h) = (mid.width, mid.height);
        crate::gpu::check_image_size("middle size", w.into(), h.into(), self.vk.info().max_image_dimension_2d)?;
        let block = uniform_block(&self.left, &self.right, mid, &self.params)?;
        self.target(w, h)?;
        let t0 = Instant::now();
        let t = self.target.as_ref().expect("allocated above");
        // No submit is pending (each is waited for), so the buffer is free to overwrite.
        self.uniforms.write(&block);
        let wanted = [self.outputs.color, self.outputs.depth, true];
        let d = &self.vk.device;
        let (layout, set) = (self.layout, self.set);
        let pipeline = self.pipeline.as_ref().expect("built in new").raw;
        self.vk.run_commands(|cb| {
            t.record_begin(cb, None);
            // SAFETY: recording into `cb` inside the rendering; every handle lives until the
            // submit has been waited for.
            unsafe {
                d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, layout, 0, &[set], &[]);
                d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipeline);
                d.cmd_draw(cb, 3, 1, 0, 0);
            }
            t.record_end_and_readback(cb, &wanted);
        })?;
        let rows_of = |i: usize| t.read_rows(i, self.rows);
        let color = match wanted[0] {
            true => {
                let packed = rows_of(0).chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
                Some(RgbImage::new(w, h, packed)?)
            }
            false => None,
        };
        let depth = match wanted[1] {
            true => Some(DepthMap::new(w, h, bytemuck::pod_collect_to_vec(&rows_of(1)))?),
            false => None,
        };
        let out = CyclopeanOutput {
            color,
            depth,
            sources: rows_of(2),
        };
        let timing = Timing {
            gpu_ms: None,
            wall_ms: t0.elapsed().as_secs_f64() * 1e3,
        };
        Ok((out, timing))
    }
}

/// The uniform block of vulkan_interface.glsl: the values render.rs sets as GL uniforms, in f64
/// until the final f32 rounding, as `Program::set_mat4_rows` and `set_f32` do.
fn uniform_block(
    left: &EyeImages,
    right: &EyeImages,
    mid: &MiddleCamera,
    params: &CyclopeanParams,
) -> Result<[u8; UNIFORM_BYTES]> {
    let inv = |m: &Mat4, what: &str| mat4::inverse(m).ok_or_else(|| Error::param(what.to_string(), "singular"));
    let mut out = [0u8; UNIFORM_BYTES];
    let mut offset = 0;
    let mut mat = |m: &Mat4, out: &mut [u8; UNIFORM_BYTES]| {
        // Column-major, as Program::set_mat4_rows uploads it.
        for (r, row) in m.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                let at = offset + 4 * (c * 4 + r);
                out[at..at + 4].copy_from_slice(&(*v as f32).to_ne_bytes());
            }
        }
        offset += 64;
    };
    for eye in [left, right] {
        mat(&mat4::mul(&eye.proj, &eye.view), &mut out);
        mat(&inv(&eye.view, "eye view")?, &mut out);
        mat(&inv(&eye.proj, "eye projection")?, &mut out);
        mat(&eye.view, &mut out);
    }
    mat(&mid.view, &mut out);
    mat(&inv(&mid.view, "middle view")?, &mut out);
    mat(&inv(&mid.proj, "middle projection")?, &mut out);
    mat(&mat4::mul(&mid.proj, &mid.view), &mut out);
    let w_left = match params.dominant {
        Some((Eye::Left, wt)) => wt,
        Some((Eye::Right, wt)) => 1.0 - wt,
        None => 0.5,
    };
    let mut put = |at: usize, bytes: [u8; 4]| out[at..at + 4].copy_from_slice(&bytes);
    put(768, (mid.width as f32).to_ne_bytes());
    put(772, (mid.height as f32).to_ne_bytes());
    put(776, (params.fixation_distance as f32).to_ne_bytes());
    put(780, (params.z_threshold as f32).to_ne_bytes());
    put(784, (w_left as f32).to_ne_bytes());
    put(788, (params.steps() as i32).to_ne_bytes());
    Ok(out)
}

impl Drop for VkCyclopean {
    fn drop(&mut self) {
        let d = &self.vk.device;
        self.pipeline = None;
        // SAFETY: owned handles (null ones are ignored by Vulkan); no submit is pending.
        unsafe {
            d.destroy_descriptor_pool(self.descriptor_pool, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
            d.destroy_sampler(self.sampler, None);
        }
    }
}
