//! Forward warp, the mesh alternative to the gather: each eye's depth map becomes the refocus grid
//! mesh (broken at depth discontinuities), is rendered into the middle camera with a depth test,
//! and the two eyes merge by depth (nearest surface wins). Rasterised, so it has no fixation
//! guess to get wrong and fills every pixel a kept triangle covers; its oracle is the
//! ray-traced middle view (viewsynth_tests/tests/library/cyclopean/gather.rs).

use crate::camera::mat4::{self, Mat4};
use crate::convention::RowOrder;
use crate::error::{Error, Result};
use crate::mesh::code_rows;
use crate::mesh::{BreakRule, Grid};
use crate::pass::shaders::TRI_TEX_WIDTH;
use crate::pass::{mat4_std140, Device, Draw, Format, Image, ImageData, Step, Target, Texels, ToDevice};
use crate::pass::{ProgramKind, ShaderProgram, Timing};
use crate::stereo::gather::CyclopeanOutput;
use crate::stereo::{EyeInput, FrameDepth, MiddleCamera, StereoFrame};

/// The right eye replaces the left only where it is nearer by more than this (relative): ties
/// between the two views of one surface go to the left eye under every convention. Far above
/// f32 depth-buffer resolution (~4e-6 relative at 6 m with standard Z and near 0.05 m).
pub const RIGHT_EYE_DEPTH_BIAS: f32 = 1e-4;

/// View distance per eye pixel (rows top-down), 0 where the depth is background or invalid.
pub fn eye_distances(eye: &EyeInput, kind: FrameDepth, conv: &crate::convention::Conventions) -> Result<Vec<f32>> {
    let inv_proj = mat4::inverse(&eye.proj).ok_or_else(|| Error::param("eye projection", "singular"))?;
    let basis =
        crate::camera::rays::ray_basis(&eye.proj).ok_or_else(|| Error::param("eye projection", "not perspective"))?;
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
                crate::camera::rays::pixel_ndc(x as f64, w as f64),
                crate::camera::rays::pixel_ndc(y_mem as f64, h as f64),
            ];
            let d = eye.depth.data[y * w + x] as f64;
            out[y * w + x] = crate::stereo::gather::reference::stored_view_point(d, ndc, kind, conv, &inv_proj, &basis)
                .map(|p| -p[2])
                .filter(|v| v.is_finite() && *v > 0.0)
                .unwrap_or(0.0) as f32;
        }
    }
    Ok(out)
}

crate::param_block! {
    /// One eye's draw: shaders/cyclopean/forward_params.glsl, member for member.
    pub struct ForwardParams("ForwardParams") {
        u_inv_view_e: [[f32; 4]; 4],
        u_ray_basis_e: [[f32; 4]; 4],
        u_view_proj_e: [[f32; 4]; 4],
        u_view_m: [[f32; 4]; 4],
        u_view_proj_m: [[f32; 4]; 4],
        u_ray_basis_vp_m: [[f32; 4]; 4],
        u_middle_centre: [f32; 3],
        u_expand_px: f32,
        u_size_m: [f32; 2],
        u_eye_size: [i32; 2],
        u_depth_bias: f32,
        u_eye_bit: i32,
    }
}

struct EyeMesh {
    color: Image,
    distance: Image,
    tris: Option<Image>,
    count: usize,
    view: Mat4,
    proj: Mat4,
    size: (u32, u32),
}

/// The forward warp of a stereo frame on the GPU (GL or Vulkan): both eyes' meshes uploaded,
/// ready for any middle camera.
pub struct ForwardWarp {
    device: Device,
    program: ShaderProgram,
    eyes: [EyeMesh; 2],
    conv: crate::convention::Conventions,
}

impl ForwardWarp {
    /// `rule` breaks the mesh at eye-depth discontinuities (the refocus rule on view distance).
    pub fn new(device: impl ToDevice, frame: &StereoFrame, rule: &BreakRule) -> Result<Self> {
        frame.validate()?;
        rule.validate()?;
        let device = device.to_device()?;
        let mesh = |eye: &EyeInput| -> Result<EyeMesh> {
            let (w, h) = (eye.color.width, eye.color.height);
            device.check_image_size("eye size", w, h)?;
            let dist = eye_distances(eye, frame.depth_kind, &frame.conv)?;
            let grid = Grid { width: w, height: h };
            let keep = grid.keep_mask(&dist, rule);
            let codes = grid.kept_triangles(&keep);
            let rgba: Vec<u8> = crate::pass::pixels::rgb_to_rgba(&eye.color.data);
            let dbytes: Vec<u8> = crate::pass::pixels::f32_to_bytes(&dist);
            let image = |width, height, format, bytes: &[u8], label| {
                device.upload(&ImageData {
                    width,
                    height,
                    format,
                    bytes,
                    label,
                })
            };
            let tris = match code_rows(&codes, u32::MAX)? {
                Some((rows, bytes)) => Some(image(
                    TRI_TEX_WIDTH,
                    rows,
                    Format::R32Ui,
                    &bytes,
                    "kept triangle codes",
                )?),
                None => None,
            };
            Ok(EyeMesh {
                color: image(
                    w,
                    h,
                    Format::Rgba8,
                    &frame.conv.row_order.convert_rows(rgba, w as usize * 4),
                    "forward warp eye colour",
                )?,
                distance: image(
                    w,
                    h,
                    Format::R32F,
                    &frame.conv.row_order.convert_rows(dbytes, w as usize * 4),
                    "forward warp eye distance",
                )?,
                tris,
                count: codes.len(),
                view: eye.view,
                proj: eye.proj,
                size: (w, h),
            })
        };
        Ok(ForwardWarp {
            program: ShaderProgram::new(frame.conv, ProgramKind::CyclopeanForward),
            eyes: [mesh(&frame.left)?, mesh(&frame.right)?],
            device,
            conv: frame.conv,
        })
    }

    /// Renders the middle view of camera `mid`, with its times.
    pub fn render(&mut self, mid: &MiddleCamera) -> Result<(CyclopeanOutput, Timing)> {
        let (w, h) = (mid.width, mid.height);
        self.device.check_image_size("middle size", w, h)?;
        let vp_m = mat4::mul(&mid.proj, &mid.view);
        let centre = crate::camera::projection_centre(&vp_m)
            .ok_or_else(|| Error::param("middle projection", "not perspective"))?;
        let rays_vp_m = crate::stereo::ray_basis_std140(&vp_m, "middle view-projection")?;
        let inv = |m: &Mat4, what: &str| {
            mat4::inverse(m)
                .map(|m| mat4_std140(&m))
                .ok_or_else(|| Error::param(what.to_string(), "singular"))
        };
        let mut blocks = Vec::new();
        let mut images = Vec::new();
        for (bit, eye) in [(1, &self.eyes[0]), (2, &self.eyes[1])] {
            let Some(tris) = &eye.tris else { continue };
            blocks.push(ForwardParams {
                u_inv_view_e: inv(&eye.view, "eye view")?,
                u_ray_basis_e: crate::stereo::ray_basis_std140(&eye.proj, "eye projection")?,
                u_view_proj_e: mat4_std140(&mat4::mul(&eye.proj, &eye.view)),
                u_view_m: mat4_std140(&mid.view),
                u_view_proj_m: mat4_std140(&vp_m),
                u_ray_basis_vp_m: rays_vp_m,
                u_middle_centre: centre.map(|v| v as f32),
                u_expand_px: 1.0 / 32.0,
                u_size_m: [w as f32, h as f32],
                u_eye_size: [eye.size.0 as i32, eye.size.1 as i32],
                u_depth_bias: if bit == 2 { RIGHT_EYE_DEPTH_BIAS } else { 0.0 },
                u_eye_bit: bit,
            });
            images.push(([eye.color.id(), eye.distance.id(), tris.id()], eye.count as u32));
        }
        // The eyes merge by depth: nearest surface wins under the conventions' depth test.
        let steps: Vec<Step> = blocks
            .iter()
            .zip(&images)
            .map(|(block, (images, count))| {
                Step::Draw(Draw {
                    program: self.program,
                    params: bytemuck::bytes_of(block),
                    images,
                    buffers: &[],
                    viewport: [0, 0, w, h],
                    triangles: *count,
                    indices: None,
                })
            })
            .collect();
        let target = Target {
            depth_test: Some(self.conv),
            ..Target::view(w, h, true, true, self.conv.row_order)
        };
        let mut out = if steps.is_empty() {
            // Neither eye kept a triangle: an empty view (a run without draws reads nothing).
            let n = w as usize * h as usize;
            crate::pass::Rendered {
                outputs: vec![
                    Some(Texels::Bytes(vec![0; 3 * n])),
                    Some(Texels::Floats(vec![0.0; n])),
                    Some(Texels::Bytes(vec![0; n])),
                ],
                timing: Timing {
                    gpu_ms: None,
                    wall_ms: 0.0,
                },
                size: (w, h),
                api: self.device.api(),
            }
        } else {
            self.device.run(Some(&target), &steps)?
        };
        let (color, depth) = (out.color(0)?, out.depth(1)?);
        let sources = out.take(2, "cyclopean forward warp")?;
        Ok((CyclopeanOutput { color, depth, sources }.finite(), out.timing))
    }
}
