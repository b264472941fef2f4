//! GPU cyclopean pass: one full-screen draw (shaders/cyclopean/gather.frag) into colour,
//! middle depth and source bits, read back top-down; described once ([`crate::pass`]) and run
//! by the GL or the Vulkan executor.

use crate::camera::mat4::{self, Mat4};
use crate::convention::RowOrder;
use crate::error::{Error, Result};
use crate::pass::{mat4_std140, Device, Draw, Format, Image, ImageData, Target, ToDevice};
use crate::pass::{ProgramKind, ShaderProgram, Timing};
use crate::stereo::gather::{Blend, CyclopeanOutput, CyclopeanOutputs, CyclopeanParams, Method};
use crate::stereo::{EyeInput, FrameDepth, MiddleCamera, StereoFrame};

crate::param_block! {
    /// The gather's parameters: shaders/cyclopean/gather_params.glsl, member for member.
    pub struct GatherParams("GatherParams") {
        u_view_proj_l: [[f32; 4]; 4],
        u_inv_view_l: [[f32; 4]; 4],
        u_inv_proj_l: [[f32; 4]; 4],
        u_view_l: [[f32; 4]; 4],
        u_view_proj_r: [[f32; 4]; 4],
        u_inv_view_r: [[f32; 4]; 4],
        u_inv_proj_r: [[f32; 4]; 4],
        u_view_r: [[f32; 4]; 4],
        u_view_m: [[f32; 4]; 4],
        u_inv_view_m: [[f32; 4]; 4],
        u_ray_basis_m: [[f32; 4]; 4],
        u_view_proj_m: [[f32; 4]; 4],
        u_ray_basis_l: [[f32; 4]; 4],
        u_ray_basis_r: [[f32; 4]; 4],
        u_size_m: [f32; 2],
        u_fixation: f32,
        u_z_threshold: f32,
        u_w_left: f32,
        u_steps: i32,
    }
}

struct EyeGpu {
    color: Image,
    depth: Image,
    view: Mat4,
    proj: Mat4,
}

fn upload_eye(device: &Device, eye: &EyeInput, rows: RowOrder) -> Result<EyeGpu> {
    let (w, h) = (eye.color.width, eye.color.height);
    device.check_image_size("eye size", w, h)?;
    let rgba: Vec<u8> = crate::pass::pixels::rgb_to_rgba(&eye.color.data);
    let depth: Vec<u8> = crate::pass::pixels::f32_to_bytes(&eye.depth.data);
    let image = |bytes: &[u8], format, label| device.upload(&ImageData::new(w, h, format, bytes, label));
    Ok(EyeGpu {
        color: image(
            &rows.convert_rows(rgba, w as usize * 4),
            Format::Rgba8,
            "cyclopean eye colour",
        )?,
        depth: image(
            &rows.convert_rows(depth, w as usize * 4),
            Format::R32F,
            "cyclopean eye depth",
        )?,
        view: eye.view,
        proj: eye.proj,
    })
}

/// A stereo frame on the GPU (GL or Vulkan), ready to render middle views.
pub struct CyclopeanRenderer {
    device: Device,
    program: ShaderProgram,
    params: CyclopeanParams,
    outputs: CyclopeanOutputs,
    rows: RowOrder,
    left: EyeGpu,
    right: EyeGpu,
}

impl CyclopeanRenderer {
    /// All outputs (colour, depth, source bits).
    pub fn new(device: impl ToDevice, frame: &StereoFrame, params: CyclopeanParams) -> Result<Self> {
        Self::with_outputs(device, frame, params, CyclopeanOutputs::default())
    }

    /// Only the requested colour/depth (the source bits always).
    pub fn with_outputs(
        device: impl ToDevice,
        frame: &StereoFrame,
        params: CyclopeanParams,
        outputs: CyclopeanOutputs,
    ) -> Result<Self> {
        frame.validate()?;
        params.validate()?;
        let device = device.to_device()?;
        let kind = ProgramKind::CyclopeanGather {
            depth_is_device: frame.depth_kind == FrameDepth::Device,
            refine: matches!(params.method, Method::Refine { .. }),
            blend_soft: params.blend == Blend::Soft,
        };
        Ok(CyclopeanRenderer {
            program: ShaderProgram::new(frame.conv, kind),
            params,
            outputs,
            rows: frame.conv.row_order,
            left: upload_eye(&device, &frame.left, frame.conv.row_order)?,
            right: upload_eye(&device, &frame.right, frame.conv.row_order)?,
            device,
        })
    }

    /// The parameter block for middle camera `mid`: matrices and their inverses in f64, rounded
    /// to f32 once.
    fn block(&self, mid: &MiddleCamera) -> Result<GatherParams> {
        let inv = |m: &Mat4, what: &str| {
            mat4::inverse(m)
                .map(|m| mat4_std140(&m))
                .ok_or_else(|| Error::param(what.to_string(), "singular"))
        };
        let rays = crate::stereo::ray_basis_std140;
        let (l, r) = (&self.left, &self.right);
        Ok(GatherParams {
            u_view_proj_l: mat4_std140(&mat4::mul(&l.proj, &l.view)),
            u_inv_view_l: inv(&l.view, "eye view")?,
            u_inv_proj_l: inv(&l.proj, "eye projection")?,
            u_view_l: mat4_std140(&l.view),
            u_view_proj_r: mat4_std140(&mat4::mul(&r.proj, &r.view)),
            u_inv_view_r: inv(&r.view, "eye view")?,
            u_inv_proj_r: inv(&r.proj, "eye projection")?,
            u_view_r: mat4_std140(&r.view),
            u_view_m: mat4_std140(&mid.view),
            u_inv_view_m: inv(&mid.view, "middle view")?,
            u_ray_basis_m: rays(&mid.proj, "middle projection")?,
            u_view_proj_m: mat4_std140(&mat4::mul(&mid.proj, &mid.view)),
            u_ray_basis_l: rays(&l.proj, "eye projection")?,
            u_ray_basis_r: rays(&r.proj, "eye projection")?,
            u_size_m: [mid.width as f32, mid.height as f32],
            u_fixation: self.params.fixation_distance as f32,
            u_z_threshold: self.params.z_threshold as f32,
            u_w_left: self.params.left_eye_weight() as f32,
            u_steps: self.params.steps() as i32,
        })
    }

    /// Renders the middle view of camera `mid` (one full-screen gather pass), with its times.
    pub fn render(&mut self, mid: &MiddleCamera) -> Result<(CyclopeanOutput, Timing)> {
        let (w, h) = (mid.width, mid.height);
        self.device.check_image_size("middle size", w, h)?;
        let block = self.block(mid)?;
        let target = Target::view(w, h, self.outputs.color, self.outputs.depth, self.rows);
        let images = [
            self.left.color.id(),
            self.right.color.id(),
            self.left.depth.id(),
            self.right.depth.id(),
        ];
        let draw = Draw::fullscreen(self.program, bytemuck::bytes_of(&block), &images, w, h);
        let mut out = self.device.render(&target, &[draw])?;
        let (color, depth) = (out.color(0)?, out.depth(1)?);
        let sources = out.take(2, "cyclopean gather")?;
        Ok((CyclopeanOutput { color, depth, sources }.finite(), out.timing))
    }
}
