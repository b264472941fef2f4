//! Temporal accumulation over a sequence of middle views (seed 000 section 8, "TAA-lite"): the
//! previous result is forward-projected into the current middle camera with its depth (nearest
//! surface per pixel wins); where the current frame is valid and the history agrees in depth,
//! colours are blended exponentially; where the current frame has a hole (disocclusion) the
//! history fills it (source bit 4). With `alpha` 1 the history only fills holes: what a
//! spectator stream wants when objects move (blending without motion vectors ghosts them).
//!
//! Only pixels an eye rendered are carried into the next frame ([`carried`]: not at a depth
//! break or beside a hole either); a pixel the history filled is not carried again. Each carry moves a texel to the nearest pixel centre (up to half a pixel
//! off), so a fill carried frame after frame drifts: on the built-in scene's 8-frame dolly with
//! the spectator 0.1 m right of the head (`viewsynth scene --frames 8 --dolly 0.03
//! --spectator-offset 0.1`), carrying fills lost 4.7 dB by frame 5 against carrying them once
//! (measured before edge texels were dropped too).
//!
//! Two passes on either executor ([`Accumulator`]): shaders/cyclopean/temporal_reproject.comp
//! moves the history's texels (nearest distance, then that texel, as an atomic min each) and
//! temporal_compose.frag applies the rule. [`TemporalAccumulator`] is the f64 twin: the same
//! texel choices, so the two differ only where f32 and f64 disagree on which pixel a texel
//! lands in or which texel is nearer (texels within about 1e-4 px of a pixel edge), and by one
//! level where a blended colour rounds at a tie.

use crate::camera::mat4;
use crate::convention::{Conventions, RowOrder};
use crate::error::{Error, Result};
use crate::pass::{
    mat4_std140, Device, Dispatch, Draw, Format, Groups, Image, ImageData, ImageId, Step, StorageImage, Target,
    ToDevice,
};
use crate::pass::{ProgramKind, ShaderProgram};
use crate::stereo::gather::CyclopeanOutput;
use crate::stereo::MiddleCamera;

/// Source bit of pixels filled from the history (temporal_compose.frag's FROM_HISTORY).
pub const FROM_HISTORY: u8 = 4;

/// Weight of the current frame the sequence mode uses: the history only fills holes.
pub const FILL_ONLY: f64 = 1.0;
/// Relative distance difference above which history is taken for another surface.
pub const DEPTH_TOLERANCE: f64 = 0.02;

crate::param_block! {
    /// shaders/cyclopean/temporal_params.glsl, member for member.
    pub struct TemporalParams("TemporalParams") {
        u_inv_view_h: [[f32; 4]; 4],
        u_ray_basis_h: [[f32; 4]; 4],
        u_view_proj_m: [[f32; 4]; 4],
        u_view_m: [[f32; 4]; 4],
        u_size_h: [i32; 2],
        u_size_m: [i32; 2],
        u_stage: u32,
        u_flip_rows: i32,
        u_alpha: f32,
        u_depth_tolerance: f32,
    }
}

/// The rule's settings, checked: `alpha` in (0, 1] weighs the current frame, `depth_tolerance`
/// (relative, > 0) rejects history at another depth.
pub(super) fn check_rule(alpha: f64, depth_tolerance: f64) -> Result<()> {
    if !(alpha > 0.0 && alpha <= 1.0) {
        return Err(Error::param("temporal alpha", format!("{alpha} outside (0, 1]")));
    }
    if !(depth_tolerance.is_finite() && depth_tolerance > 0.0) {
        return Err(Error::param(
            "temporal depth tolerance",
            format!("{depth_tolerance} must be > 0"),
        ));
    }
    Ok(())
}

/// The history one device holds: the previous accumulated view as uploaded, and its camera.
struct History {
    mid: MiddleCamera,
    /// Colour (RGBA8), distance (R32F) and source bits (R8UI), memory rows.
    images: [Option<Image>; 3],
    /// Their ids, as uploaded.
    ids: [ImageId; 3],
}

/// The temporal accumulation on one device (GL or Vulkan): [`TemporalAccumulator`]'s rule, run
/// as two passes. Feed it the frames in order; [`Accumulator::reset`] at a cut.
pub struct Accumulator {
    device: Device,
    alpha: f64,
    depth_tolerance: f64,
    conv: Conventions,
    history: Option<History>,
    /// The current frame's colour, distance and source bits, rewritten in place each frame.
    current: [Option<Image>; 3],
    /// Nearest reprojected distance and its texel per pixel, for the current size.
    scratch: Option<((u32, u32), [Image; 2])>,
}

impl Accumulator {
    /// An empty history on `device`; see [`TemporalAccumulator::new`] for the settings.
    pub fn new(device: impl ToDevice, alpha: f64, depth_tolerance: f64, conv: Conventions) -> Result<Self> {
        check_rule(alpha, depth_tolerance)?;
        Ok(Accumulator {
            device: device.to_device()?,
            alpha,
            depth_tolerance,
            conv,
            history: None,
            current: [None, None, None],
            scratch: None,
        })
    }

    /// Forgets the history: the next frame is taken as it is.
    pub fn reset(&mut self) {
        self.history = None;
    }

    /// Uploads a view's planes in memory rows into `slots`, rewriting them in place.
    fn put(
        device: &Device,
        slots: &mut [Option<Image>; 3],
        out: &CyclopeanOutput,
        mid: &MiddleCamera,
        conv: &Conventions,
        what: &str,
    ) -> Result<[ImageId; 3]> {
        let (color, depth) = color_and_depth(out)?;
        let (w, h) = (mid.width, mid.height);
        let rows = conv.row_order;
        let rgba = rows.convert_rows(crate::pass::pixels::rgb_to_rgba(&color.data), w as usize * 4);
        let dist = rows.convert_rows(bytemuck::cast_slice(&depth.data).to_vec(), w as usize * 4);
        let sources = rows.convert_rows(out.sources.clone(), w as usize);
        let [c, d, s] = slots;
        let put = |slot, format, bytes: &[u8]| device.put_image(slot, &ImageData::new(w, h, format, bytes, what));
        Ok([
            put(c, Format::Rgba8, &rgba)?,
            put(d, Format::R32F, &dist)?,
            put(s, Format::R8Ui, &sources)?,
        ])
    }

    /// Accumulates `current` (seen by `mid`, top-down rows) with the history; returns the
    /// accumulated frame, which becomes the history.
    pub fn push(&mut self, current: &CyclopeanOutput, mid: &MiddleCamera) -> Result<CyclopeanOutput> {
        let (w, h) = (mid.width, mid.height);
        let (color, _) = color_and_depth(current)?;
        if current.sources.len() != (w * h) as usize || color.width != w || color.height != h {
            return Err(Error::SizeMismatch {
                message: format!("frame does not match the middle camera's {w}x{h}"),
            });
        }
        let Some(hist) = &self.history else {
            let out = current.clone().finite();
            self.keep(&out, mid)?;
            return Ok(out);
        };
        let d = &self.device;
        d.check_image_size("middle size", w, h)?;
        let [cc, cd, cs] = Self::put(d, &mut self.current, current, mid, &self.conv, "temporal current")?;
        // Kept for the next frame of this size; another size frees them before making new ones.
        let [nearest, winner] = match self.scratch.take() {
            Some((size, images)) if size == (w, h) => images,
            old => {
                drop(old);
                let make = |label| d.create_image(w, h, Format::R32Ui, label);
                [make("temporal nearest")?, make("temporal winner")?]
            }
        };
        let singular = |what: &str| Error::param(what.to_string(), "singular");
        let inv = |m: &mat4::Mat4, what: &str| mat4::inverse(m).map(|m| mat4_std140(&m)).ok_or_else(|| singular(what));
        let stage = |u_stage| -> Result<TemporalParams> {
            Ok(TemporalParams {
                u_inv_view_h: inv(&hist.mid.view, "previous middle view")?,
                u_ray_basis_h: crate::stereo::ray_basis_std140(&hist.mid.proj, "previous middle projection")?,
                u_view_proj_m: mat4_std140(&mat4::mul(&mid.proj, &mid.view)),
                u_view_m: mat4_std140(&mid.view),
                u_size_h: [hist.mid.width as i32, hist.mid.height as i32],
                u_size_m: [w as i32, h as i32],
                u_stage,
                u_flip_rows: (self.conv.row_order == RowOrder::BottomUp).into(),
                u_alpha: self.alpha as f32,
                u_depth_tolerance: self.depth_tolerance as f32,
            })
        };
        let blocks = [stage(0)?, stage(1)?];
        let [hc, hd, hs] = hist.ids;
        let reproject_images = [hd, hs];
        let storage = [StorageImage::Image(nearest.id()), StorageImage::Image(winner.id())];
        let compose_images = [cc, cd, cs, hc, nearest.id(), winner.id()];
        let groups = Groups::Fixed([hist.mid.width.div_ceil(8), hist.mid.height.div_ceil(8)]);
        let reproject = |k: usize| {
            Step::Dispatch(Dispatch {
                program: ShaderProgram::new(self.conv, ProgramKind::CyclopeanTemporalReproject { winner: k == 1 }),
                params: bytemuck::bytes_of(&blocks[k]),
                images: &reproject_images,
                storage_images: &storage,
                buffers: &[],
                groups,
            })
        };
        let steps = [
            Step::Clear {
                image: nearest.id(),
                bits: u32::MAX,
            },
            Step::Clear {
                image: winner.id(),
                bits: u32::MAX,
            },
            reproject(0),
            reproject(1),
            Step::Draw(Draw::fullscreen(
                ShaderProgram::new(self.conv, ProgramKind::CyclopeanTemporalCompose),
                bytemuck::bytes_of(&blocks[1]),
                &compose_images,
                w,
                h,
            )),
        ];
        let target = Target::view(w, h, true, true, self.conv.row_order);
        let mut r = self.device.run(Some(&target), &steps)?;
        self.scratch = Some(((w, h), [nearest, winner]));
        let out = CyclopeanOutput {
            color: r.color(0)?,
            depth: r.depth(1)?,
            sources: r.take(2, "temporal accumulation")?,
        }
        .finite();
        self.keep(&out, mid)?;
        Ok(out)
    }

    /// `out` becomes the history (uploaded now: the next frame reads it on the device).
    fn keep(&mut self, out: &CyclopeanOutput, mid: &MiddleCamera) -> Result<()> {
        let mut images = match self.history.take() {
            Some(h) => h.images,
            None => [None, None, None],
        };
        let ids = Self::put(&self.device, &mut images, out, mid, &self.conv, "temporal history")?;
        self.history = Some(History { mid: *mid, images, ids });
        Ok(())
    }
}

/// Colour and depth of a middle view: the accumulation needs both.
pub(super) fn color_and_depth(out: &CyclopeanOutput) -> Result<(&crate::io::RgbImage, &crate::io::DepthMap)> {
    match (&out.color, &out.depth) {
        (Some(c), Some(d)) => Ok((c, d)),
        _ => Err(Error::param(
            "temporal accumulation",
            "needs the colour and depth outputs of the middle view",
        )),
    }
}
