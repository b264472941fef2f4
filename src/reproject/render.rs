//! GPU reprojection: the shift gathers as one full-screen pass (shaders/reproject/shift.frag),
//! the 3-D gather through the cyclopean renderer with one eye; described once
//! ([`crate::pass`]) and run by the GL or the Vulkan executor. Output rows top-down.

use super::merge_nearer;
use super::reference::SCAN_MARGIN;
use super::{
    check, gather3d_params, one_eye_frame, Geometry, Method, ReprojectOutput, ReprojectParams, ReprojectSource,
};
use crate::convention::RowOrder;
use crate::depth::DepthEncoding;
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use crate::pass::shaders::ShiftDepth;
use crate::pass::{Device, Draw, Format, Image, ImageData, Target, ToDevice};
use crate::pass::{ProgramKind, ShaderProgram, Timing};
use crate::stereo::gather::gpu::CyclopeanRenderer;
use crate::stereo::gather::CyclopeanOutputs;
use crate::stereo::MiddleCamera;

crate::param_block! {
    /// The shift's parameters: shaders/reproject/reproject_params.glsl, member for member.
    pub struct ShiftParams("ShiftParams") {
        u_a: f32,
        u_b: f32,
        u_alpha: f32,
        u_beta: f32,
        u_q_min: f32,
        u_q_max: f32,
        u_tau_rel: f32,
        u_steps: i32,
    }
}

struct ShiftPass {
    program: ShaderProgram,
    color: Image,
    depth: Image,
    block: ShiftParams,
}

enum Pass {
    Shift(Box<ShiftPass>),
    Gather3d(Box<([CyclopeanRenderer; 2], MiddleCamera)>),
}

/// A source view on the GPU (GL or Vulkan), ready to render its reprojection.
pub struct Reprojector {
    device: Device,
    params: ReprojectParams,
    rows: RowOrder,
    width: u32,
    height: u32,
    pass: Pass,
}

impl Reprojector {
    /// Uploads `src` for the target `geometry` and builds the method's programs; checks the inputs first.
    pub fn new(
        device: impl ToDevice,
        src: &ReprojectSource,
        geometry: &Geometry,
        params: ReprojectParams,
    ) -> Result<Self> {
        let device = device.to_device()?;
        device.check_image_size("source size", src.color.width, src.color.height)?;
        let model = check(src, geometry, &params)?;
        let rows = src.conv.row_order;
        let (w, h) = (src.color.width, src.color.height);
        let pass = match (model, params.method) {
            (None, Method::Gather3d { steps }) => {
                let (frame, target) = one_eye_frame(src, geometry)?;
                let [p0, p1] = gather3d_params(src, geometry, steps);
                // The two walks are merged by depth, so depth is always rendered; colour only
                // when asked for.
                let wanted = CyclopeanOutputs {
                    color: params.outputs.color,
                    depth: true,
                };
                let r = [
                    CyclopeanRenderer::with_outputs(&device, &frame, p0, wanted)?,
                    CyclopeanRenderer::with_outputs(&device, &frame, p1, wanted)?,
                ];
                Pass::Gather3d(Box::new((r, target)))
            }
            (Some(model), _) => {
                let kind = ProgramKind::ReprojectShift {
                    depth: match src.depth_kind {
                        // View distance is refused by `check` (ReprojectSource::validate).
                        DepthEncoding::ViewZ | DepthEncoding::ViewDistance => ShiftDepth::ViewZ,
                        DepthEncoding::Device { .. } => ShiftDepth::Device,
                        DepthEncoding::Disparity { .. } => ShiftDepth::Disparity,
                    },
                    scan: params.method == Method::ShiftScan,
                    scan_margin: SCAN_MARGIN as u32,
                };
                let rgba: Vec<u8> = crate::pass::pixels::rgb_to_rgba(&src.color.data);
                let depth: Vec<u8> = crate::pass::pixels::f32_to_bytes(&src.depth.data);
                let image = |bytes: Vec<u8>, format, label| {
                    device.upload(&ImageData::new(
                        w,
                        h,
                        format,
                        &rows.convert_rows(bytes, w as usize * 4),
                        label,
                    ))
                };
                let (alpha, beta) = src.depth_kind.affine_inverse_depth(&src.conv).unwrap_or((0.0, 0.0));
                // No valid depth: q_max = 0 makes every pixel invalid.
                let (q_min, q_max) = src.inverse_depth_range().unwrap_or((0.0, 0.0));
                let steps = match params.method {
                    Method::Shift { steps } => steps,
                    _ => 0,
                };
                Pass::Shift(Box::new(ShiftPass {
                    program: ShaderProgram::new(src.conv, kind),
                    color: image(rgba, Format::Rgba8, "reproject source colour")?,
                    depth: image(depth, Format::R32F, "reproject source depth")?,
                    block: ShiftParams {
                        u_a: model.a_px as f32,
                        u_b: model.b_px as f32,
                        u_alpha: alpha as f32,
                        u_beta: beta as f32,
                        u_q_min: q_min as f32,
                        u_q_max: q_max as f32,
                        u_tau_rel: params.tau_rel as f32,
                        u_steps: steps as i32,
                    },
                }))
            }
            (None, _) => return Err(Error::param("method", "shift method without a shift model")),
        };
        Ok(Reprojector {
            device,
            params,
            rows,
            width: w,
            height: h,
            pass,
        })
    }

    /// Render the target view (colour, target depth, mask) and the pass's timing.
    pub fn render(&mut self) -> Result<(ReprojectOutput, Timing)> {
        match &mut self.pass {
            Pass::Gather3d(g) => {
                let (r, target) = (&mut g.0, &g.1);
                let (a, ta) = r[0].render(target)?;
                let (b, tb) = r[1].render(target)?;
                let timing = Timing {
                    gpu_ms: ta.gpu_ms.zip(tb.gpu_ms).map(|(x, y)| x + y),
                    wall_ms: ta.wall_ms + tb.wall_ms,
                };
                let n = a.sources.len();
                let (mut color, mut depth, mut mask) = (vec![0u8; n * 3], vec![0f32; n], vec![0u8; n]);
                let (za, zb) = (a.depth()?, b.depth()?);
                let (ca, cb) = (a.color.as_ref(), b.color.as_ref());
                for i in 0..n {
                    let first = (a.sources[i] != 0, za.data[i] as f64);
                    let second = (b.sources[i] != 0, zb.data[i] as f64);
                    let (sources, z, c) = if merge_nearer(first, second) {
                        (&b.sources, zb, cb)
                    } else {
                        (&a.sources, za, ca)
                    };
                    let zi = z.data[i];
                    if sources[i] != 0 && zi.is_finite() {
                        if let Some(c) = c {
                            color[i * 3..i * 3 + 3].copy_from_slice(&c.data[i * 3..i * 3 + 3]);
                        }
                        depth[i] = zi;
                        mask[i] = 255;
                    }
                }
                let outputs = self.params.outputs;
                Ok((
                    ReprojectOutput {
                        color: outputs
                            .color
                            .then(|| RgbImage::new(target.width, target.height, color))
                            .transpose()?,
                        depth: outputs
                            .depth
                            .then(|| DepthMap::new(target.width, target.height, depth))
                            .transpose()?,
                        mask,
                    }
                    .finite(),
                    timing,
                ))
            }
            Pass::Shift(s) => {
                let (w, h) = (self.width, self.height);
                let outputs = self.params.outputs;
                let target = Target::view(w, h, outputs.color, outputs.depth, self.rows);
                let images = [s.color.id(), s.depth.id()];
                let draw = Draw::fullscreen(s.program, bytemuck::bytes_of(&s.block), &images, w, h);
                let mut out = self.device.render(&target, &[draw])?;
                // A non-finite depth makes its pixel invalid (`finite`, below).
                let (color, depth) = (out.color(0)?, out.depth(1)?);
                let mask = out.take(2, "reproject shift")?;
                Ok((ReprojectOutput { color, depth, mask }.finite(), out.timing))
            }
        }
    }
}
