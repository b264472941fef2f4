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

use crate::camera::mat4::{self, Mat4};
use crate::convention::RowOrder;
use crate::error::{Error, Result};
use crate::pass::{
    mat4_std140, Buffer, Device, Dispatch, Draw, Format, Groups, Image, ImageData, ImageId, Step, StorageImage, Target,
    ToDevice,
};
use crate::pass::{ProgramKind, ShaderProgram, Timing};
use crate::stereo::gather::{CyclopeanOutput, CyclopeanOutputs};
use crate::stereo::{MiddleCamera, StereoFrame};

crate::param_block! {
    /// The splat's parameters: shaders/cyclopean/splat.comp, member for member.
    pub struct SplatBlock("SplatParams") {
        u_inv_view_e: [[f32; 4]; 4],
        u_ray_basis_e: [[f32; 4]; 4],
        u_view_proj_m: [[f32; 4]; 4],
        u_view_m: [[f32; 4]; 4],
        u_grid: [i32; 2],
        u_size_m: [i32; 2],
    }
}

crate::param_block! {
    /// The edge snap's parameters: shaders/cyclopean/edge_snap.comp, member for member.
    pub struct EdgeSnapBlock("EdgeSnapParams") {
        u_parallax_px: f32,
        u_tolerance_px: f32,
        u_margin: i32,
    }
}

crate::param_block! {
    /// The gather draw's and the edge pass's parameters: shaders/cyclopean/splat_gather.glsl.
    pub struct SplatGatherBlock("SplatGatherParams") {
        u_view_proj_l: [[f32; 4]; 4],
        u_view_l: [[f32; 4]; 4],
        u_inv_view_l: [[f32; 4]; 4],
        u_ray_basis_l: [[f32; 4]; 4],
        u_view_proj_r: [[f32; 4]; 4],
        u_view_r: [[f32; 4]; 4],
        u_inv_view_r: [[f32; 4]; 4],
        u_ray_basis_r: [[f32; 4]; 4],
        u_view_m: [[f32; 4]; 4],
        u_inv_view_m: [[f32; 4]; 4],
        u_ray_basis_m: [[f32; 4]; 4],
        u_size_m: [f32; 2],
        u_parallax_px: f32,
        u_tolerance_px: f32,
        u_w_left: f32,
    }
}

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
        let mem = |eye: &crate::stereo::EyeInput| -> Result<Vec<f32>> {
            let d = super::forward::eye_distances(eye, frame.depth_kind, &frame.conv)?;
            let w = eye.depth.width as usize;
            let bytes = frame
                .conv
                .row_order
                .convert_rows(crate::pass::pixels::f32_to_bytes(&d), w * 4);
            Ok(crate::pass::pixels::bytes_to_f32(&bytes))
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
    color: Option<Image>,
    /// The distances as uploaded.
    raw: Option<Image>,
    /// Edge-snapped distances (when the params snap): what the passes read instead.
    snapped: Option<Image>,
    size: (u32, u32),
    view: Mat4,
    proj: Mat4,
}

impl EyeGpu {
    /// No images: a new eye before its first upload, and what a failed
    /// [`SplatRenderer::set_frame`] leaves (its next render is refused).
    fn empty() -> Self {
        EyeGpu {
            color: None,
            raw: None,
            snapped: None,
            size: (0, 0),
            view: [[0.0; 4]; 4],
            proj: [[0.0; 4]; 4],
        }
    }

    /// The colour and the distances the passes read (snapped where the params snap), or an
    /// error where a failed `set_frame` left no eye.
    fn images(&self) -> Result<(ImageId, ImageId)> {
        match (&self.color, self.snapped.as_ref().or(self.raw.as_ref())) {
            (Some(color), Some(dist)) => Ok((color.id(), dist.id())),
            _ => Err(Error::param(
                "splat-gather renderer",
                "holds no eyes: the last set_frame failed; give it a frame again",
            )),
        }
    }
}

/// Uploads one eye into `old`'s images where their shapes match (rewritten in place), new ones
/// otherwise, and snaps its distances when `snap` says so.
fn upload_eye(
    device: &Device,
    eye: &crate::stereo::EyeInput,
    dist: &[f32],
    rows: RowOrder,
    old: Option<EyeGpu>,
    snap: Option<(ShaderProgram, &EdgeSnapBlock)>,
) -> Result<EyeGpu> {
    let (w, h) = (eye.color.width, eye.color.height);
    device.check_image_size("eye size", w, h)?;
    let rgba = crate::pass::pixels::rgb_to_rgba(&eye.color.data);
    let mut gpu = old.unwrap_or_else(EyeGpu::empty);
    let resized = gpu.size != (w, h);
    let color = rows.convert_rows(rgba, w as usize * 4);
    let color = device.put_image(&mut gpu.color, &ImageData::rgba8(w, h, &color, "splat eye colour"))?;
    let dist = ImageData::r32f(w, h, dist, "splat eye distance");
    let raw = device.put_image(&mut gpu.raw, &dist)?;
    (gpu.size, gpu.view, gpu.proj) = ((w, h), eye.view, eye.proj);
    gpu.snapped = match (snap, gpu.snapped.take()) {
        (None, _) => None,
        (Some((program, block)), old) => {
            let out = match old {
                Some(out) if !resized => out,
                old => {
                    drop(old);
                    device.create_image(w, h, Format::R32F, "edge-snapped distances")?
                }
            };
            snap_edges(device, program, (w, h), [raw, color], block, &out)?;
            Some(out)
        }
    };
    Ok(gpu)
}

fn inverse(m: &Mat4, what: &str) -> Result<[[f32; 4]; 4]> {
    mat4::inverse(m)
        .map(|m| mat4_std140(&m))
        .ok_or_else(|| Error::param(what.to_string(), "singular"))
}

/// Both eyes of `frame` on `device` (into `old`'s images where they fit), edge-snapped when
/// `params` say so, and the frame's parallax unit.
fn upload_eyes(
    device: &Device,
    frame: &StereoFrame,
    params: &SplatParams,
    old: Option<[EyeGpu; 2]>,
) -> Result<([EyeGpu; 2], f64)> {
    // The middle camera does not change the eye data; any will do to derive it here.
    let probe = MiddleCamera {
        view: frame.left.view,
        proj: frame.left.proj,
        width: 1,
        height: 1,
    };
    let geo = SplatGeometry::new(frame, &probe)?;
    let program = ShaderProgram::new(frame.conv, ProgramKind::CyclopeanEdgeSnap);
    let block = params.edge_snap_margin.map(|margin| EdgeSnapBlock {
        u_parallax_px: geo.parallax_px as f32,
        u_tolerance_px: params.surface_tolerance_px as f32,
        u_margin: margin as i32,
    });
    let snap = block.as_ref().map(|b| (program, b));
    let rows = frame.conv.row_order;
    let [old_l, old_r] = old.map_or([None, None], |[l, r]| [Some(l), Some(r)]);
    let eyes = [
        upload_eye(device, &frame.left, &geo.dist_mem[0], rows, old_l, snap)?,
        upload_eye(device, &frame.right, &geo.dist_mem[1], rows, old_r, snap)?,
    ];
    Ok((eyes, geo.parallax_px))
}

/// One eye's distances (`images`: the uploaded distances, then the colour, both `size`) with
/// its depth breaks snapped to its colour edges, into `out` (edge_snap.comp).
fn snap_edges(
    device: &Device,
    program: ShaderProgram,
    (w, h): (u32, u32),
    images: [ImageId; 2],
    block: &EdgeSnapBlock,
    out: &Image,
) -> Result<()> {
    let storage = [StorageImage::Image(out.id())];
    device.run(
        None,
        &[Step::Dispatch(Dispatch {
            program,
            params: bytemuck::bytes_of(block),
            images: &images,
            storage_images: &storage,
            buffers: &[],
            groups: Groups::Fixed([w.div_ceil(8), h.div_ceil(8)]),
        })],
    )?;
    Ok(())
}

/// Per middle-view size: each eye's splat image and the edge-pixel list.
struct SizedTargets {
    size: (u32, u32),
    splats: [Image; 2],
    edges: Buffer,
}

/// A stereo frame on the GPU (GL or Vulkan), ready to render splat-gather views.
pub struct SplatRenderer {
    device: Device,
    /// The frame's conventions, which the programs were built for.
    conv: crate::convention::Conventions,
    splat: ShaderProgram,
    gather: ShaderProgram,
    /// The edge pass over the pixels the gather listed (shaders/cyclopean/splat_edges.comp).
    edges: ShaderProgram,
    params: SplatParams,
    outputs: CyclopeanOutputs,
    rows: RowOrder,
    eyes: [EyeGpu; 2],
    /// Kept to derive the geometry of each middle camera (its weights).
    frame_views: [Mat4; 2],
    parallax_px: f64,
    targets: Option<SizedTargets>,
}

impl SplatRenderer {
    /// Uploads `frame`'s eyes (edge-snapped when the params say so).
    pub fn new(
        device: impl ToDevice,
        frame: &StereoFrame,
        params: SplatParams,
        outputs: CyclopeanOutputs,
    ) -> Result<Self> {
        params.validate()?;
        let device = device.to_device()?;
        let (eyes, parallax_px) = upload_eyes(&device, frame, &params, None)?;
        Ok(SplatRenderer {
            conv: frame.conv,
            splat: ShaderProgram::new(frame.conv, ProgramKind::CyclopeanSplat),
            gather: ShaderProgram::new(frame.conv, ProgramKind::CyclopeanSplatGather),
            edges: ShaderProgram::new(frame.conv, ProgramKind::CyclopeanSplatEdges),
            device,
            params,
            outputs,
            rows: frame.conv.row_order,
            eyes,
            frame_views: [frame.left.view, frame.right.view],
            parallax_px,
            targets: None,
        })
    }

    /// The conventions the renderer was made for.
    pub fn conventions(&self) -> crate::convention::Conventions {
        self.conv
    }

    /// Replaces the eyes with `frame`'s, rewriting the images in place where the sizes match
    /// (a sequence's next frame allocates nothing); `frame` must have the conventions this
    /// renderer was made for.
    pub fn set_frame(&mut self, frame: &StereoFrame) -> Result<()> {
        if frame.conv != self.conv {
            return Err(Error::param(
                "splat-gather frame",
                "has other conventions than the renderer was made for",
            ));
        }
        let old = std::mem::replace(&mut self.eyes, [EyeGpu::empty(), EyeGpu::empty()]);
        (self.eyes, self.parallax_px) = upload_eyes(&self.device, frame, &self.params, Some(old))?;
        self.frame_views = [frame.left.view, frame.right.view];
        Ok(())
    }

    /// Renders the middle view of camera `mid`, with its times.
    pub fn render(&mut self, mid: &MiddleCamera) -> Result<(CyclopeanOutput, Timing)> {
        // Before the eyes' matrices are read: after a failed set_frame they are zero.
        let [(lc, ld), (rc, rd)] = [self.eyes[0].images()?, self.eyes[1].images()?];
        let (w, h) = (mid.width, mid.height);
        self.device.check_image_size("middle size", w, h)?;
        let w_left = left_weight(&self.frame_views[0], &self.frame_views[1], &mid.view)?;
        if self.targets.as_ref().is_none_or(|t| t.size != (w, h)) {
            self.targets = None;
            let splat = |label| self.device.create_image(w, h, Format::R32Ui, label);
            // The counter and the edge pass's 3 dispatch words, then room for every pixel.
            self.targets = Some(SizedTargets {
                size: (w, h),
                splats: [splat("splat left")?, splat("splat right")?],
                edges: self.device.create_buffer(4 + w as usize * h as usize, "edge pixels")?,
            });
        }
        let t = self.targets.as_ref().expect("allocated above");
        let view_proj_m = mat4_std140(&mat4::mul(&mid.proj, &mid.view));
        let splat_blocks = self
            .eyes
            .iter()
            .map(|eye| {
                Ok(SplatBlock {
                    u_inv_view_e: inverse(&eye.view, "eye view")?,
                    u_ray_basis_e: crate::stereo::ray_basis_std140(&eye.proj, "eye projection")?,
                    u_view_proj_m: view_proj_m,
                    u_view_m: mat4_std140(&mid.view),
                    u_grid: [eye.size.0 as i32, eye.size.1 as i32],
                    u_size_m: [w as i32, h as i32],
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let [l, r] = &self.eyes;
        let gather = SplatGatherBlock {
            u_view_proj_l: mat4_std140(&mat4::mul(&l.proj, &l.view)),
            u_view_l: mat4_std140(&l.view),
            u_inv_view_l: inverse(&l.view, "eye view")?,
            u_ray_basis_l: crate::stereo::ray_basis_std140(&l.proj, "eye projection")?,
            u_view_proj_r: mat4_std140(&mat4::mul(&r.proj, &r.view)),
            u_view_r: mat4_std140(&r.view),
            u_inv_view_r: inverse(&r.view, "eye view")?,
            u_ray_basis_r: crate::stereo::ray_basis_std140(&r.proj, "eye projection")?,
            u_view_m: mat4_std140(&mid.view),
            u_inv_view_m: inverse(&mid.view, "middle view")?,
            u_ray_basis_m: crate::stereo::ray_basis_std140(&mid.proj, "middle projection")?,
            u_size_m: [w as f32, h as f32],
            u_parallax_px: self.parallax_px as f32,
            u_tolerance_px: self.params.surface_tolerance_px as f32,
            u_w_left: w_left as f32,
        };
        let splat_images = [[ld], [rd]];
        let splat_targets = [
            [StorageImage::Image(t.splats[0].id())],
            [StorageImage::Image(t.splats[1].id())],
        ];
        let gather_images = [lc, ld, t.splats[0].id(), rc, rd, t.splats[1].id()];
        let edges = [t.edges.id()];
        let color_out = [StorageImage::Output(0)];
        let mut steps = vec![
            // "No surface" in both splat images (the driver fills them).
            Step::Clear {
                image: t.splats[0].id(),
                bits: u32::MAX,
            },
            Step::Clear {
                image: t.splats[1].id(),
                bits: u32::MAX,
            },
        ];
        // Pass 1: each eye splatted into its own image.
        for (k, eye) in self.eyes.iter().enumerate() {
            steps.push(Step::Dispatch(Dispatch {
                program: self.splat,
                params: bytemuck::bytes_of(&splat_blocks[k]),
                images: &splat_images[k],
                storage_images: &splat_targets[k],
                buffers: &[],
                groups: Groups::Fixed([eye.size.0.div_ceil(8), eye.size.1.div_ceil(8)]),
            }));
        }
        // No edge pixel yet: count 0, no work group (x), 1 (y), 1 (z).
        steps.push(Step::WriteBuffer {
            buffer: t.edges.id(),
            words: &[0, 0, 1, 1],
        });
        // Pass 2: gather and merge, listing the edge pixels.
        steps.push(Step::Draw(Draw {
            buffers: &edges,
            ..Draw::fullscreen(self.gather, bytemuck::bytes_of(&gather), &gather_images, w, h)
        }));
        // Pass 3: the listed pixels' colour mixed (colour only: without it, nothing to mix).
        if self.outputs.color {
            steps.push(Step::Dispatch(Dispatch {
                program: self.edges,
                params: bytemuck::bytes_of(&gather),
                images: &gather_images,
                storage_images: &color_out,
                buffers: &edges,
                groups: Groups::Indirect {
                    buffer: t.edges.id(),
                    offset_words: 1,
                },
            }));
        }
        let target = Target::view(w, h, self.outputs.color, self.outputs.depth, self.rows);
        let mut out = self.device.run(Some(&target), &steps)?;
        let (color, depth) = (out.color(0)?, out.depth(1)?);
        let sources = out.take(2, "cyclopean splat-gather")?;
        Ok((CyclopeanOutput { color, depth, sources }.finite(), out.timing))
    }
}
