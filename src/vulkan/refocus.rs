//! Refocus on Vulkan: the full-screen and the mesh pass of src/refocus/render.rs and mesh.rs,
//! from the same GLSL (build.rs), with the same inputs: the f64 per-column/row lookups, the
//! coverage flags or kept-triangle codes, the clip matrix and depth coefficients of the
//! conventions. Synchronous: one command buffer per target (lookup uploads, the draw, the
//! copies into host buffers), waited for with a fence.
//!
//! Memory rows mean what they mean under GL: NDC y = -1 lands on memory row 0 in both APIs
//! (GL's window origin is its row 0, Vulkan's framebuffer origin too), so the same clip matrix
//! gives the same memory image and `RowOrder::BottomUp` is flipped on readback as under GL.
//! The GL NDC depth range comes from VK_EXT_depth_clip_control, the GL depth clamp from the
//! rasteriser's depthClampEnable.

use super::context::{vk_err, Vk};
use super::pipeline::{Pipeline, PipelineDesc, DEPTH_FORMAT};
use super::resources::{pool_with_one_set, sampled_image, sampler_and_set_layout, Buffer, Image};
use super::targets::ColorTargets;
use crate::camera::{clip_from_view_opencv, PinholeCamera};
use crate::convention::{Conventions, DepthPlanes, NdcDepthRange};
use crate::error::{Error, Result};
use crate::gpu::Timing;
use crate::gpu::{ProgramKind, ShaderProgram};
use crate::io::{DepthMap, Mask, RgbImage};
use crate::refocus::mesh::{EXPAND_PX, MIN_INTERIOR_SCALE};
use crate::refocus::{axis_lookup, BreakRule, Grid, Method, OutputSet, RefocusOutput, RefocusSource, TRI_TEX_WIDTH};
use ash::vk;
use std::time::Instant;

/// The `#define` preamble the GL backend gives the refocus passes (`ShaderProgram::preamble`,
/// the same for the three refocus programs), which selects the SPIR-V variant.
pub fn preamble(conv: &Conventions, want_rgb: bool) -> String {
    ShaderProgram::new(*conv, ProgramKind::RefocusFullscreen { want_rgb }).preamble()
}

/// Attachment formats, in the fragment shaders' output locations: colour, metric Z, mask.
const COLOR_FORMATS: [vk::Format; 3] = [vk::Format::R8G8B8A8_UNORM, vk::Format::R32_SFLOAT, vk::Format::R8_UNORM];
const TEXEL_BYTES: [usize; 3] = [4, 4, 1];
/// Bytes of the push-constant block (shaders/refocus/vulkan_interface.glsl).
const PUSH_BYTES: usize = 112;
const BINDINGS: u32 = 6;

/// The uploaded source and its geometry.
struct Source {
    camera: PinholeCamera,
    planes: DepthPlanes,
    rgb: Image,
    depth: Image,
    /// Full-screen pass: coverage flags per cell (R8UI).
    keep: Option<Image>,
    /// Mesh pass: interior triangles' vertex indices and count of indices.
    interior: Option<(Buffer, u32)>,
    /// Mesh pass: boundary triangles' codes (R32UI, TRI_TEX_WIDTH wide), and every triangle's
    /// for scales below MIN_INTERIOR_SCALE.
    boundary: Option<Image>,
    all_as_boundary: Option<Image>,
    interior_count: usize,
    boundary_count: usize,
}

/// Attachments, lookup images and host buffers of one output size.
struct Target {
    color: ColorTargets,
    depth: Option<Image>,
    cols: Image,
    rows: Image,
    cols_staging: Buffer,
    rows_staging: Buffer,
}

/// Refocus on one Vulkan device, for one set of settings; any number of sources and targets.
pub struct VkRefocuser {
    vk: Vk,
    conv: Conventions,
    outputs: OutputSet,
    rule: BreakRule,
    method: Method,
    sampler: vk::Sampler,
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    descriptor_pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    /// Full-screen: [pass]; mesh: [interior, boundary].
    pipelines: Vec<Pipeline>,
    /// Bound to the integer sampler a pass declares but does not use (u_keep or u_tris).
    unused_uint: Image,
    source: Option<Source>,
    target: Option<Target>,
}

/// Kept-triangle codes as an R32UI image `TRI_TEX_WIDTH` wide (mesh.rs code_texture).
fn code_image(vk: &Vk, codes: &[u32]) -> Result<Option<Image>> {
    if codes.is_empty() {
        return Ok(None);
    }
    let rows = codes.len().div_ceil(TRI_TEX_WIDTH as usize);
    if rows > vk.info().max_image_dimension_2d as usize
        || codes.len().checked_mul(3).is_none_or(|v| v > u32::MAX as usize)
    {
        return Err(Error::param(
            "source size",
            format!(
                "{} triangles exceed the mesh path's limit; use the full-screen method",
                codes.len()
            ),
        ));
    }
    let mut padded = codes.to_vec();
    padded.resize(rows * TRI_TEX_WIDTH as usize, 0);
    Ok(Some(sampled_image(
        vk,
        TRI_TEX_WIDTH,
        rows as u32,
        vk::Format::R32_UINT,
        bytemuck::cast_slice(&padded),
    )?))
}

impl VkRefocuser {
    /// Build the pipelines for these settings and upload `src`.
    pub fn new(
        vk: &Vk,
        src: &RefocusSource,
        rule: &BreakRule,
        method: Method,
        outputs: OutputSet,
        conv: Conventions,
    ) -> Result<Self> {
        let mut r = VkRefocuser::with_settings(vk, rule, method, outputs, conv)?;
        r.set_source(src)?;
        Ok(r)
    }

    /// Build the pipelines; a source comes with [`VkRefocuser::set_source`].
    pub fn with_settings(
        vk: &Vk,
        rule: &BreakRule,
        method: Method,
        outputs: OutputSet,
        conv: Conventions,
    ) -> Result<Self> {
        rule.validate()?;
        let d = &vk.device;
        let unused_uint = sampled_image(vk, 1, 1, vk::Format::R32_UINT, &[0; 4])?;
        let bindings: Vec<_> = (0..BINDINGS)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
            })
            .collect();
        // Owned by the returned value, whose Drop destroys them (on an error below, the partly
        // built value is dropped the same way).
        let (sampler, set_layout) = sampler_and_set_layout(vk, &bindings)?;
        let mut me = VkRefocuser {
            vk: vk.clone(),
            conv,
            outputs,
            rule: *rule,
            method,
            sampler,
            set_layout,
            layout: vk::PipelineLayout::null(),
            descriptor_pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            pipelines: Vec::new(),
            unused_uint,
            source: None,
            target: None,
        };
        // SAFETY: as above; handles stored in `me` as soon as they exist.
        unsafe {
            let layouts = [set_layout];
            let push = [vk::PushConstantRange::default()
                .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
                .size(PUSH_BYTES as u32)];
            me.layout = d
                .create_pipeline_layout(
                    &vk::PipelineLayoutCreateInfo::default()
                        .set_layouts(&layouts)
                        .push_constant_ranges(&push),
                    None,
                )
                .map_err(vk_err("vkCreatePipelineLayout"))?;
            let sizes = [vk::DescriptorPoolSize::default()
                .ty(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                .descriptor_count(BINDINGS)];
            (me.descriptor_pool, me.set) = pool_with_one_set(vk, &sizes, set_layout)?;
        }
        let preamble = preamble(&conv, outputs.rgb);
        let depth_op = if conv.reversed_z {
            vk::CompareOp::GREATER_OR_EQUAL
        } else {
            vk::CompareOp::LESS_OR_EQUAL
        };
        let programs: &[&str] = match method {
            Method::Fullscreen => &["refocus/fullscreen"],
            Method::Mesh => &["refocus/mesh_interior", "refocus/mesh_boundary"],
        };
        for program in programs {
            let desc = PipelineDesc {
                program,
                preamble: &preamble,
                color_formats: &COLOR_FORMATS,
                depth: (method == Method::Mesh).then_some(depth_op),
                ndc_minus_one_to_one: method == Method::Mesh && conv.ndc_depth == NdcDepthRange::MinusOneToOne,
            };
            me.pipelines.push(Pipeline::new(vk, me.layout, &desc)?);
        }
        Ok(me)
    }

    /// The device this refocuser renders on.
    pub fn vk(&self) -> &Vk {
        &self.vk
    }

    /// Upload a new source (replacing the previous one).
    pub fn set_source(&mut self, src: &RefocusSource) -> Result<()> {
        src.validate()?;
        let vk = self.vk.clone();
        let (w, h) = (src.rgb.width, src.rgb.height);
        // As under GL: (w + 1) x (h + 1) cells are texels of one image.
        let limit = vk.info().max_image_dimension_2d.saturating_sub(1);
        crate::gpu::check_image_size("source size", w.into(), h.into(), limit)?;
        self.source = None;
        let grid = Grid { width: w, height: h };
        let keep = grid.keep_mask(&src.depth.data, &self.rule);
        let rgba = crate::gpu::pixels::rgb_to_rgba(&src.rgb.data);
        let rgb = sampled_image(&vk, w, h, vk::Format::R8G8B8A8_UNORM, &rgba)?;
        let depth = sampled_image(&vk, w, h, vk::Format::R32_SFLOAT, bytemuck::cast_slice(&src.depth.data))?;
        let mut source = Source {
            camera: src.camera(),
            // As render.rs: every kept vertex lies in [min, max] of the valid depths, with room
            // for the pushed-out border of boundary triangles.
            planes: match src.depth_range() {
                Some((lo, hi)) => DepthPlanes {
                    near: 0.25 * lo,
                    far: 4.0 * hi,
                },
                None => DepthPlanes { near: 1.0, far: 2.0 },
            },
            rgb,
            depth,
            keep: None,
            interior: None,
            boundary: None,
            all_as_boundary: None,
            interior_count: 0,
            boundary_count: 0,
        };
        match self.method {
            Method::Fullscreen => {
                let flags = grid.coverage_flags(&keep);
                let (cx, cy) = (grid.cells_x() as u32, grid.cells_y() as u32);
                source.keep = Some(sampled_image(&vk, cx, cy, vk::Format::R8_UINT, &flags)?);
            }
            Method::Mesh => {
                let (interior, boundary) = grid.split_kept_triangles(&keep);
                let indices: Vec<u32> = interior.iter().flat_map(|&c| grid.triangle_vertices(c)).collect();
                if !indices.is_empty() {
                    let bytes: &[u8] = bytemuck::cast_slice(&indices);
                    let buffer = Buffer::new(&vk, bytes.len(), vk::BufferUsageFlags::INDEX_BUFFER)?;
                    buffer.write(bytes);
                    source.interior = Some((buffer, indices.len() as u32));
                    let mut all = boundary.clone();
                    all.extend_from_slice(&interior);
                    source.all_as_boundary = code_image(&vk, &all)?;
                }
                source.boundary = code_image(&vk, &boundary)?;
                source.interior_count = interior.len();
                source.boundary_count = boundary.len();
            }
        }
        self.source = Some(source);
        Ok(())
    }

    /// The target of size w x h, allocated when the size changes.
    fn target(&mut self, w: u32, h: u32) -> Result<&Target> {
        if self
            .target
            .as_ref()
            .is_none_or(|t| (t.color.width, t.color.height) != (w, h))
        {
            self.target = None;
            let vk = &self.vk;
            let color = ColorTargets::new(vk, w, h, &COLOR_FORMATS, &TEXEL_BYTES)?;
            let depth = match self.method {
                Method::Mesh => Some(Image::new(
                    vk,
                    w,
                    h,
                    DEPTH_FORMAT,
                    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                )?),
                Method::Fullscreen => None,
            };
            let lookup = |n: u32| {
                Image::new(
                    vk,
                    n,
                    1,
                    vk::Format::R32G32B32A32_SFLOAT,
                    vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
                )
            };
            let staging = |n: u32| Buffer::new(vk, n as usize * 16, vk::BufferUsageFlags::TRANSFER_SRC);
            self.target = Some(Target {
                color,
                depth,
                cols: lookup(w)?,
                rows: lookup(h)?,
                cols_staging: staging(w)?,
                rows_staging: staging(h)?,
            });
        }
        Ok(self.target.as_ref().expect("allocated above"))
    }

    /// Render `target` (same pose as the source) and read back the requested outputs.
    pub fn render(&mut self, target: &PinholeCamera) -> Result<RefocusOutput> {
        target.validate("target camera")?;
        crate::gpu::check_image_size(
            "output size",
            target.width.into(),
            target.height.into(),
            self.vk.info().max_image_dimension_2d,
        )?;
        let Some(source) = &self.source else {
            return Err(Error::param("refocus source", "no source uploaded (set_source)"));
        };
        let (src_cam, planes) = (source.camera, source.planes);
        let (sk, tk) = (src_cam.k, target.k);
        let cols = axis_lookup(src_cam.width, sk.cx, tk.cx, sk.fx / tk.fx, target.width);
        let rows = axis_lookup(src_cam.height, sk.cy, tk.cy, sk.fy / tk.fy, target.height);
        let (w, h) = (target.width, target.height);
        self.target(w, h)?;
        let t = self.target.as_ref().expect("allocated above");
        let source = self.source.as_ref().expect("checked above");
        t.cols_staging.write(bytemuck::cast_slice(&cols));
        t.rows_staging.write(bytemuck::cast_slice(&rows));

        let conv = self.conv;
        let m = clip_from_view_opencv(target, &planes, &conv);
        let (a, b) = planes.clip_z_coefficients(&conv);
        let push = push_constants(
            &m,
            [sk.fx, sk.fy, sk.cx, sk.cy],
            [src_cam.width, src_cam.height],
            [a, b],
            w,
            h,
        );

        // Integer sampler slot the pass does not use gets a valid dummy.
        let scale = (tk.fx / sk.fx).min(tk.fy / sk.fy);
        let all_pulled = scale < MIN_INTERIOR_SCALE;
        let (pulled, pulled_count) = if all_pulled {
            (
                source.all_as_boundary.as_ref().or(source.boundary.as_ref()),
                source.interior_count + source.boundary_count,
            )
        } else {
            (source.boundary.as_ref(), source.boundary_count)
        };
        let keep = source.keep.as_ref().unwrap_or(&self.unused_uint);
        let tris = pulled.unwrap_or(&self.unused_uint);
        let images = [&source.rgb, &source.depth, keep, &t.cols, &t.rows, tris];
        let infos: Vec<[vk::DescriptorImageInfo; 1]> = images
            .iter()
            .map(|i| {
                [vk::DescriptorImageInfo::default()
                    .sampler(self.sampler)
                    .image_view(i.view)
                    .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)]
            })
            .collect();
        let writes: Vec<_> = infos
            .iter()
            .enumerate()
            .map(|(b, info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(self.set)
                    .dst_binding(b as u32)
                    .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .image_info(info)
            })
            .collect();
        let d = &self.vk.device;
        // SAFETY: the set is not in use (every previous submit was waited for).
        unsafe { d.update_descriptor_sets(&writes, &[]) };

        let t0 = Instant::now();
        let clear_depth = conv.clear_depth() as f32;
        let method = self.method;
        let (pipelines, layout, set) = (&self.pipelines, self.layout, self.set);
        self.vk.run_commands(|cb| {
            t.cols.record_upload(cb, &t.cols_staging);
            t.rows.record_upload(cb, &t.rows_staging);
            let depth_attachment = t
                .depth
                .as_ref()
                .map(|dpt| super::targets::depth_attachment(cb, dpt, clear_depth));
            t.color.record_begin(cb, depth_attachment.as_ref());
            // SAFETY: recording into `cb` inside the rendering; every handle lives until the
            // submit has been waited for.
            unsafe {
                d.cmd_bind_descriptor_sets(cb, vk::PipelineBindPoint::GRAPHICS, layout, 0, &[set], &[]);
                d.cmd_push_constants(
                    cb,
                    layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    &push,
                );
                match method {
                    Method::Fullscreen => {
                        d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipelines[0].raw);
                        d.cmd_draw(cb, 3, 1, 0, 0);
                    }
                    Method::Mesh => {
                        if let (Some((indices, count)), false) = (&source.interior, all_pulled) {
                            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipelines[0].raw);
                            d.cmd_bind_index_buffer(cb, indices.raw, 0, vk::IndexType::UINT32);
                            d.cmd_draw_indexed(cb, *count, 1, 0, 0, 0);
                        }
                        if pulled.is_some() {
                            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, pipelines[1].raw);
                            d.cmd_draw(cb, (pulled_count * 3) as u32, 1, 0, 0);
                        }
                    }
                }
            }
            t.color.record_end_and_readback(cb, &[true; 3]);
        })?;
        let render_ms = t0.elapsed().as_secs_f64() * 1e3;

        let t1 = Instant::now();
        let rows_of = |i: usize| t.color.read_rows(i, conv.row_order);
        let rgb = match self.outputs.rgb {
            true => {
                let rgba = rows_of(0);
                let packed = rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
                Some(RgbImage::new(w, h, packed)?)
            }
            false => None,
        };
        let depth = match self.outputs.depth {
            true => Some(DepthMap::new(w, h, bytemuck::pod_collect_to_vec(&rows_of(1)))?),
            false => None,
        };
        let mask = match self.outputs.mask {
            true => Some(Mask::new(w, h, rows_of(2))?),
            false => None,
        };
        Ok(RefocusOutput {
            camera: *target,
            rgb,
            depth,
            mask,
            render: Timing {
                gpu_ms: None,
                wall_ms: render_ms,
            },
            readback_ms: t1.elapsed().as_secs_f64() * 1e3,
        }
        .finite())
    }
}

/// The push-constant block of vulkan_interface.glsl (std430 offsets there).
fn push_constants(
    m: &[[f64; 4]; 4],
    src_k: [f64; 4],
    src_size: [u32; 2],
    clip_z: [f64; 2],
    w: u32,
    h: u32,
) -> [u8; PUSH_BYTES] {
    let mut out = [0u8; PUSH_BYTES];
    let mut put = |offset: usize, bytes: [u8; 4]| out[offset..offset + 4].copy_from_slice(&bytes);
    // Column-major, as Program::set_mat4_rows uploads it.
    for (r, row) in m.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            put(4 * (c * 4 + r), (*v as f32).to_ne_bytes());
        }
    }
    for (i, v) in src_k.iter().enumerate() {
        put(64 + 4 * i, (*v as f32).to_ne_bytes());
    }
    put(80, (src_size[0] as i32).to_ne_bytes());
    put(84, (src_size[1] as i32).to_ne_bytes());
    put(88, (clip_z[0] as f32).to_ne_bytes());
    put(92, (clip_z[1] as f32).to_ne_bytes());
    put(96, (w as f32).to_ne_bytes());
    put(100, (h as f32).to_ne_bytes());
    put(104, (h as i32).to_ne_bytes());
    put(108, EXPAND_PX.to_ne_bytes());
    out
}

impl Drop for VkRefocuser {
    fn drop(&mut self) {
        let d = &self.vk.device;
        self.pipelines.clear();
        // SAFETY: owned handles (null ones are ignored by Vulkan); no submit is pending.
        unsafe {
            d.destroy_descriptor_pool(self.descriptor_pool, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
            d.destroy_sampler(self.sampler, None);
        }
    }
}
