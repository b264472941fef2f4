//! Float64 CPU twin of the cyclopean pass (shaders/cyclopean/gather.frag): same steps, same
//! texel choices. Images are handled in memory order (row 0 = framebuffer row 0 under the
//! frame's row order) exactly as the GPU sees its textures, and converted at the end.

use crate::camera::mat4::{self, Mat4};
use crate::camera::rays::{pixel_ndc, ray_basis, view_ray};
use crate::convention::{Conventions, RowOrder};
use crate::depth::{is_background, ndc_z_of_window_depth};
use crate::error::Result;
use crate::io::{DepthMap, RgbImage};
use crate::stereo::gather::ambiguity::{distance_bound, position_bound, row_condition, Reach, EPS32};
use crate::stereo::gather::{Blend, CyclopeanOutput, CyclopeanParams};
use crate::stereo::{EyeInput, FrameDepth, MiddleCamera, StereoFrame};

/// An eye prepared for sampling: rows in memory order, inverse matrices.
struct Eye64<'a> {
    input: &'a EyeInput,
    flip: bool,
    inv_view: Mat4,
    inv_proj: Mat4,
    /// Pixel rays ([`crate::camera::rays`]), the same under every convention.
    ray_basis: Mat4,
}

impl Eye64<'_> {
    fn size(&self) -> (i64, i64) {
        (self.input.color.width as i64, self.input.color.height as i64)
    }
    /// Image row of memory row `y`.
    fn image_row(&self, y: i64) -> i64 {
        if self.flip {
            self.size().1 - 1 - y
        } else {
            y
        }
    }
    fn depth_at(&self, x: i64, y: i64) -> f64 {
        let (w, _) = self.size();
        self.input.depth.data[(self.image_row(y) * w + x) as usize] as f64
    }
    fn color_at(&self, x: i64, y: i64) -> [f64; 3] {
        let (w, h) = self.size();
        let (x, y) = (x.clamp(0, w - 1), y.clamp(0, h - 1));
        let o = ((self.image_row(y) * w + x) * 3) as usize;
        let d = &self.input.color.data;
        [d[o] as f64, d[o + 1] as f64, d[o + 2] as f64]
    }
    /// Bilinear colour at uv in [0, 1]^2 (texel centres at (i + 0.5) / size), clamp to edge.
    /// With `edge_aware = Some((z, tolerance))`, texels whose view distance differs from z by
    /// more than the tolerance get no weight (no colour bleeding across depth edges); the
    /// texel holding uv always qualifies, so the weights never all vanish.
    /// `reach` records the edge-aware choices that f32 could take otherwise (`z` of relative error
    /// `rel_z`).
    fn bilinear(
        &self,
        uv: [f64; 2],
        edge_aware: Option<(f64, f64, FrameDepth, &Conventions)>,
        reach: Option<(&Reach, f64)>,
    ) -> [f64; 3] {
        let (w, h) = self.size();
        let t = [uv[0] * w as f64 - 0.5, uv[1] * h as f64 - 0.5];
        let (x0, y0) = (t[0].floor(), t[1].floor());
        let (fx, fy) = (t[0] - x0, t[1] - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let taps = [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ];
        let mut out = [0.0; 3];
        let mut total = 0.0;
        for (dx, dy, weight) in taps {
            let (x, y) = ((x0 + dx).clamp(0, w - 1), (y0 + dy).clamp(0, h - 1));
            let keep = match edge_aware {
                None => true,
                Some((z, tol, kind, conv)) => self.view_distance(x, y, kind, conv).is_some_and(|zt| {
                    if let Some((reach, rel_z)) = reach {
                        let rel_t = distance_bound(self.condition(x, y, kind, conv));
                        reach.threshold((zt - z).abs() - tol, rel_t * zt + rel_z * z);
                    }
                    (zt - z).abs() <= tol
                }),
            };
            if keep {
                let c = self.color_at(x, y);
                for k in 0..3 {
                    out[k] += weight * c[k];
                }
                total += weight;
            }
        }
        if total > 0.0 {
            out.map(|v| v / total)
        } else {
            out
        }
    }

    /// View-space distance stored at texel (x, y) (memory order), None for background.
    fn view_distance(&self, x: i64, y: i64, kind: FrameDepth, conv: &Conventions) -> Option<f64> {
        let (ndc, inv_proj) = (self.texel_ndc(x, y), &self.inv_proj);
        stored_view_point(self.depth_at(x, y), ndc, kind, conv, inv_proj, &self.ray_basis).map(|p| -p[2])
    }
    fn texel_ndc(&self, x: i64, y: i64) -> [f64; 2] {
        let (w, h) = self.size();
        [pixel_ndc(x as f64, w as f64), pixel_ndc(y as f64, h as f64)]
    }
    /// The condition of reconstructing texel (x, y)'s distance (see [`unprojection_condition`]).
    fn condition(&self, x: i64, y: i64, kind: FrameDepth, conv: &Conventions) -> f64 {
        unprojection_condition(self.depth_at(x, y), self.texel_ndc(x, y), kind, conv, &self.inv_proj)
    }
}

/// The eye view-space point a stored depth `d` describes at NDC (x, y): device depth unprojected
/// through the eye's inverse projection, or a view distance along the pixel's ray (from the ray
/// basis, [`crate::camera::rays`]). None for
/// background (device depth by [`crate::depth::is_background`], distance <= 0) and non-finite values.
pub(crate) fn stored_view_point(
    d: f64,
    ndc: [f64; 2],
    kind: FrameDepth,
    conv: &Conventions,
    inv_proj: &Mat4,
    ray_basis: &Mat4,
) -> Option<[f64; 3]> {
    if !d.is_finite() {
        return None;
    }
    match kind {
        FrameDepth::Device => {
            if is_background(d, conv) {
                return None;
            }
            let ndc_z = ndc_z_of_window_depth(d, conv);
            Some(mat4::transform_point(inv_proj, [ndc[0], ndc[1], ndc_z]))
        }
        FrameDepth::ViewZ => {
            if d <= 0.0 {
                return None;
            }
            let r = view_ray(ray_basis, ndc);
            Some([r[0] * d, r[1] * d, r[2] * d])
        }
    }
}

/// How much f32 roundings grow in the distance [`stored_view_point`] reconstructs from `d` at
/// `ndc`: 1 for a view distance (a scaled ray); for device depth the condition of the inverse
/// projection's w row (~ z / near under standard Z, where depth precision is spent near).
fn unprojection_condition(d: f64, ndc: [f64; 2], kind: FrameDepth, conv: &Conventions, inv_proj: &Mat4) -> f64 {
    match kind {
        FrameDepth::Device => row_condition(inv_proj, 3, [ndc[0], ndc[1], ndc_z_of_window_depth(d, conv), 1.0]),
        FrameDepth::ViewZ => 1.0,
    }
}

/// Window position (px, `size` wide and high) where `clip` lands.
fn window(clip: [f64; 4], size: [f64; 2]) -> [f64; 2] {
    [
        (clip[0] / clip[3] * 0.5 + 0.5) * size[0],
        (clip[1] / clip[3] * 0.5 + 0.5) * size[1],
    ]
}

/// The parallax |d px / d ln z| (px) of window position `px` of a point at distance z along
/// world direction `dir` seen through `view_proj`: its shift from where the direction's point at
/// infinity lands.
fn parallax(view_proj: &Mat4, dir: [f64; 3], px: [f64; 2], size: [f64; 2]) -> f64 {
    let c = mat4::transform(view_proj, [dir[0], dir[1], dir[2], 0.0]);
    if c[3].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return size[0].max(size[1]);
    }
    let inf = window(c, size);
    (px[0] - inf[0]).hypot(px[1] - inf[1])
}

/// Result of walking one eye along a middle ray.
#[derive(Debug, Clone, Copy)]
pub struct EyeSample {
    /// Whether the walk found a surface that the eye sees (and, refining, that projects back onto the pixel).
    pub valid: bool,
    /// Colour there, 0..=255 per channel, unrounded.
    pub color: [f64; 3],
    /// Middle view-space distance of the surface found.
    pub z_middle: f64,
}

struct Ctx<'a> {
    frame: &'a StereoFrame,
    mid: &'a MiddleCamera,
    inv_view_m: Mat4,
    params: &'a CyclopeanParams,
    reach: Reach,
}

impl Ctx<'_> {
    /// The eye's sample, and the relative f32 error bound of its middle distance.
    fn walk(&self, eye: &Eye64, ray_m: [f64; 3], pixel: [f64; 2]) -> (EyeSample, f64) {
        let invalid = (
            EyeSample {
                valid: false,
                color: [0.0; 3],
                z_middle: 0.0,
            },
            0.0,
        );
        let reach = &self.reach;
        let eye_size = [eye.size().0 as f64, eye.size().1 as f64];
        let view_proj = mat4::mul(&eye.input.proj, &eye.input.view);
        // The fixation distance, rounded to f32.
        let mut rel_z = EPS32;
        let (w, h) = eye.size();
        let mut z = self.params.fixation_distance;
        let mut uv = [0.0; 2];
        let mut world = [0.0; 3];
        let mut texel = (0, 0);
        for _ in 0..self.params.steps() {
            let guess = mat4::transform_point(&self.inv_view_m, [ray_m[0] * z, ray_m[1] * z, ray_m[2] * z]);
            let clip = mat4::transform(&view_proj, [guess[0], guess[1], guess[2], 1.0]);
            // Behind the eye (or NaN): w <= 0 fails `w > 0`.
            if clip[3].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return invalid;
            }
            let ndc = [clip[0] / clip[3], clip[1] / clip[3]];
            uv = [ndc[0] * 0.5 + 0.5, ndc[1] * 0.5 + 0.5];
            if reach.on() {
                // The texel choice and the range check both cut at integers of uv * size.
                let px = [uv[0] * eye_size[0], uv[1] * eye_size[1]];
                let dir = mat4::transform(&self.inv_view_m, [ray_m[0], ray_m[1], ray_m[2], 0.0]);
                let shift = parallax(&view_proj, [dir[0], dir[1], dir[2]], px, eye_size);
                let bound = position_bound(eye_size[0].max(eye_size[1]), rel_z, shift);
                reach.floor(px[0], bound);
                reach.floor(px[1], bound);
            }
            if !(uv[0] >= 0.0 && uv[0] <= 1.0 && uv[1] >= 0.0 && uv[1] <= 1.0) {
                return invalid;
            }
            let tx = ((uv[0] * w as f64).floor() as i64).clamp(0, w - 1);
            let ty = ((uv[1] * h as f64).floor() as i64).clamp(0, h - 1);
            let d = eye.depth_at(tx, ty);
            texel = (tx, ty);
            let kind = self.frame.depth_kind;
            let Some(view) = stored_view_point(d, ndc, kind, &self.frame.conv, &eye.inv_proj, &eye.ray_basis) else {
                return invalid;
            };
            world = mat4::transform_point(&eye.inv_view, view);
            z = -mat4::transform_point(&self.mid.view, world)[2];
            rel_z = distance_bound(unprojection_condition(
                d,
                ndc,
                self.frame.depth_kind,
                &self.frame.conv,
                &eye.inv_proj,
            ));
            if !(z.is_finite() && z > 0.0) {
                return invalid;
            }
        }
        if let crate::stereo::gather::Method::Refine { .. } = self.params.method {
            // The surface sample found (at its texel centre, where the eye really measured it;
            // reconstructing at uv would put it on the middle ray by construction) must project
            // back onto this middle pixel.
            let Some(z_eye) = eye.view_distance(texel.0, texel.1, self.frame.depth_kind, &self.frame.conv) else {
                return invalid;
            };
            let centre = [pixel_ndc(texel.0 as f64, w as f64), pixel_ndc(texel.1 as f64, h as f64)];
            let r = view_ray(&eye.ray_basis, centre);
            let sample = mat4::transform_point(&eye.inv_view, [r[0] * z_eye, r[1] * z_eye, r[2] * z_eye]);
            let clip = mat4::transform(
                &mat4::mul(&self.mid.proj, &self.mid.view),
                [sample[0], sample[1], sample[2], 1.0],
            );
            let mid_size = [self.mid.width as f64, self.mid.height as f64];
            let px = window(clip, mid_size);
            if reach.on() {
                let rel_t = distance_bound(eye.condition(texel.0, texel.1, self.frame.depth_kind, &self.frame.conv));
                let dir = mat4::transform(&eye.inv_view, [r[0], r[1], r[2], 0.0]);
                let view_proj_m = mat4::mul(&self.mid.proj, &self.mid.view);
                let shift = parallax(&view_proj_m, [dir[0], dir[1], dir[2]], px, mid_size);
                let bound = position_bound(mid_size[0].max(mid_size[1]), rel_t, shift);
                reach.threshold((px[0] - pixel[0]).abs() - REFINE_TOLERANCE_PX, bound);
                reach.threshold((px[1] - pixel[1]).abs() - REFINE_TOLERANCE_PX, bound);
            }
            if !((px[0] - pixel[0]).abs() <= REFINE_TOLERANCE_PX && (px[1] - pixel[1]).abs() <= REFINE_TOLERANCE_PX) {
                return invalid;
            }
        }
        let edge_aware = match self.params.method {
            crate::stereo::gather::Method::Seed => None,
            crate::stereo::gather::Method::Refine { .. } => {
                let z_eye = -mat4::transform_point(&eye.input.view, world)[2];
                Some((z_eye, self.params.z_threshold, self.frame.depth_kind, &self.frame.conv))
            }
        };
        let sample = EyeSample {
            valid: true,
            color: eye.bilinear(uv, edge_aware, reach.on().then_some((reach, rel_z))),
            z_middle: z,
        };
        (sample, rel_z)
    }
}

/// How far (middle pixels) a refined surface may project from the pixel that found it: the eye
/// depth is read at the nearest texel, so the point can sit half an eye texel off the ray,
/// which is up to about one middle pixel when the middle camera has a similar resolution.
pub const REFINE_TOLERANCE_PX: f64 = 1.0;

/// Resolve the two eyes' samples into colour, middle depth and source bits (shared rule).
pub fn combine(l: &EyeSample, r: &EyeSample, params: &CyclopeanParams) -> Option<([f64; 3], f64, u8)> {
    let w_left = params.left_eye_weight();
    match (l.valid, r.valid) {
        (false, false) => None,
        (true, false) => Some((l.color, l.z_middle, 1)),
        (false, true) => Some((r.color, r.z_middle, 2)),
        (true, true) => {
            let mean = [0, 1, 2].map(|c| w_left * l.color[c] + (1.0 - w_left) * r.color[c]);
            let (near, near_bit) = if l.z_middle <= r.z_middle { (l, 1) } else { (r, 2) };
            let dz = (l.z_middle - r.z_middle).abs();
            let z = l.z_middle.min(r.z_middle);
            match params.blend {
                Blend::Hard if dz > params.z_threshold => Some((near.color, z, near_bit)),
                Blend::Hard => Some((mean, z, 3)),
                Blend::Soft => {
                    let t = (1.0 - dz / params.z_threshold).clamp(0.0, 1.0);
                    let c = [0, 1, 2].map(|k| near.color[k] + (mean[k] - near.color[k]) * t);
                    Some((c, z, if t > 0.0 { 3 } else { near_bit }))
                }
            }
        }
    }
}

/// Unquantised reference result (rows top-down).
pub struct CyclopeanReference {
    /// Colour per pixel, 0..=255 per channel, unrounded.
    pub color: Vec<[f64; 3]>,
    /// Middle view-space distance (metres) per pixel; 0 where no eye had a surface.
    pub depth: Vec<f64>,
    /// Per pixel, bit 0: the left eye contributed, bit 1: the right eye; 0 = invalid.
    pub sources: Vec<u8>,
}

/// The f64 twin of [`CyclopeanRenderer`](crate::stereo::gather::gpu::CyclopeanRenderer): the middle view of `frame` through `mid` under `params`, rows top-down.
pub fn cyclopean_reference(
    frame: &StereoFrame,
    mid: &MiddleCamera,
    params: &CyclopeanParams,
) -> Result<CyclopeanReference> {
    Ok(twin(frame, mid, params, false)?.0)
}

/// Per pixel of [`cyclopean_reference`]'s view (rows top-down): whether any of the twin's
/// decisions (texel choices and range checks in either eye's walk, the refinement's projection
/// check, the edge-aware colour's depth test, the blend's depth threshold) came within the f32
/// error bound of its boundary (see [`super::ambiguity`]), so that the GPU may answer the pixel
/// otherwise. Every other pixel the GPU must render as the twin does.
pub fn ambiguity(frame: &StereoFrame, mid: &MiddleCamera, params: &CyclopeanParams) -> Result<Vec<bool>> {
    Ok(twin(frame, mid, params, true)?.1)
}

fn twin(
    frame: &StereoFrame,
    mid: &MiddleCamera,
    params: &CyclopeanParams,
    track: bool,
) -> Result<(CyclopeanReference, Vec<bool>)> {
    frame.validate()?;
    params.validate()?;
    let flip = frame.conv.row_order == RowOrder::BottomUp;
    fn prep(input: &EyeInput, flip: bool) -> Result<Eye64<'_>> {
        Ok(Eye64 {
            input,
            flip,
            inv_view: mat4::inverse(&input.view).ok_or_else(|| crate::Error::param("eye view", "singular"))?,
            inv_proj: mat4::inverse(&input.proj).ok_or_else(|| crate::Error::param("eye projection", "singular"))?,
            ray_basis: ray_basis(&input.proj)
                .ok_or_else(|| crate::Error::param("eye projection", "not perspective"))?,
        })
    }
    let (left, right) = (prep(&frame.left, flip)?, prep(&frame.right, flip)?);
    let ctx = Ctx {
        frame,
        mid,
        inv_view_m: mat4::inverse(&mid.view).ok_or_else(|| crate::Error::param("middle view", "singular"))?,
        params,
        reach: Reach::new(track),
    };
    let basis_m = ray_basis(&mid.proj).ok_or_else(|| crate::Error::param("middle projection", "not perspective"))?;
    let (w, h) = (mid.width as usize, mid.height as usize);
    let mut out = CyclopeanReference {
        color: vec![[0.0; 3]; w * h],
        depth: vec![0.0; w * h],
        sources: vec![0; w * h],
    };
    let mut ambiguous = vec![false; if track { w * h } else { 0 }];
    for y_mem in 0..h {
        let y_img = if flip { h - 1 - y_mem } else { y_mem };
        for x in 0..w {
            let pixel = [x as f64 + 0.5, y_mem as f64 + 0.5];
            let uv = [pixel[0] / w as f64, pixel[1] / h as f64];
            // As the shader: (2 pixel - size) / size, exactly mirrored under the other row order.
            let ndc = [
                (2.0 * pixel[0] - w as f64) / w as f64,
                (2.0 * pixel[1] - h as f64) / h as f64,
            ];
            let ray = view_ray(&basis_m, ndc);
            let (l, rel_l) = ctx.walk(&left, ray, pixel);
            let (r, rel_r) = ctx.walk(&right, ray, pixel);
            let o = y_img * w + x;
            if track {
                if l.valid && r.valid {
                    // Hard: near colour or mean; soft: whether t > 0 (the colour is continuous in dz).
                    let dz = (l.z_middle - r.z_middle).abs();
                    ctx.reach
                        .threshold(dz - params.z_threshold, rel_l * l.z_middle + rel_r * r.z_middle);
                }
                ambiguous[o] = ctx.reach.take();
            }
            match combine(&l, &r, params) {
                Some((c, z, bits)) => {
                    out.color[o] = c;
                    out.depth[o] = z;
                    out.sources[o] = bits;
                }
                None => {
                    // The seed's fallback colour: both eyes at the same uv, averaged.
                    let (a, b) = (left.bilinear(uv, None, None), right.bilinear(uv, None, None));
                    out.color[o] = [0, 1, 2].map(|c| 0.5 * (a[c] + b[c]));
                }
            }
        }
    }
    Ok((out, ambiguous))
}

impl CyclopeanReference {
    /// Rounded to the output types (for writing or comparing as images).
    pub fn to_output(&self, width: u32, height: u32) -> CyclopeanOutput {
        CyclopeanOutput {
            color: Some(
                RgbImage::new(
                    width,
                    height,
                    self.color
                        .iter()
                        .flat_map(|c| c.map(crate::metrics::quantize_u8))
                        .collect(),
                )
                .expect("size matches"),
            ),
            depth: Some(
                DepthMap::new(width, height, self.depth.iter().map(|z| *z as f32).collect()).expect("size matches"),
            ),
            sources: self.sources.clone(),
        }
    }
}
