//! Forward warp, the mesh alternative to the gather: each eye's depth map becomes the refocus grid
//! mesh (broken at depth discontinuities), is rendered into the middle camera with a depth test,
//! and the two eyes merge by depth (nearest surface wins). Rasterised, so it has no fixation
//! guess to get wrong and fills every pixel a kept triangle covers; its oracle is the
//! ray-traced middle view (tests/integration/cyclopean.rs).

use super::{CyclopeanOutput, EyeInput, FrameDepth, MiddleCamera, StereoFrame};
use crate::camera::mat4::{self, Mat4};
use crate::convention::RowOrder;
use crate::error::{Error, Result};
use crate::gpu::{
    Attachment, DrawState, Framebuffer, Gpu, GpuTimer, Program, ProgramKind, ShaderProgram, Texture, TextureFormat,
    Timing, VertexArray,
};
use crate::refocus::code_texture;
use crate::refocus::{BreakRule, Grid};

/// The right eye replaces the left only where it is nearer by more than this (relative): ties
/// between the two views of one surface go to the left eye under every convention. Far above
/// f32 depth-buffer resolution (~4e-6 relative at 6 m with standard Z and near 0.05 m).
pub const RIGHT_EYE_DEPTH_BIAS: f32 = 1e-4;

/// View distance per eye pixel (rows top-down), 0 where the depth is background or invalid.
pub fn eye_distances(eye: &EyeInput, kind: FrameDepth, conv: &crate::convention::Conventions) -> Result<Vec<f32>> {
    let inv_proj = mat4::inverse(&eye.proj).ok_or_else(|| Error::param("eye projection", "singular"))?;
    let (w, h) = (eye.depth.width as usize, eye.depth.height as usize);
    let mut out = vec![0f32; w * h];
    for y in 0..h {
        // NDC y of image row y under the row order.
        let y_mem = if conv.row_order == RowOrder::BottomUp {
            h - 1 - y
        } else {
            y
        };
        for x in 0..w {
            let ndc = [
                (x as f64 + 0.5) / w as f64 * 2.0 - 1.0,
                (y_mem as f64 + 0.5) / h as f64 * 2.0 - 1.0,
            ];
            let d = eye.depth.data[y * w + x] as f64;
            out[y * w + x] = super::reference::stored_view_point(d, ndc, kind, conv, &inv_proj)
                .map(|p| -p[2])
                .filter(|v| v.is_finite() && *v > 0.0)
                .unwrap_or(0.0) as f32;
        }
    }
    Ok(out)
}

struct EyeMesh {
    color: Texture,
    distance: Texture,
    tris: Option<Texture>,
    count: usize,
    view: Mat4,
    proj: Mat4,
    size: (u32, u32),
}

/// The forward warp of a stereo frame on the GPU: both eyes' meshes uploaded, ready for any middle camera.
pub struct ForwardWarp {
    gpu: Gpu,
    program: Program,
    eyes: [EyeMesh; 2],
    conv: crate::convention::Conventions,
    vao: VertexArray,
}

impl ForwardWarp {
    /// `rule` breaks the mesh at eye-depth discontinuities (the refocus rule on view distance).
    pub fn new(gpu: &Gpu, frame: &StereoFrame, rule: &BreakRule) -> Result<Self> {
        frame.validate()?;
        rule.validate()?;
        let mesh = |eye: &EyeInput| -> Result<EyeMesh> {
            let (w, h) = (eye.color.width, eye.color.height);
            let dist = eye_distances(eye, frame.depth_kind, &frame.conv)?;
            let grid = Grid { width: w, height: h };
            let keep = grid.keep_mask(&dist, rule);
            let codes = grid.kept_triangles(&keep);
            let rgba: Vec<u8> = crate::gpu::pixels::rgb_to_rgba(&eye.color.data);
            let dbytes: Vec<u8> = crate::gpu::pixels::f32_to_bytes(&dist);
            Ok(EyeMesh {
                color: Texture::new(
                    gpu,
                    w,
                    h,
                    TextureFormat::Rgba8,
                    Some(&frame.conv.row_order.convert_rows(rgba, w as usize * 4)),
                )?
                .with_label("forward warp eye colour"),
                distance: Texture::new(
                    gpu,
                    w,
                    h,
                    TextureFormat::R32F,
                    Some(&frame.conv.row_order.convert_rows(dbytes, w as usize * 4)),
                )?
                .with_label("forward warp eye distance"),
                tris: code_texture(gpu, &codes)?,
                count: codes.len(),
                view: eye.view,
                proj: eye.proj,
                size: (w, h),
            })
        };
        let program = ShaderProgram::new(frame.conv, ProgramKind::CyclopeanForward).build(gpu)?;
        Ok(ForwardWarp {
            gpu: gpu.clone(),
            program,
            eyes: [mesh(&frame.left)?, mesh(&frame.right)?],
            conv: frame.conv,
            vao: VertexArray::new(gpu)?.with_label("forward warp vertex array"),
        })
    }

    /// Renders the middle view of camera `mid`, with its times.
    pub fn render(&mut self, mid: &MiddleCamera) -> Result<(CyclopeanOutput, Timing)> {
        let (w, h) = (mid.width, mid.height);
        self.gpu.check_image_size("middle size", w, h)?;
        let slot = |format| {
            Some(Attachment {
                format,
                clear: [0.0; 4],
            })
        };
        let fb = Framebuffer::new(
            &self.gpu,
            w,
            h,
            &[
                slot(TextureFormat::Rgba8),
                slot(TextureFormat::R32F),
                slot(TextureFormat::R8),
            ],
            true,
        )?
        .with_label("forward warp target");
        let p = &self.program;
        let gpu = &self.gpu;
        let timer = GpuTimer::start(gpu);
        // The eyes merge by depth: nearest surface wins under the conventions' depth test.
        let pass = fb.begin_pass(DrawState::depth_tested(&self.conv), self.conv.clear_depth() as f32);
        p.bind();
        p.set_mat4_rows("u_view_m", &mid.view);
        p.set_mat4_rows("u_view_proj_m", &mat4::mul(&mid.proj, &mid.view));
        let vp_m = mat4::mul(&mid.proj, &mid.view);
        let centre = crate::scene::gpu::projection_centre(&vp_m)
            .ok_or_else(|| Error::param("middle projection", "not perspective"))?;
        p.set_vec3("u_middle_centre", centre.map(|v| v as f32));
        p.set_i32("u_color", 0);
        p.set_i32("u_distance", 1);
        p.set_i32("u_tris", 2);
        p.set_vec2("u_size_m", [w as f32, h as f32]);
        p.set_f32("u_expand_px", 1.0 / 32.0);
        let inv_vp_m = mat4::inverse(&mat4::mul(&mid.proj, &mid.view))
            .ok_or_else(|| Error::param("middle view-projection", "singular"))?;
        p.set_mat4_rows("u_inv_view_proj_m", &inv_vp_m);
        for (bit, eye) in [(1, &self.eyes[0]), (2, &self.eyes[1])] {
            let Some(tris) = &eye.tris else { continue };
            let inv = |m: &Mat4, what: &str| mat4::inverse(m).ok_or_else(|| Error::param(what.to_string(), "singular"));
            eye.color.bind(0);
            eye.distance.bind(1);
            p.set_mat4_rows("u_inv_view_e", &inv(&eye.view, "eye view")?);
            p.set_mat4_rows("u_inv_proj_e", &inv(&eye.proj, "eye projection")?);
            p.set_mat4_rows("u_view_proj_e", &mat4::mul(&eye.proj, &eye.view));
            p.set_ivec2("u_eye_size", [eye.size.0 as i32, eye.size.1 as i32]);
            p.set_i32("u_eye_bit", bit);
            p.set_f32("u_depth_bias", if bit == 2 { RIGHT_EYE_DEPTH_BIAS } else { 0.0 });
            tris.bind(2);
            pass.draw_triangles(&self.vao, eye.count);
        }
        drop(pass);
        gpu.check("forward warp")?;
        let out = super::render::read_output(&fb, self.conv.row_order)?;
        let timing = timer.stop();
        Ok((out, timing))
    }
}
