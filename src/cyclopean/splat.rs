//! Splat-gather: the middle view for real stereo, where the gather walk's fixed point lands
//! behind thin near objects. Three GPU passes:
//!
//! 1. splat (shaders/cyclopean/splat.comp, into images the driver clears): every valid eye texel's surface point goes to the
//!    middle pixel its one-pixel footprint covers, nearest first (atomic min per eye). This says
//!    *which* surface each middle pixel sees from each eye; a pole one texel wide stays one
//!    pixel wide, so nothing behind it shows through.
//! 2. gather (shaders/cyclopean/splat_gather.frag over the functions of splat_gather.glsl): per
//!    eye, from that candidate depth (or a
//!    neighbour's, in the holes a splat leaves), one fixed-point step on the eye's surface
//!    interpolated in inverse depth over the bilinear taps on that surface gives the sub-pixel
//!    position, checked to land on the same surface, and the colour there (bilinear, the same
//!    taps). The eyes merge per pixel: on one surface, weighted by nearness to each eye and by
//!    the taps' weight (low at edges, where real pixels mix colours); else the nearer; a
//!    disocclusion from the one eye that sees it. It lists the pixels a depth edge may cross
//!    (two of it and its left and right neighbours different surfaces in an eye's splat).
//! 3. edges (shaders/cyclopean/splat_edges.comp, one invocation per listed pixel, dispatched
//!    indirectly by the count the gather kept): where the centre and two samples at +-1/3 px
//!    along x see different surfaces the colour is their mean, as a camera pixel integrates
//!    both surfaces: measured +0.5 dB on Cones, +0.2 to +0.4 dB on the one-eye Cones/Teddy
//!    reprojections, +0.0 to +0.1 dB with estimated disparities (a 1 px box; 2 samples gave
//!    less, 4 or 8 the same on the reprojections). A pass of its own, not a branch of the
//!    gather: llvmpipe runs both sides of every branch for every pixel, so the branch cost 40 %
//!    of the frame though 0.3 % of the built-in scene's pixels are at edges; on SIMT GPUs it
//!    keeps no warp waiting on a few edge lanes. 720p on llvmpipe: 2.4x the seed method's time
//!    as a branch, 1.6x as a pass (the built-in scene; 2.0x on Cones upsampled to 720p).
//!
//! Before both, once per frame, each eye's depth breaks are moved onto its colour edges where
//! they sit one texel off (shaders/cyclopean/edge_snap.comp, [`edge_snap`](super::edge_snap)).
//!
//! "Same surface" is about one pixel of full-baseline disparity (`SplatParams::surface_tolerance_px`),
//! a unit that means the same on every rig. The f64 twin is [`splat_reference`](super::splat_reference).

use super::{CyclopeanOutput, CyclopeanOutputs, MiddleCamera, StereoFrame};
use crate::camera::mat4::{self, Mat4};
use crate::convention::RowOrder;
use crate::error::{Error, Result};
use crate::gpu::{
    Attachment, Barrier, DrawState, Framebuffer, Gpu, GpuTimer, Program, ProgramKind, ShaderProgram, StorageBuffer,
    Texture, TextureFormat, Timing, VertexArray,
};

/// Settings of the splat-gather method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplatParams {
    /// Two depths are one surface when their full-baseline disparities differ by at most this
    /// many pixels (neighbouring texels of a slanted surface differ by its disparity gradient,
    /// well under 1 on real scenes; object edges by several pixels). Default 1.1, not 1:
    /// disparities quantised to 1/2^k px (Middlebury: 1/4) differ by exactly 1 px often, and
    /// a threshold on a quantisation step would be decided by f32 rounding.
    pub surface_tolerance_px: f64,
    /// Edge snap (see [`edge_snap`](super::edge_snap)): the colour evidence, in L1 RGB levels,
    /// by which a texel beside a depth break must look like the other side to join it; None:
    /// the disparities as given. Default 80 (about 27 levels per channel): well above sensor
    /// noise and texture within a surface, so estimated disparities are left as they are
    /// (measured within +-0.03 dB of no snap), while whole-texel colour edges qualify.
    pub edge_snap_margin: Option<u32>,
}

impl Default for SplatParams {
    fn default() -> Self {
        SplatParams {
            surface_tolerance_px: 1.1,
            edge_snap_margin: Some(80),
        }
    }
}

impl SplatParams {
    /// Refuses a non-positive or non-finite surface tolerance and an edge-snap margin above 765 levels.
    pub fn validate(&self) -> Result<()> {
        if !(self.surface_tolerance_px.is_finite() && self.surface_tolerance_px > 0.0) {
            return Err(Error::param(
                "surface tolerance",
                format!("{} px must be finite and > 0", self.surface_tolerance_px),
            ));
        }
        if let Some(m) = self.edge_snap_margin {
            if m > 765 {
                return Err(Error::param(
                    "edge snap margin",
                    format!("{m} levels: at most 765 (3 x 255); None disables it"),
                ));
            }
        }
        Ok(())
    }
}

/// What both implementations derive from the frame and the middle camera.
pub struct SplatGeometry {
    /// Per eye view distance (0 = invalid), rows in memory order.
    pub dist_mem: [Vec<f32>; 2],
    /// focal (px) x baseline (m): full-baseline disparity = parallax_px / distance.
    pub parallax_px: f64,
    /// Weight of the left eye where both see one surface: the middle camera's nearness to it
    /// (1 at the left eye, 0 at the right).
    pub w_left: f64,
    /// World -> GL eye transform of the middle camera, row-major.
    pub view_m: Mat4,
}

fn centre(view: &Mat4) -> Result<[f64; 3]> {
    let inv = mat4::inverse(view).ok_or_else(|| Error::param("view matrix", "singular"))?;
    Ok([inv[0][3], inv[1][3], inv[2][3]])
}

fn dist3(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// [`SplatGeometry::w_left`] of eyes and a middle camera given by their view matrices.
fn left_weight(left_view: &Mat4, right_view: &Mat4, mid_view: &Mat4) -> Result<f64> {
    let (cl, cr, cm) = (centre(left_view)?, centre(right_view)?, centre(mid_view)?);
    let (dl, dr) = (dist3(cm, cl), dist3(cm, cr));
    Ok(if dl + dr > 0.0 { dr / (dl + dr) } else { 0.5 })
}

impl SplatGeometry {
    /// Eye distances and rig weights of `frame` seen from `mid` (the frame is validated first).
    pub fn new(frame: &StereoFrame, mid: &MiddleCamera) -> Result<Self> {
        frame.validate()?;
        let baseline = dist3(centre(&frame.left.view)?, centre(&frame.right.view)?);
        // GL projection: x_ndc = P00 x / -z, so the focal length in pixels is P00 w / 2.
        let focal = frame.left.proj[0][0].abs() * frame.left.color.width as f64 / 2.0;
        let parallax_px = focal * baseline;
        if !(parallax_px.is_finite() && parallax_px > 0.0) {
            return Err(Error::param(
                "eye cameras",
                "the splat method needs two distinct eye positions (baseline > 0)",
            ));
        }
        let mem = |eye: &super::EyeInput| -> Result<Vec<f32>> {
            let d = super::forward::eye_distances(eye, frame.depth_kind, &frame.conv)?;
            let w = eye.depth.width as usize;
            let bytes = frame
                .conv
                .row_order
                .convert_rows(crate::gpu::pixels::f32_to_bytes(&d), w * 4);
            Ok(crate::gpu::pixels::bytes_to_f32(&bytes))
        };
        Ok(SplatGeometry {
            dist_mem: [mem(&frame.left)?, mem(&frame.right)?],
            parallax_px,
            w_left: left_weight(&frame.left.view, &frame.right.view, &mid.view)?,
            view_m: mid.view,
        })
    }
}

struct EyeGpu {
    color: Texture,
    dist: Texture,
    view: Mat4,
    proj: Mat4,
}

/// One eye's distances with its depth breaks snapped to its colour edges (edge_snap.comp).
fn snap_edges(
    gpu: &Gpu,
    snap: &Program,
    eye: &EyeGpu,
    parallax_px: f64,
    params: &SplatParams,
    margin: u32,
) -> Result<Texture> {
    let (w, h) = (eye.dist.width(), eye.dist.height());
    let out = Texture::new(gpu, w, h, TextureFormat::R32F, None)?.with_label("edge-snapped distances");
    snap.bind();
    eye.dist.bind(0);
    eye.color.bind(1);
    snap.set_i32("u_dist", 0);
    snap.set_i32("u_color", 1);
    snap.set_f32("u_parallax_px", parallax_px as f32);
    snap.set_f32("u_tolerance_px", params.surface_tolerance_px as f32);
    snap.set_i32("u_margin", margin as i32);
    {
        let _image = out.bind_image(0)?;
        snap.dispatch([w.div_ceil(8), h.div_ceil(8)]);
    }
    // The snapped distances before the later passes' texel fetches.
    gpu.memory_barrier(Barrier::TextureFetch);
    gpu.check("cyclopean edge snap")?;
    Ok(out)
}

/// A stereo frame on the GPU, ready to render splat-gather views.
pub struct SplatRenderer {
    gpu: Gpu,
    splat: Program,
    gather: Program,
    /// The edge pass over the pixels the gather listed (shaders/cyclopean/splat_edges.comp).
    edges: Program,
    params: SplatParams,
    outputs: CyclopeanOutputs,
    rows: RowOrder,
    frame_eyes: [(u32, u32); 2],
    eyes: [EyeGpu; 2],
    /// Kept to derive the geometry of each middle camera (its weights).
    frame_views: [Mat4; 2],
    parallax_px: f64,
    vao: VertexArray,
    /// Per view size: its framebuffer; as the two attachments of a second one (cleared to "no
    /// surface" by the driver each frame), each eye's splat image; the edge-pixel list.
    targets: Option<(Framebuffer, Framebuffer, StorageBuffer)>,
}

impl SplatRenderer {
    /// Uploads `frame`'s eyes (edge-snapped when the params say so) and builds both programs.
    pub fn new(gpu: &Gpu, frame: &StereoFrame, params: SplatParams, outputs: CyclopeanOutputs) -> Result<Self> {
        params.validate()?;
        // The middle camera does not change the eye data; any will do to derive it here.
        let probe = MiddleCamera {
            view: frame.left.view,
            proj: frame.left.proj,
            width: 1,
            height: 1,
        };
        let geo = SplatGeometry::new(frame, &probe)?;
        let upload = |eye: &super::EyeInput, dist: &[f32]| -> Result<EyeGpu> {
            let (w, h) = (eye.color.width, eye.color.height);
            let rgba = crate::gpu::pixels::rgb_to_rgba(&eye.color.data);
            Ok(EyeGpu {
                color: Texture::new(
                    gpu,
                    w,
                    h,
                    TextureFormat::Rgba8,
                    Some(&frame.conv.row_order.convert_rows(rgba, w as usize * 4)),
                )?
                .with_label("splat eye colour"),
                dist: Texture::new(
                    gpu,
                    w,
                    h,
                    TextureFormat::R32F,
                    Some(&crate::gpu::pixels::f32_to_bytes(dist)),
                )?
                .with_label("splat eye distance"),
                view: eye.view,
                proj: eye.proj,
            })
        };
        let mut eyes = [
            upload(&frame.left, &geo.dist_mem[0])?,
            upload(&frame.right, &geo.dist_mem[1])?,
        ];
        if let Some(margin) = params.edge_snap_margin {
            let snap = ShaderProgram::new(frame.conv, ProgramKind::CyclopeanEdgeSnap).build(gpu)?;
            for eye in &mut eyes {
                eye.dist = snap_edges(gpu, &snap, eye, geo.parallax_px, &params, margin)?;
            }
        }
        Ok(SplatRenderer {
            gpu: gpu.clone(),
            splat: ShaderProgram::new(frame.conv, ProgramKind::CyclopeanSplat).build(gpu)?,
            gather: ShaderProgram::new(frame.conv, ProgramKind::CyclopeanSplatGather).build(gpu)?,
            edges: ShaderProgram::new(frame.conv, ProgramKind::CyclopeanSplatEdges).build(gpu)?,
            params,
            outputs,
            rows: frame.conv.row_order,
            frame_eyes: [
                (frame.left.color.width, frame.left.color.height),
                (frame.right.color.width, frame.right.color.height),
            ],
            eyes,
            frame_views: [frame.left.view, frame.right.view],
            parallax_px: geo.parallax_px,
            vao: VertexArray::new(gpu)?.with_label("splat-gather vertex array"),
            targets: None,
        })
    }

    /// Renders the middle view of camera `mid`, with its times.
    pub fn render(&mut self, mid: &MiddleCamera) -> Result<(CyclopeanOutput, Timing)> {
        let (w, h) = (mid.width, mid.height);
        self.gpu.check_image_size("middle size", w, h)?;
        let inv = |m: &Mat4, what: &str| mat4::inverse(m).ok_or_else(|| Error::param(what.to_string(), "singular"));
        let w_left = left_weight(&self.frame_views[0], &self.frame_views[1], &mid.view)?;
        if !matches!(&self.targets, Some((f, ..)) if f.width() == w && f.height() == h) {
            self.targets = None;
            let slot = |wanted: bool, format| {
                wanted.then_some(Attachment {
                    format,
                    clear: [0.0; 4],
                })
            };
            let fb = Framebuffer::new(
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
            .with_label("splat-gather target");
            // 0xFFFFFFFF, "no surface": the clear's f32 is converted with saturation
            // (u32::MAX as f32 rounds up to 2^32, which saturates back to u32::MAX).
            let none = Some(Attachment {
                format: TextureFormat::R32Ui,
                clear: [u32::MAX as f32; 4],
            });
            let splats = Framebuffer::new(&self.gpu, w, h, &[none, none], false)?.with_label("splat left, right");
            // The counter and the edge pass's 3 dispatch words, then room for every pixel.
            let edges = StorageBuffer::new(&self.gpu, 4 + w as usize * h as usize)?.with_label("edge pixels");
            self.targets = Some((fb, splats, edges));
        }
        let (fb, splats, edges) = self.targets.as_ref().expect("allocated above");
        let gpu = &self.gpu;
        let timer = GpuTimer::start(gpu);
        let view_proj_m = mat4::mul(&mid.proj, &mid.view);
        // Pass 1: clear and splat each eye into its own image.
        splats.clear();
        let splats: [&Texture; 2] = [0, 1].map(|k| splats.color(k).expect("two attachments"));
        let s = &self.splat;
        s.bind();
        s.set_mat4_rows("u_view_proj_m", &view_proj_m);
        s.set_mat4_rows("u_view_m", &mid.view);
        s.set_ivec2("u_size_m", [w as i32, h as i32]);
        s.set_i32("u_dist", 0);
        for (eye, (size, target)) in self.eyes.iter().zip(self.frame_eyes.iter().zip(splats)) {
            let _image = target.bind_image(0)?;
            eye.dist.bind(0);
            s.set_ivec2("u_grid", [size.0 as i32, size.1 as i32]);
            s.set_mat4_rows("u_inv_view_e", &inv(&eye.view, "eye view")?);
            s.set_mat4_rows("u_inv_proj_e", &inv(&eye.proj, "eye projection")?);
            s.dispatch([size.0.div_ceil(8), size.1.div_ceil(8)]);
        }
        // The atomics before the gather's texel fetches.
        gpu.memory_barrier(Barrier::TextureFetch);
        gpu.check("cyclopean splat")?;
        // Pass 2: gather and merge.
        let pass = fb.begin_pass(DrawState::default(), 1.0);
        for (k, eye) in self.eyes.iter().enumerate() {
            eye.color.bind(3 * k as u32);
            eye.dist.bind(3 * k as u32 + 1);
            splats[k].bind(3 * k as u32 + 2);
        }
        // No edge pixel yet: count 0, no work group (x), 1 (y), 1 (z).
        edges.write_head(&[0, 0, 1, 1]);
        edges.bind_storage(0);
        // The centre samples, then the listed edge pixels over them (same inputs, uniforms).
        self.bind_gather_inputs(&self.gather, mid, w_left)?;
        pass.draw_fullscreen(&self.vao);
        // Edge mixing changes colour only: without a colour attachment there is nothing to mix.
        if let Some(color) = fb.color(0) {
            // The list and its counts before the edge pass reads them.
            gpu.memory_barrier(Barrier::StorageAndCommand);
            self.bind_gather_inputs(&self.edges, mid, w_left)?;
            let _image = color.bind_image(0)?;
            self.edges.set_i32("u_color_out", 0);
            self.edges.dispatch_indirect(edges, 1);
            // The rewritten texels before the readback.
            gpu.memory_barrier(Barrier::Framebuffer);
        }
        drop(pass);
        gpu.check("cyclopean splat gather")?;
        let out = super::render::read_output(fb, self.rows)?;
        let timing = timer.stop();
        Ok((out, timing))
    }

    /// Binds `p` (the gather draw or the edge pass: one set of inputs, splat_gather.glsl) and
    /// sets its uniforms for view `mid`: each eye's texture units (colour 3k, distance 3k + 1,
    /// splat 3k + 2, bound by the caller) and cameras, the middle camera, the rig's constants.
    fn bind_gather_inputs(&self, p: &Program, mid: &MiddleCamera, w_left: f64) -> Result<()> {
        let inv = |m: &Mat4, what: &str| mat4::inverse(m).ok_or_else(|| Error::param(what.to_string(), "singular"));
        p.bind();
        for (k, (eye, sfx)) in self.eyes.iter().zip(["l", "r"]).enumerate() {
            p.set_i32(&format!("u_color_{sfx}"), 3 * k as i32);
            p.set_i32(&format!("u_dist_{sfx}"), 3 * k as i32 + 1);
            p.set_i32(&format!("u_splat_{sfx}"), 3 * k as i32 + 2);
            p.set_mat4_rows(&format!("u_view_proj_{sfx}"), &mat4::mul(&eye.proj, &eye.view));
            p.set_mat4_rows(&format!("u_view_{sfx}"), &eye.view);
            p.set_mat4_rows(&format!("u_inv_view_{sfx}"), &inv(&eye.view, "eye view")?);
            p.set_mat4_rows(&format!("u_inv_proj_{sfx}"), &inv(&eye.proj, "eye projection")?);
        }
        p.set_mat4_rows("u_view_m", &mid.view);
        p.set_mat4_rows("u_inv_view_m", &inv(&mid.view, "middle view")?);
        p.set_mat4_rows("u_inv_proj_m", &inv(&mid.proj, "middle projection")?);
        p.set_vec2("u_size_m", [mid.width as f32, mid.height as f32]);
        p.set_f32("u_parallax_px", self.parallax_px as f32);
        p.set_f32("u_tolerance_px", self.params.surface_tolerance_px as f32);
        p.set_f32("u_w_left", w_left as f32);
        Ok(())
    }
}
