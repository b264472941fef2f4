//! GPU stitch: both eyes' faces uploaded once as atlases (face k at columns [k n, (k + 1) n):
//! GLSL cannot index a sampler array per pixel), one full-screen draw per eye into a
//! W x 2H top-bottom target (left eye on top), rows in the memory order of the row-order
//! convention, read back top-down. Described once ([`crate::pass`]), run by the GL or the
//! Vulkan executor. The ray distance is a second colour output of the same draws, attached,
//! read back and paid for only when asked for ([`StitchRenderer::render_outputs`]).

use super::{face_camera, CubeFace, FaceSet, Method, Side, StitchParams, REPROJECT_STEPS};
use crate::convention::{Conventions, RowOrder};
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use crate::output::OutputSet;
use crate::pass::shaders::StitchBlend;
use crate::pass::{
    mat4_std140, Device, Draw, Format, Image, ImageData, ProgramKind, ShaderProgram, Target, Timing, ToDevice,
};

crate::param_block! {
    /// One eye's draw: shaders/stitch/stitch_params.glsl, member for member.
    pub struct StitchBlock("StitchParams") {
        u_rot: [[[f32; 4]; 4]; 6],
        u_eye: [[f32; 4]; 6],
        u_centre: [f32; 4],
        u_size: [i32; 2],
        u_f: f32,
        u_c: f32,
        u_n: i32,
        u_half_ipd: f32,
        u_fade_start: f32,
        u_side: f32,
        u_overlap: f32,
        u_row0: i32,
    }
}

struct EyeAtlas {
    color: Image,
    depth: Image,
    side: Side,
    eyes: [[f64; 3]; 6],
}

/// The six faces side by side in one atlas per channel, rows in memory order under `rows`.
fn upload(device: &Device, set: &FaceSet, rows: RowOrder) -> Result<EyeAtlas> {
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
        color: device.upload(&ImageData::rgba8(w, h, &rgba, "stitch face colour atlas"))?,
        depth: device.upload(&ImageData::new(w, h, Format::R32F, &depth, "stitch face depth atlas"))?,
        side: set.side,
        eyes: CubeFace::ALL.map(|f| f.pose(&set.rig, set.side).position),
    })
}

/// A stitch's images, top-bottom (left eye on top), rows top-down; None where not asked for.
#[derive(Debug, Clone)]
pub struct StitchOutput {
    /// The colour equirects.
    pub color: Option<RgbImage>,
    /// Per eye, the distance in metres along each pixel's ODS ray, from its origin on the
    /// viewing circle, to the surface its colour came from (see [`super`]); 0 = sky.
    pub distance: Option<DepthMap>,
    /// Render time.
    pub timing: Timing,
}

/// Refuses an output the stitch does not make (a mask: distance 0 already marks the sky) and
/// an empty set.
pub fn check_outputs(outputs: OutputSet) -> Result<()> {
    if outputs.mask {
        return Err(Error::param(
            "outputs",
            "stitch writes rgb and depth (the ray distance, 0 = sky); it has no mask",
        ));
    }
    if !(outputs.rgb || outputs.depth) {
        return Err(Error::param("outputs", "at least one of rgb, depth"));
    }
    Ok(())
}

/// A stereo face capture on the GPU (GL or Vulkan), ready to stitch with any method.
pub struct StitchRenderer {
    device: Device,
    conv: Conventions,
    left: EyeAtlas,
    right: EyeAtlas,
    template: FaceSet,
    /// Face side length (the template holds no faces).
    face_size: u32,
}

impl StitchRenderer {
    /// `left` and `right` must share rig, FOV and face size. Default conventions.
    pub fn new(device: impl ToDevice, left: &FaceSet, right: &FaceSet) -> Result<Self> {
        Self::with_conventions(device, left, right, Conventions::default())
    }

    /// As [`Self::new`], with the GPU-side row order of `conv` (faces and the equirect are
    /// stored and rendered in that memory order; the output is top-down either way). The NDC
    /// range and reversed-Z do not reach this pass: face depth is view Z (convert device depth
    /// with [`super::faces::view_z_of`]) and there is no depth buffer.
    pub fn with_conventions(device: impl ToDevice, left: &FaceSet, right: &FaceSet, conv: Conventions) -> Result<Self> {
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
        let device = device.to_device()?;
        // The six faces of an eye sit side by side in one texture.
        device.check_image_size("face atlas (6 x face size)", 6 * left.size(), left.size())?;
        Ok(StitchRenderer {
            left: upload(&device, left, conv.row_order)?,
            right: upload(&device, right, conv.row_order)?,
            device,
            conv,
            template: left.clone_meta(),
            face_size: left.size(),
        })
    }

    /// Top-bottom stereo equirect (left eye on top), `params.width` x `2 params.height`.
    pub fn render(&mut self, params: &StitchParams) -> Result<(RgbImage, Timing)> {
        let out = self.render_outputs(params, OutputSet::RGB)?;
        let color = out
            .color
            .ok_or_else(|| Error::param("outputs", "colour asked for, none read"))?;
        Ok((color, out.timing))
    }

    /// As [`Self::render`], with the outputs asked for (rgb, depth: the ray distance); the
    /// others get no attachment and no readback.
    pub fn render_outputs(&mut self, params: &StitchParams, outputs: OutputSet) -> Result<StitchOutput> {
        check_outputs(outputs)?;
        params.validate(&self.template)?;
        let (w, h) = (params.width, params.height);
        // Top-bottom: both eyes in one image of 2 h rows.
        self.device.check_image_size("equirect size", w, 2 * h)?;
        let program = ShaderProgram::new(
            self.conv,
            ProgramKind::Stitch {
                method: match params.method {
                    Method::Blend => StitchBlend::Blend,
                    Method::BorderWeight => StitchBlend::BorderWeight,
                    Method::Reproject => StitchBlend::Reproject,
                },
                reproject_steps: REPROJECT_STEPS,
            },
        );
        let set = &self.template;
        let n = self.face_size;
        let cam = face_camera(n, set.fov_deg);
        let c = set.rig.centre;
        let rotation = |f: &CubeFace| {
            let r = f.rotation();
            mat4_std140(&[
                [r[0][0], r[0][1], r[0][2], 0.0],
                [r[1][0], r[1][1], r[1][2], 0.0],
                [r[2][0], r[2][1], r[2][2], 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ])
        };
        // Left eye on top of the image: bottom-up memory holds it in the upper half of the rows.
        let (left_row0, right_row0) = match self.conv.row_order {
            RowOrder::TopDown => (0, h),
            RowOrder::BottomUp => (h, 0),
        };
        let block = |eye: &EyeAtlas, row0: u32| StitchBlock {
            u_rot: CubeFace::ALL.map(|f| rotation(&f)),
            u_eye: eye.eyes.map(|e| [e[0] as f32, e[1] as f32, e[2] as f32, 1.0]),
            u_centre: [c[0] as f32, c[1] as f32, c[2] as f32, 1.0],
            u_size: [w as i32, h as i32],
            u_f: cam.k.fx as f32,
            u_c: cam.k.cx as f32,
            u_n: n as i32,
            u_half_ipd: (0.5 * set.rig.ipd) as f32,
            u_fade_start: set.rig.pole_fade_start_deg.to_radians() as f32,
            u_side: eye.side.sign() as f32,
            u_overlap: params.overlap_deg.to_radians() as f32,
            u_row0: row0 as i32,
        };
        let blocks = [block(&self.left, left_row0), block(&self.right, right_row0)];
        let images = [
            [self.left.color.id(), self.left.depth.id()],
            [self.right.color.id(), self.right.depth.id()],
        ];
        let draws: Vec<Draw> = [(left_row0, 0), (right_row0, 1)]
            .into_iter()
            .map(|(row0, e)| Draw {
                // One full-screen triangle into this eye's half of the target.
                viewport: [0, row0, w, h],
                ..Draw::fullscreen(program, bytemuck::bytes_of(&blocks[e]), &images[e], w, h)
            })
            .collect();
        let target = Target {
            width: w,
            height: 2 * h,
            outputs: vec![
                outputs.rgb.then_some(Format::Rgba8),
                outputs.depth.then_some(Format::R32F),
            ],
            rows: self.conv.row_order,
            depth_test: None,
        };
        let mut out = self.device.render(&target, &draws)?;
        let color = match outputs.rgb {
            true => Some(RgbImage::new(w, 2 * h, out.take(0, "stitch")?)?),
            false => None,
        };
        let distance = match outputs.depth {
            true => {
                let mut t = out.take_floats(1, "stitch distance")?;
                crate::view::clear_non_finite(Some(&mut t), None);
                Some(DepthMap::new(w, 2 * h, t)?)
            }
            false => None,
        };
        Ok(StitchOutput {
            color,
            distance,
            timing: out.timing,
        })
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
