//! SPIR-V lookup and graphics pipelines. build.rs compiled every shader variant from the GL
//! sources; a pass asks for one by the exact `#define` preamble the GL backend would inject, so
//! both backends run the same text.

use super::context::Vk;
use crate::error::{Error, Result};
use ash::vk;

include!(concat!(env!("OUT_DIR"), "/spirv_variants.rs"));

/// SPIR-V words of `program`'s `stage` ("vert", "frag") compiled with `preamble`.
pub fn spirv(program: &str, stage: &str, preamble: &str) -> Result<Vec<u32>> {
    let (_, _, _, bytes) = SPIRV_VARIANTS
        .iter()
        .find(|(p, s, d, _)| *p == program && *s == stage && *d == preamble)
        .ok_or_else(|| {
            Error::Vulkan(format!(
                "no SPIR-V variant of {program}.{stage} was compiled for the preamble:\n{preamble}\
                 (build.rs and ShaderProgram::preamble disagree)"
            ))
        })?;
    ash::util::read_spv(&mut std::io::Cursor::new(bytes))
        .map_err(|e| Error::Vulkan(format!("{program}.{stage}: malformed SPIR-V: {e}")))
}

/// Fixed-function state of a pass.
pub struct PipelineDesc<'a> {
    pub program: &'a str,
    pub preamble: &'a str,
    pub color_formats: &'a [vk::Format],
    /// Depth attachment, test and write (compare op), with depth clamp.
    pub depth: Option<vk::CompareOp>,
    /// Map NDC z in [-1, 1] to depth (VK_EXT_depth_clip_control), the GL range.
    pub ndc_minus_one_to_one: bool,
}

pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// A graphics pipeline (dynamic rendering, dynamic viewport and scissor, no vertex input).
pub struct Pipeline {
    vk: Vk,
    pub raw: vk::Pipeline,
}

impl Pipeline {
    pub fn new(vk: &Vk, layout: vk::PipelineLayout, desc: &PipelineDesc) -> Result<Pipeline> {
        let d = &vk.device;
        let vert = spirv(desc.program, "vert", desc.preamble)?;
        let frag = spirv(desc.program, "frag", desc.preamble)?;
        // SAFETY: create infos reference locals that outlive the calls; modules are destroyed
        // after pipeline creation on every path.
        unsafe {
            let module = |words: &[u32]| {
                d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(words), None)
                    .map_err(|r| Error::Vulkan(format!("vkCreateShaderModule {}: {r}", desc.program)))
            };
            let vs = module(&vert)?;
            let fs = match module(&frag) {
                Ok(m) => m,
                Err(e) => {
                    d.destroy_shader_module(vs, None);
                    return Err(e);
                }
            };
            let stages = [
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::VERTEX)
                    .module(vs)
                    .name(c"main"),
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::FRAGMENT)
                    .module(fs)
                    .name(c"main"),
            ];
            let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
            let assembly =
                vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
            let mut clip_control =
                vk::PipelineViewportDepthClipControlCreateInfoEXT::default().negative_one_to_one(true);
            let mut viewport = vk::PipelineViewportStateCreateInfo::default()
                .viewport_count(1)
                .scissor_count(1);
            if desc.ndc_minus_one_to_one {
                if !vk.info().depth_clip_control {
                    return Err(Error::Vulkan(format!(
                        "device '{}' lacks VK_EXT_depth_clip_control, needed for the GL NDC depth range (use --ndc vulkan)",
                        vk.info().name
                    )));
                }
                viewport = viewport.push_next(&mut clip_control);
            }
            let raster = vk::PipelineRasterizationStateCreateInfo::default()
                // As the GL mesh pass: no near/far clipping, far surfaces clamp onto the far plane.
                .depth_clamp_enable(desc.depth.is_some())
                .polygon_mode(vk::PolygonMode::FILL)
                .cull_mode(vk::CullModeFlags::NONE)
                .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
                .line_width(1.0);
            let multisample =
                vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
            let depth_stencil = vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(desc.depth.is_some())
                .depth_write_enable(desc.depth.is_some())
                .depth_compare_op(desc.depth.unwrap_or(vk::CompareOp::ALWAYS))
                .min_depth_bounds(0.0)
                .max_depth_bounds(1.0);
            let blend: Vec<_> = desc
                .color_formats
                .iter()
                .map(|_| {
                    vk::PipelineColorBlendAttachmentState::default()
                        .blend_enable(false)
                        .color_write_mask(vk::ColorComponentFlags::RGBA)
                })
                .collect();
            let color_blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend);
            let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
            let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
            let mut rendering = vk::PipelineRenderingCreateInfo::default()
                .color_attachment_formats(desc.color_formats)
                .depth_attachment_format(if desc.depth.is_some() {
                    DEPTH_FORMAT
                } else {
                    vk::Format::UNDEFINED
                });
            let info = vk::GraphicsPipelineCreateInfo::default()
                .stages(&stages)
                .vertex_input_state(&vertex_input)
                .input_assembly_state(&assembly)
                .viewport_state(&viewport)
                .rasterization_state(&raster)
                .multisample_state(&multisample)
                .depth_stencil_state(&depth_stencil)
                .color_blend_state(&color_blend)
                .dynamic_state(&dynamic)
                .layout(layout)
                .push_next(&mut rendering);
            let result = d.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None);
            d.destroy_shader_module(vs, None);
            d.destroy_shader_module(fs, None);
            let raw =
                result.map_err(|(_, r)| Error::Vulkan(format!("vkCreateGraphicsPipelines {}: {r}", desc.program)))?[0];
            vk.count(super::context::Created::Pipeline);
            Ok(Pipeline { vk: vk.clone(), raw })
        }
    }
}

impl Pipeline {
    /// A compute pipeline of `program`'s `comp` stage compiled with `preamble`.
    pub fn compute(vk: &Vk, layout: vk::PipelineLayout, program: &str, preamble: &str) -> Result<Pipeline> {
        let d = &vk.device;
        let words = spirv(program, "comp", preamble)?;
        // SAFETY: create infos reference locals that outlive the calls; the module is destroyed
        // after pipeline creation on every path.
        unsafe {
            let module = d
                .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&words), None)
                .map_err(|r| Error::Vulkan(format!("vkCreateShaderModule {program}: {r}")))?;
            let stage = vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::COMPUTE)
                .module(module)
                .name(c"main");
            let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout);
            let result = d.create_compute_pipelines(vk::PipelineCache::null(), &[info], None);
            d.destroy_shader_module(module, None);
            let raw = result.map_err(|(_, r)| Error::Vulkan(format!("vkCreateComputePipelines {program}: {r}")))?[0];
            vk.count(super::context::Created::Pipeline);
            Ok(Pipeline { vk: vk.clone(), raw })
        }
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: owned handle; no pending GPU work uses it.
        unsafe { self.vk.device.destroy_pipeline(self.raw, None) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convention::Conventions;

    /// Every program the shader table marks for Vulkan, at every switch value `ShaderProgram::all`
    /// lists and under every convention, finds its SPIR-V for every stage: build.rs's preamble
    /// is `ShaderProgram::preamble`, and the table's switch values cover the typed ones.
    #[test]
    fn every_vulkan_program_variant_is_compiled_with_the_gl_preamble() {
        use crate::pass::shaders::Stage;
        use crate::pass::ShaderProgram;
        let mut found = 0;
        for conv in Conventions::all() {
            for program in ShaderProgram::all(conv).into_iter().filter(|p| p.kind.on_vulkan()) {
                let preamble = program.preamble();
                for (stage, _) in program.sources() {
                    let stage = match stage {
                        Stage::Vertex => "vert",
                        Stage::Fragment => "frag",
                        Stage::Compute => "comp",
                    };
                    let words = spirv(program.kind.name(), stage, &preamble).unwrap();
                    assert_eq!(words[0], 0x0723_0203, "SPIR-V magic of {}.{stage}", program.kind.name());
                    found += 1;
                }
            }
        }
        // Under each of 8 conventions: refocus 9 (full-screen 4, mesh 2 x 2, colour everywhere
        // 1), gather 8, shift 6, stitch 3, ray tracer 1, splat-gather's draw 1, forward warp 1,
        // densify 1, fill 1 and temporal compose 1 programs of 2 stages; splat, edge snap, edge
        // pass, temporal reprojection's 2 stages and the matchers' 14 stages (census 9,
        // semi-global 4, trust 1) 1 stage.
        assert_eq!(found, ((9 + 8 + 6 + 3 + 1 + 1 + 1 + 1 + 1 + 1) * 2 + 3 + 2 + 14) * 8);
    }
}
