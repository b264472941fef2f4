//! GPU cyclopean pass: one full-screen draw (shaders/cyclopean/gather.frag) into colour,
//! middle depth and source bits, read back top-down.

use super::{
    Blend, CyclopeanOutput, CyclopeanOutputs, CyclopeanParams, Eye, EyeInput, FrameDepth, Method, MiddleCamera,
    StereoFrame,
};
use crate::camera::mat4::{self, Mat4};
use crate::convention::RowOrder;
use crate::error::{Error, Result};
use crate::gpu::{
    Attachment, DrawState, Framebuffer, Gpu, GpuTimer, Program, ProgramKind, ShaderProgram, Texture, TextureFormat,
    Timing, VertexArray,
};
use crate::io::{DepthMap, RgbImage};

struct EyeGpu {
    color: Texture,
    depth: Texture,
    view: Mat4,
    proj: Mat4,
}

fn upload_eye(gpu: &Gpu, eye: &EyeInput, rows: RowOrder) -> Result<EyeGpu> {
    let (w, h) = (eye.color.width, eye.color.height);
    let rgba: Vec<u8> = crate::gpu::pixels::rgb_to_rgba(&eye.color.data);
    let depth: Vec<u8> = crate::gpu::pixels::f32_to_bytes(&eye.depth.data);
    Ok(EyeGpu {
        color: Texture::new(
            gpu,
            w,
            h,
            TextureFormat::Rgba8,
            Some(&rows.convert_rows(rgba, w as usize * 4)),
        )?
        .with_label("cyclopean eye colour"),
        depth: Texture::new(
            gpu,
            w,
            h,
            TextureFormat::R32F,
            Some(&rows.convert_rows(depth, w as usize * 4)),
        )?
        .with_label("cyclopean eye depth"),
        view: eye.view,
        proj: eye.proj,
    })
}

/// A stereo frame on the GPU, ready to render middle views.
pub struct CyclopeanRenderer {
    gpu: Gpu,
    program: Program,
    params: CyclopeanParams,
    outputs: CyclopeanOutputs,
    rows: RowOrder,
    left: EyeGpu,
    right: EyeGpu,
    vao: VertexArray,
    framebuffer: Option<Framebuffer>,
}

impl CyclopeanRenderer {
    /// All outputs (colour, depth, source bits).
    pub fn new(gpu: &Gpu, frame: &StereoFrame, params: CyclopeanParams) -> Result<Self> {
        Self::with_outputs(gpu, frame, params, CyclopeanOutputs::default())
    }

    /// Only the requested colour/depth (the source bits always).
    pub fn with_outputs(
        gpu: &Gpu,
        frame: &StereoFrame,
        params: CyclopeanParams,
        outputs: CyclopeanOutputs,
    ) -> Result<Self> {
        frame.validate()?;
        params.validate()?;
        let kind = ProgramKind::CyclopeanGather {
            depth_is_device: frame.depth_kind == FrameDepth::Device,
            refine: matches!(params.method, Method::Refine { .. }),
            blend_soft: params.blend == Blend::Soft,
        };
        let program = ShaderProgram::new(frame.conv, kind).build(gpu)?;
        Ok(CyclopeanRenderer {
            gpu: gpu.clone(),
            program,
            params,
            outputs,
            rows: frame.conv.row_order,
            left: upload_eye(gpu, &frame.left, frame.conv.row_order)?,
            right: upload_eye(gpu, &frame.right, frame.conv.row_order)?,
            vao: VertexArray::new(gpu)?.with_label("cyclopean vertex array"),
            framebuffer: None,
        })
    }

    /// Renders the middle view of camera `mid` (one full-screen gather pass), with its times.
    pub fn render(&mut self, mid: &MiddleCamera) -> Result<(CyclopeanOutput, Timing)> {
        let (w, h) = (mid.width, mid.height);
        self.gpu.check_image_size("middle size", w, h)?;
        let inv = |m: &Mat4, what: &str| mat4::inverse(m).ok_or_else(|| Error::param(what.to_string(), "singular"));
        if !matches!(&self.framebuffer, Some(f) if f.width() == w && f.height() == h) {
            self.framebuffer = None;
            let slot = |wanted: bool, format| {
                wanted.then_some(Attachment {
                    format,
                    clear: [0.0; 4],
                })
            };
            self.framebuffer = Some(
                Framebuffer::new(
                    &self.gpu,
                    w,
                    h,
                    &[
                        slot(self.outputs.color, TextureFormat::Rgba8),
                        slot(self.outputs.depth, TextureFormat::R32F),
                        slot(true, TextureFormat::R8),
                    ],
                    false,
                )?
                .with_label("cyclopean target"),
            );
        }
        let fb = self.framebuffer.as_ref().expect("allocated above");
        let p = &self.program;
        let timer = GpuTimer::start(&self.gpu);
        let pass = fb.begin_pass(DrawState::default(), 1.0);
        p.bind();
        for (unit, t) in [&self.left.color, &self.right.color, &self.left.depth, &self.right.depth]
            .into_iter()
            .enumerate()
        {
            t.bind(unit as u32);
        }
        for (unit, name) in ["u_color_l", "u_color_r", "u_depth_l", "u_depth_r"]
            .into_iter()
            .enumerate()
        {
            p.set_i32(name, unit as i32);
        }
        for (suffix, eye) in [("l", &self.left), ("r", &self.right)] {
            p.set_mat4_rows(&format!("u_view_proj_{suffix}"), &mat4::mul(&eye.proj, &eye.view));
            p.set_mat4_rows(&format!("u_inv_view_{suffix}"), &inv(&eye.view, "eye view")?);
            p.set_mat4_rows(&format!("u_inv_proj_{suffix}"), &inv(&eye.proj, "eye projection")?);
            p.set_mat4_rows(&format!("u_view_{suffix}"), &eye.view);
        }
        p.set_mat4_rows("u_view_m", &mid.view);
        p.set_mat4_rows("u_inv_view_m", &inv(&mid.view, "middle view")?);
        p.set_mat4_rows("u_inv_proj_m", &inv(&mid.proj, "middle projection")?);
        p.set_mat4_rows("u_view_proj_m", &mat4::mul(&mid.proj, &mid.view));
        p.set_vec2("u_size_m", [w as f32, h as f32]);
        p.set_f32("u_fixation", self.params.fixation_distance as f32);
        p.set_f32("u_z_threshold", self.params.z_threshold as f32);
        let w_left = match self.params.dominant {
            Some((Eye::Left, wt)) => wt,
            Some((Eye::Right, wt)) => 1.0 - wt,
            None => 0.5,
        };
        p.set_f32("u_w_left", w_left as f32);
        p.set_i32("u_steps", self.params.steps() as i32);
        pass.draw_fullscreen(&self.vao);
        drop(pass);
        self.gpu.check("cyclopean draw")?;
        let out = read_output(fb, self.rows)?;
        let timing = timer.stop();
        Ok((out, timing))
    }
}

/// Read a middle-view framebuffer (RGBA8 colour, R32F depth, R8 source bits) back top-down;
/// colour and depth only where the framebuffer has them. All reads are queued before the first
/// is waited for; the GPU flips the rows (GL row order) and packs RGB, so the mapped bytes are
/// the images' bytes.
pub(crate) fn read_output(fb: &Framebuffer, rows: RowOrder) -> Result<CyclopeanOutput> {
    use crate::gpu::ReadFormat;
    let (w, h) = (fb.width(), fb.height());
    let flip = rows == RowOrder::BottomUp;
    let sources = fb
        .read_async(2, ReadFormat::R8, flip)?
        .ok_or_else(|| Error::Gl("middle framebuffer lacks the source bits".into()))?;
    let color = fb.read_async(0, ReadFormat::RGB8, flip)?;
    let depth = fb.read_async(1, ReadFormat::R32F, flip)?;
    Ok(CyclopeanOutput {
        sources: sources.finish()?,
        color: color.map(|r| RgbImage::new(w, h, r.finish()?)).transpose()?,
        depth: depth.map(|r| DepthMap::new(w, h, r.finish_f32()?)).transpose()?,
    })
}
