//! GPU stitch: both eyes' faces uploaded once as atlases (face k at columns [k n, (k + 1) n):
//! GLSL cannot index a sampler array per pixel), one full-screen draw per eye into a
//! W x 2H top-bottom target (left eye on top), rows in the memory order of the row-order
//! convention, read back top-down.

use super::{face_camera, CubeFace, FaceSet, Method, Side, StitchParams, REPROJECT_STEPS};
use crate::convention::{Conventions, RowOrder};
use crate::error::{Error, Result};
use crate::gpu::shaders::StitchBlend;
use crate::gpu::{
    Attachment, DrawState, Framebuffer, Gpu, GpuTimer, Program, ProgramKind, ShaderProgram, Texture, TextureFormat,
    Timing, VertexArray,
};
use crate::io::RgbImage;

struct EyeAtlas {
    color: Texture,
    depth: Texture,
    set_meta: (Side, [[f64; 3]; 6]),
}

/// The six faces side by side in one atlas per channel, rows in memory order under `rows`.
fn upload(gpu: &Gpu, set: &FaceSet, rows: RowOrder) -> Result<EyeAtlas> {
    let n = set.size() as usize;
    let (mut rgba, mut depth) = (vec![0u8; 6 * n * n * 4], vec![0u8; 6 * n * n * 4]);
    for (k, face) in set.faces.iter().enumerate() {
        for y in 0..n {
            let my = match rows {
                RowOrder::TopDown => y,
                RowOrder::BottomUp => n - 1 - y,
            };
            for x in 0..n {
                let (s, d) = (y * n + x, my * 6 * n + k * n + x);
                rgba[d * 4..d * 4 + 3].copy_from_slice(&face.color.data[s * 3..s * 3 + 3]);
                rgba[d * 4 + 3] = 255;
                depth[d * 4..d * 4 + 4].copy_from_slice(&face.depth.data[s].to_ne_bytes());
            }
        }
    }
    let (w, h) = (6 * n as u32, n as u32);
    Ok(EyeAtlas {
        color: Texture::new(gpu, w, h, TextureFormat::Rgba8, Some(&rgba))?.with_label("stitch face colour atlas"),
        depth: Texture::new(gpu, w, h, TextureFormat::R32F, Some(&depth))?.with_label("stitch face depth atlas"),
        set_meta: (set.side, CubeFace::ALL.map(|f| f.pose(&set.rig, set.side).position)),
    })
}

/// A stereo face capture on the GPU, ready to stitch with any method.
pub struct StitchRenderer {
    gpu: Gpu,
    conv: Conventions,
    programs: Vec<Program>,
    vao: VertexArray,
    left: EyeAtlas,
    right: EyeAtlas,
    template: FaceSet,
    framebuffer: Option<Framebuffer>,
}

impl StitchRenderer {
    /// `left` and `right` must share rig, FOV and face size. Default conventions.
    pub fn new(gpu: &Gpu, left: &FaceSet, right: &FaceSet) -> Result<Self> {
        Self::with_conventions(gpu, left, right, Conventions::default())
    }

    /// As [`Self::new`], with the GPU-side row order of `conv` (faces and the equirect are
    /// stored and rendered in that memory order; the output is top-down either way). The NDC
    /// range and reversed-Z do not reach this pass: face depth is view Z (convert device depth
    /// with [`super::faces::view_z_of`]) and there is no depth buffer.
    pub fn with_conventions(gpu: &Gpu, left: &FaceSet, right: &FaceSet, conv: Conventions) -> Result<Self> {
        left.validate()?;
        right.validate()?;
        if left.side != Side::Left || right.side != Side::Right {
            return Err(Error::param(
                "face sets",
                "expected the left eye's then the right eye's",
            ));
        }
        if left.rig != right.rig || left.fov_deg != right.fov_deg || left.size() != right.size() {
            return Err(Error::param("face sets", "left and right differ in rig, FOV or size"));
        }
        // The six faces of an eye sit side by side in one texture.
        gpu.check_image_size("face atlas (6 x face size)", 6 * left.size(), left.size())?;
        let mut programs = Vec::new();
        for m in Method::ALL {
            let kind = ProgramKind::Stitch {
                method: match m {
                    Method::Blend => StitchBlend::Blend,
                    Method::BorderWeight => StitchBlend::BorderWeight,
                    Method::Reproject => StitchBlend::Reproject,
                },
                reproject_steps: REPROJECT_STEPS,
            };
            programs.push(ShaderProgram::new(conv, kind).build(gpu)?);
        }
        Ok(StitchRenderer {
            gpu: gpu.clone(),
            conv,
            programs,
            vao: VertexArray::new(gpu)?.with_label("stitch vertex array"),
            left: upload(gpu, left, conv.row_order)?,
            right: upload(gpu, right, conv.row_order)?,
            template: left.clone_meta(),
            framebuffer: None,
        })
    }

    /// Top-bottom stereo equirect (left eye on top), `params.width` x `2 params.height`.
    pub fn render(&mut self, params: &StitchParams) -> Result<(RgbImage, Timing)> {
        params.validate(&self.template)?;
        let (w, h) = (params.width, params.height);
        // Top-bottom: both eyes in one image of 2 h rows.
        self.gpu.check_image_size("equirect size", w, 2 * h)?;
        if !matches!(&self.framebuffer, Some(f) if f.width() == w && f.height() == 2 * h) {
            self.framebuffer = None;
            self.framebuffer = Some(
                Framebuffer::new(
                    &self.gpu,
                    w,
                    2 * h,
                    &[Some(Attachment {
                        format: TextureFormat::Rgba8,
                        clear: [0.0; 4],
                    })],
                    false,
                )?
                .with_label("stitch equirect"),
            );
        }
        let fb = self.framebuffer.as_ref().expect("allocated above");
        let p = &self.programs[params.method.index() as usize];
        let set = &self.template;
        let n = self.left.color.height();
        let cam = face_camera(n, set.fov_deg);
        let timer = GpuTimer::start(&self.gpu);
        let pass = fb.begin_pass(DrawState::default(), 1.0);
        p.bind();
        p.set_i32("u_color", 0);
        p.set_i32("u_depth", 1);
        for (k, f) in CubeFace::ALL.iter().enumerate() {
            let r = f.rotation();
            let rows = [
                [r[0][0], r[0][1], r[0][2], 0.0],
                [r[1][0], r[1][1], r[1][2], 0.0],
                [r[2][0], r[2][1], r[2][2], 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ];
            p.set_mat4_rows(&format!("u_rot[{k}]"), &rows);
        }
        p.set_f32("u_f", cam.k.fx as f32);
        p.set_f32("u_c", cam.k.cx as f32);
        p.set_i32("u_n", n as i32);
        let c = set.rig.centre;
        p.set_vec4("u_centre", [c[0] as f32, c[1] as f32, c[2] as f32, 1.0]);
        p.set_f32("u_half_ipd", (0.5 * set.rig.ipd) as f32);
        p.set_f32("u_fade_start", set.rig.pole_fade_start_deg.to_radians() as f32);
        p.set_f32("u_overlap", params.overlap_deg.to_radians() as f32);
        p.set_ivec2("u_size", [w as i32, h as i32]);
        // Left eye on top of the image: bottom-up memory holds it in the upper half of the rows.
        let (left_row0, right_row0) = match self.conv.row_order {
            RowOrder::TopDown => (0, h),
            RowOrder::BottomUp => (h, 0),
        };
        for (row0, eye) in [(left_row0, &self.left), (right_row0, &self.right)] {
            eye.color.bind(0);
            eye.depth.bind(1);
            p.set_f32("u_side", eye.set_meta.0.sign() as f32);
            for (k, e) in eye.set_meta.1.iter().enumerate() {
                p.set_vec4(&format!("u_eye[{k}]"), [e[0] as f32, e[1] as f32, e[2] as f32, 1.0]);
            }
            p.set_i32("u_row0", row0 as i32);
            // One full-screen triangle into this eye's half of the framebuffer.
            pass.viewport(0, row0, w, h);
            pass.draw_fullscreen(&self.vao);
        }
        drop(pass);
        self.gpu.check("stitch draw")?;
        // Rows flipped (GL row order) and RGB packed on the GPU: the mapped bytes are the image.
        let flip = self.conv.row_order == crate::convention::RowOrder::BottomUp;
        let read = fb.read_async(0, crate::gpu::ReadFormat::RGB8, flip)?;
        let rgb = read.expect("colour attachment").finish()?;
        let timing = timer.stop();
        Ok((RgbImage::new(w, 2 * h, rgb)?, timing))
    }
}

impl FaceSet {
    fn clone_meta(&self) -> FaceSet {
        FaceSet {
            rig: self.rig,
            side: self.side,
            fov_deg: self.fov_deg,
            faces: Vec::new(),
        }
    }
}
