//! Float64 CPU twin of the splat-gather method (shaders/cyclopean/edge_snap.comp, splat.comp
//! and splat_gather.frag): the same passes, the same texel choices, in memory order (row 0 =
//! framebuffer row 0) as the GPU sees its textures; converted to top-down rows at the end.

use super::edge_snap::SnapRule;
use super::splat::{SplatGeometry, SplatParams};
use crate::camera::mat4::{self, Mat4};
use crate::camera::rays::{pixel_ndc, ray_basis, view_ray};
use crate::convention::RowOrder;
use crate::error::Result;
use crate::stereo::gather::ambiguity::{distance_bound, position_bound, Reach, EPS32};
use crate::stereo::gather::reference::CyclopeanReference;
use crate::stereo::{MiddleCamera, StereoFrame};

/// One eye as the passes read it: distance (0 = invalid) and colour in memory order.
struct Eye<'a> {
    dist: Vec<f64>,
    color: &'a [u8],
    flip: bool,
    w: i64,
    h: i64,
    view: Mat4,
    inv_view: Mat4,
    /// Pixel rays ([`crate::camera::rays`]), the same under every convention.
    ray_basis: Mat4,
    view_proj: Mat4,
}

impl Eye<'_> {
    fn dist(&self, x: i64, y: i64) -> f64 {
        self.dist[(y * self.w + x) as usize]
    }
    fn color(&self, x: i64, y: i64) -> [f64; 3] {
        let row = if self.flip { self.h - 1 - y } else { y };
        let i = ((row * self.w + x) * 3) as usize;
        [0, 1, 2].map(|c| self.color[i + c] as f64)
    }
}

/// The ray basis of projection `proj`, refused as the GPU side refuses it.
fn basis(proj: &Mat4, what: &str) -> Result<Mat4> {
    ray_basis(proj).ok_or_else(|| crate::Error::param(what.to_string(), "not perspective"))
}

fn scaled(r: [f64; 3], z: f64) -> [f64; 3] {
    [r[0] * z, r[1] * z, r[2] * z]
}

/// The pass-1 splat of one eye: per middle pixel (memory order) the nearest middle distance of
/// the eye texels whose centre projects into it (the pixel whose centre the texel's one-pixel
/// footprint covers); +inf where none does. Tracking, also the range f32 may store per pixel: a
/// texel within f32 reach of a pixel border may land on either side, so a pixel holds between
/// the nearest of all texels that may land there and the nearest of those that certainly do
/// (+inf if none does).
fn splat(eye: &Eye, view_proj_m: &Mat4, view_m: &Mat4, wm: i64, hm: i64, track: bool) -> (Vec<f64>, SplatRange) {
    let mut out = vec![f64::INFINITY; (wm * hm) as usize];
    let n = if track { (wm * hm) as usize } else { 0 };
    let (mut must, mut may) = (vec![f64::INFINITY; n], vec![f64::INFINITY; n]);
    // The eye's distances are the same f32 inputs on both sides.
    let reach = position_bound(wm.max(hm) as f64, 0.0, 0.0);
    let sides = |v: f64| -> Vec<i64> {
        if (v - v.round()).abs() <= reach {
            vec![v.round() as i64 - 1, v.round() as i64]
        } else {
            vec![v.floor() as i64]
        }
    };
    for y in 0..eye.h {
        for x in 0..eye.w {
            let z = eye.dist(x, y);
            if z <= 0.0 {
                continue;
            }
            let ndc = [pixel_ndc(x as f64, eye.w as f64), pixel_ndc(y as f64, eye.h as f64)];
            let world = mat4::transform_point(&eye.inv_view, scaled(view_ray(&eye.ray_basis, ndc), z));
            let clip = mat4::transform(view_proj_m, [world[0], world[1], world[2], 1.0]);
            if clip[3].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let (wx, wy) = (
                (clip[0] / clip[3] * 0.5 + 0.5) * wm as f64,
                (clip[1] / clip[3] * 0.5 + 0.5) * hm as f64,
            );
            let (px, py) = (wx.floor(), wy.floor());
            let zm = -mat4::transform_point(view_m, world)[2];
            if track && zm > 0.0 && zm.is_finite() {
                let (xs, ys) = (sides(wx), sides(wy));
                let certain = xs.len() == 1 && ys.len() == 1;
                for &qx in &xs {
                    for &qy in &ys {
                        if qx >= 0 && qy >= 0 && qx < wm && qy < hm {
                            let o = (qy * wm + qx) as usize;
                            let slot = if certain { &mut must[o] } else { &mut may[o] };
                            *slot = slot.min(zm);
                        }
                    }
                }
            }
            if !(px >= 0.0 && py >= 0.0 && px < wm as f64 && py < hm as f64 && zm > 0.0 && zm.is_finite()) {
                continue;
            }
            let o = (py as i64 * wm + px as i64) as usize;
            out[o] = out[o].min(zm);
        }
    }
    let lo = must.iter().zip(&may).map(|(m, y)| m.min(*y)).collect();
    (out, SplatRange { lo, hi: must })
}

/// Per middle pixel, the nearest distance f32 may store in a splat: from `lo` to `hi`.
struct SplatRange {
    lo: Vec<f64>,
    hi: Vec<f64>,
}

/// One eye's answer for a middle pixel.
#[derive(Debug, Clone, Copy)]
struct Sample {
    color: [f64; 3],
    z_middle: f64,
    /// Bilinear weight of the texels on the surface found (0..1]: < 1 at the surface's edge,
    /// where real images mix foreground and background colours.
    confidence: f64,
    /// Relative f32 error bound of `z_middle`.
    rel: f64,
}

struct Ctx<'a> {
    geo: &'a SplatGeometry,
    params: &'a SplatParams,
    inv_view_m: Mat4,
    reach: Reach,
}

impl Ctx<'_> {
    /// Whether distances `z1` and `z2` (relative f32 errors up to `rel`) are one surface.
    fn same_surface(&self, z1: f64, z2: f64, rel: f64) -> bool {
        let (d1, d2) = (self.geo.parallax_px / z1, self.geo.parallax_px / z2);
        // The divisions and the difference: a few roundings more.
        self.reach.threshold(
            (d1 - d2).abs() - self.params.surface_tolerance_px,
            (rel + 4.0 * EPS32) * (d1.abs() + d2.abs()),
        );
        (d1 - d2).abs() <= self.params.surface_tolerance_px
    }

    /// Eye texel coordinates (texel i's centre at i) of the middle ray point at middle distance z
    /// (relative error `rel`), and that point's eye distance; tracking, the texel coordinates' f32
    /// error bound.
    fn to_eye(&self, eye: &Eye, ray_m: [f64; 3], z: f64, rel: f64) -> Option<([f64; 2], f64, f64)> {
        let world = mat4::transform_point(&self.inv_view_m, scaled(ray_m, z));
        let clip = mat4::transform(&eye.view_proj, [world[0], world[1], world[2], 1.0]);
        if clip[3].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let e = [
            (clip[0] / clip[3] * 0.5 + 0.5) * eye.w as f64 - 0.5,
            (clip[1] / clip[3] * 0.5 + 0.5) * eye.h as f64 - 0.5,
        ];
        let z_eye = -mat4::transform_point(&eye.view, world)[2];
        let mut bound = 0.0;
        if self.reach.on() {
            // Parallax: the shift from where the ray's point at infinity lands.
            let dir = mat4::transform(&self.inv_view_m, [ray_m[0], ray_m[1], ray_m[2], 0.0]);
            let c = mat4::transform(&eye.view_proj, dir);
            let size = eye.w.max(eye.h) as f64;
            let shift = if c[3] > 0.0 {
                let inf = [
                    (c[0] / c[3] * 0.5 + 0.5) * eye.w as f64 - 0.5,
                    (c[1] / c[3] * 0.5 + 0.5) * eye.h as f64 - 0.5,
                ];
                (e[0] - inf[0]).hypot(e[1] - inf[1])
            } else {
                size
            };
            bound = position_bound(size, rel, shift);
        }
        Some((e, z_eye, bound))
    }

    /// The texel nearest `e` and the bilinear taps of `e` on its surface: (surface distance by
    /// interpolated inverse depth, colour, kept weight); None when the nearest texel is invalid,
    /// off the image, or on another surface than `z_eye`.
    /// Tracking, `bound` is the f32 error bound of `e` and `rel` that of `z_eye`.
    fn surface_at(&self, eye: &Eye, e: [f64; 2], z_eye: f64, bound: f64, rel: f64) -> Option<(f64, [f64; 3], f64)> {
        let n = [(e[0] + 0.5).floor(), (e[1] + 0.5).floor()];
        if self.reach.on() {
            // The nearest texel and the range check cut at integers of e + 0.5: f32 may take the
            // texel across a border within reach, which matters only if it keeps other taps (on
            // a surface, the nearest texel only names the surface; quarter-pixel disparities put
            // many rays exactly on such borders).
            let sides = |v: f64, k: f64| {
                if (v - v.round()).abs() <= bound {
                    vec![v.round() - 1.0, v.round()]
                } else {
                    vec![k]
                }
            };
            let base = self.kept(eye, e, z_eye, n);
            for x in sides(e[0] + 0.5, n[0]) {
                for y in sides(e[1] + 0.5, n[1]) {
                    if self.kept(eye, e, z_eye, [x, y]) != base {
                        self.reach.mark();
                    }
                }
            }
        }
        if !(n[0] >= 0.0 && n[1] >= 0.0 && n[0] < eye.w as f64 && n[1] < eye.h as f64) {
            return None;
        }
        let zn = eye.dist(n[0] as i64, n[1] as i64);
        if !(zn > 0.0 && z_eye > 0.0 && self.same_surface(zn, z_eye, rel)) {
            return None;
        }
        let (x0, y0) = (e[0].floor(), e[1].floor());
        let (fx, fy) = (e[0] - x0, e[1] - y0);
        let (mut inv, mut color, mut total) = (0.0, [0.0; 3], 0.0);
        for (dx, dy, wt) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let x = (x0 as i64 + dx).clamp(0, eye.w - 1);
            let y = (y0 as i64 + dy).clamp(0, eye.h - 1);
            let z = eye.dist(x, y);
            // Both the same f32 inputs on either side.
            if z > 0.0 && self.same_surface(z, zn, 0.0) {
                let c = eye.color(x, y);
                inv += wt / z;
                for k in 0..3 {
                    color[k] += wt * c[k];
                }
                total += wt;
            }
        }
        // The nearest texel always qualifies and has weight >= 1/4.
        Some((total / inv, color.map(|c| c / total), total))
    }

    /// The bilinear taps of `e` that nearest texel `n` keeps on its surface (None where `n` is off
    /// the image, invalid or on another surface than `z_eye`), without tracking: the choice
    /// [`Self::surface_at`] makes, for a texel f32 may take instead.
    fn kept(&self, eye: &Eye, e: [f64; 2], z_eye: f64, n: [f64; 2]) -> Option<[bool; 4]> {
        if !(n[0] >= 0.0 && n[1] >= 0.0 && n[0] < eye.w as f64 && n[1] < eye.h as f64) {
            return None;
        }
        let same = |a: f64, b: f64| {
            (self.geo.parallax_px / a - self.geo.parallax_px / b).abs() <= self.params.surface_tolerance_px
        };
        let zn = eye.dist(n[0] as i64, n[1] as i64);
        if !(zn > 0.0 && z_eye > 0.0 && same(zn, z_eye)) {
            return None;
        }
        let (x0, y0) = (e[0].floor() as i64, e[1].floor() as i64);
        Some([(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| {
            let z = eye.dist((x0 + dx).clamp(0, eye.w - 1), (y0 + dy).clamp(0, eye.h - 1));
            z > 0.0 && same(z, zn)
        }))
    }

    /// Follow a candidate middle distance to the eye's surface: one fixed-point step on the
    /// locally interpolated surface, then the colour there.
    fn eye_sample(&self, eye: &Eye, ray_m: [f64; 3], z0: f64) -> Option<Sample> {
        // A splatted distance, computed in f32 by the splat.
        let rel0 = distance_bound(1.0);
        let (e0, z_eye0, bound0) = self.to_eye(eye, ray_m, z0, rel0)?;
        let (z_surface, _, _) = self.surface_at(eye, e0, z_eye0, bound0, 2.0 * rel0)?;
        let ndc = [pixel_ndc(e0[0], eye.w as f64), pixel_ndc(e0[1], eye.h as f64)];
        let on_surface = mat4::transform_point(&eye.inv_view, scaled(view_ray(&eye.ray_basis, ndc), z_surface));
        let z1 = -mat4::transform_point(&self.geo.view_m, on_surface)[2];
        if !(z1.is_finite() && z1 > 0.0) {
            return None;
        }
        // z1 carries z0's error through the interpolated surface, and the chain's own.
        let rel1 = 2.0 * rel0;
        let (e1, z_eye1, bound1) = self.to_eye(eye, ray_m, z1, rel1)?;
        let (_, color, confidence) = self.surface_at(eye, e1, z_eye1, bound1, 2.0 * rel1)?;
        Some(Sample {
            color,
            z_middle: z1,
            confidence,
            rel: rel1,
        })
    }

    /// Whether f32 reaches the twin's candidates and edge flag of pixel (x, y) from `range`, an
    /// eye's splat: settled where every pixel of the neighbourhood (the pixel and its 4
    /// neighbours) holds its value whichever side its border texels land on; or where the
    /// nearest value is settled and every value in reach lies on its surface, clear of the
    /// tolerance, so that no second candidate and no edge appears either way.
    fn splat_settled(&self, range: &SplatRange, x: i64, y: i64, wm: i64, hm: i64) -> bool {
        let rel = 2.0 * distance_bound(1.0);
        let same = |a: f64, b: f64| {
            if a.is_finite() != b.is_finite() {
                false
            } else {
                !a.is_finite() || (a - b).abs() <= rel * a.max(b)
            }
        };
        let around: Vec<usize> = [(0, 0), (-1, 0), (1, 0), (0, -1), (0, 1)]
            .iter()
            .map(|(dx, dy)| (x + dx, y + dy))
            .filter(|&(qx, qy)| qx >= 0 && qy >= 0 && qx < wm && qy < hm)
            .map(|(qx, qy)| (qy * wm + qx) as usize)
            .collect();
        if around.iter().all(|&i| same(range.lo[i], range.hi[i])) {
            return true;
        }
        let nearest = |v: &[f64]| around.iter().map(|&i| v[i]).fold(f64::INFINITY, f64::min);
        let (near_lo, near_hi) = (nearest(&range.lo), nearest(&range.hi));
        if !same(near_lo, near_hi) {
            return false;
        }
        let d_near = self.geo.parallax_px / near_lo;
        let clear = self.params.surface_tolerance_px - (rel + 4.0 * EPS32) * 2.0 * d_near;
        around
            .iter()
            .flat_map(|&i| [range.lo[i], range.hi[i]])
            .filter(|z| z.is_finite())
            .all(|z| (self.geo.parallax_px / z - d_near).abs() < clear)
    }

    /// Whether a depth edge may cross pixel (x, y) along x: two of the pixel and its left and
    /// right neighbours (clamped to the image) hold different surfaces in this eye's splat.
    /// An empty one is no edge: a crack in a stretched surface is none, and where one eye's
    /// splat is empty because the surface was hidden from it, the other eye's shows the edge.
    fn edge_nearby(&self, splat: &[f64], x: i64, y: i64, wm: i64) -> bool {
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for dx in -1..=1 {
            let z = splat[(y * wm + (x + dx).clamp(0, wm - 1)) as usize];
            if z.is_finite() {
                lo = lo.min(z);
                hi = hi.max(z);
            }
        }
        hi > 0.0 && !self.same_surface(lo, hi, distance_bound(1.0))
    }

    /// Candidates from the eye's splat: the nearest of the pixel and its 4 neighbours (a near
    /// surface whose splat rounded next door), then the pixel's own (or, in a hole, the farthest
    /// neighbour: the surface a disocclusion shows); the first that leads to a surface wins.
    fn candidates(&self, splat: &[f64], x: i64, y: i64, wm: i64, hm: i64) -> [f64; 2] {
        let own = splat[(y * wm + x) as usize];
        let (mut near, mut far) = (own, if own.is_finite() { own } else { -1.0 });
        for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1)] {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= wm || ny >= hm {
                continue;
            }
            let z = splat[(ny * wm + nx) as usize];
            near = near.min(z);
            if !own.is_finite() && z.is_finite() {
                far = far.max(z);
            }
        }
        let second = if far > 0.0 && !self.same_surface(far, near, distance_bound(1.0)) {
            far
        } else {
            f64::INFINITY
        };
        [near, second]
    }
}

/// The splat-gather middle view in f64 (rows top-down; colour 0 where no eye answers).
pub fn splat_reference(frame: &StereoFrame, mid: &MiddleCamera, params: &SplatParams) -> Result<CyclopeanReference> {
    Ok(twin(frame, mid, params, false)?.0)
}

/// Per pixel of [`splat_reference`]'s view (rows top-down): whether any of the twin's decisions
/// came within the f32 error bound of its boundary (see [`super::ambiguity`]), so that the GPU may
/// answer the pixel otherwise: either eye's splat around the pixel not settled (a texel within
/// reach of a pixel border that may change the pixel's candidates or edge flag), a nearest eye
/// texel or range check within reach of its border, or a same-surface test within reach of its
/// tolerance (candidates, edge, texels, eyes, edge mix). Every other pixel the GPU must render
/// as the twin does.
pub fn ambiguity(frame: &StereoFrame, mid: &MiddleCamera, params: &SplatParams) -> Result<Vec<bool>> {
    Ok(twin(frame, mid, params, true)?.1)
}

fn twin(
    frame: &StereoFrame,
    mid: &MiddleCamera,
    params: &SplatParams,
    track: bool,
) -> Result<(CyclopeanReference, Vec<bool>)> {
    params.validate()?;
    frame.validate()?;
    let geo = SplatGeometry::new(frame, mid)?;
    let flip = frame.conv.row_order == RowOrder::BottomUp;
    let eyes: Vec<Eye> = [(&frame.left, &geo.dist_mem[0]), (&frame.right, &geo.dist_mem[1])]
        .into_iter()
        .map(|(input, dist)| -> Result<Eye> {
            let inv = |m: &Mat4| mat4::inverse(m).ok_or_else(|| crate::Error::param("eye matrix", "singular"));
            let (w, h) = (input.color.width as usize, input.color.height as usize);
            let dist = match params.edge_snap_margin {
                Some(margin) => {
                    let rgb = |x: usize, y: usize| {
                        let row = if flip { h - 1 - y } else { y };
                        let i = (row * w + x) * 3;
                        [0, 1, 2].map(|c| input.color.data[i + c])
                    };
                    let rule = SnapRule {
                        parallax_px: geo.parallax_px,
                        tolerance_px: params.surface_tolerance_px,
                        margin,
                    };
                    rule.apply(dist, &rgb, w, h)
                }
                None => dist.iter().map(|&z| z as f64).collect(),
            };
            Ok(Eye {
                dist,
                color: &input.color.data,
                flip,
                w: w as i64,
                h: h as i64,
                view: input.view,
                inv_view: inv(&input.view)?,
                ray_basis: basis(&input.proj, "eye projection")?,
                view_proj: mat4::mul(&input.proj, &input.view),
            })
        })
        .collect::<Result<_>>()?;
    let (wm, hm) = (mid.width as i64, mid.height as i64);
    let view_proj_m = mat4::mul(&mid.proj, &mid.view);
    let (splats, ranges): (Vec<Vec<f64>>, Vec<SplatRange>) = eyes
        .iter()
        .map(|e| splat(e, &view_proj_m, &mid.view, wm, hm, track))
        .unzip();
    let ctx = Ctx {
        geo: &geo,
        params,
        inv_view_m: mat4::inverse(&mid.view).ok_or_else(|| crate::Error::param("middle view", "singular"))?,
        reach: Reach::new(track),
    };
    let basis_m = basis(&mid.proj, "middle projection")?;
    let n = (wm * hm) as usize;
    let mut out = CyclopeanReference {
        color: vec![[0.0; 3]; n],
        depth: vec![0.0; n],
        sources: vec![0; n],
    };
    let mut ambiguous = vec![false; if track { n } else { 0 }];
    for y in 0..hm {
        let y_img = if flip { hm - 1 - y } else { y };
        for x in 0..wm {
            // Both eyes' answer for the middle ray through window position (x + 0.5 + dx, y + 0.5),
            // from this pixel's splat candidates.
            let shade = |dx: f64| {
                let ndc = [
                    (2.0 * (x as f64 + 0.5 + dx) - wm as f64) / wm as f64,
                    pixel_ndc(y as f64, hm as f64),
                ];
                let ray = view_ray(&basis_m, ndc);
                let samples: Vec<Option<Sample>> = eyes
                    .iter()
                    .zip(&splats)
                    .map(|(eye, sp)| {
                        ctx.candidates(sp, x, y, wm, hm)
                            .into_iter()
                            .filter(|z| z.is_finite())
                            .find_map(|z| ctx.eye_sample(eye, ray, z))
                    })
                    .collect();
                merge(&ctx, samples[0], samples[1])
            };
            let o = (y_img * wm + x) as usize;
            if let Some((mut c, z, bits, rel)) = shade(0.0) {
                // Evaluated for both eyes, as the GPU does (no short cut: each may be ambiguous).
                let edges: Vec<bool> = splats.iter().map(|sp| ctx.edge_nearby(sp, x, y, wm)).collect();
                if edges.contains(&true) {
                    c = edge_mix(&ctx, c, z, rel, [shade(-SUBSAMPLE_PX), shade(SUBSAMPLE_PX)]);
                }
                out.color[o] = c;
                out.depth[o] = z;
                out.sources[o] = bits;
            }
            if track {
                let unsettled = ranges.iter().any(|r| !ctx.splat_settled(r, x, y, wm, hm));
                ambiguous[o] = ctx.reach.take() || unsettled;
            }
        }
    }
    Ok((out, ambiguous))
}

/// Sub-pixel sample offset along x at depth edges (pixels): with the centre, a 3-tap box.
const SUBSAMPLE_PX: f64 = 1.0 / 3.0;

/// A camera pixel integrates its footprint: where the centre and the samples at +-1/3 px along
/// x (those an eye answers) span more than one surface, their mean colour; else the centre's.
/// Only x: rectified views move depth edges along rows, their mixing along y is in the eyes.
fn edge_mix(ctx: &Ctx, centre: [f64; 3], z: f64, rel: f64, subs: [Option<Merged>; 2]) -> [f64; 3] {
    let (mut sum, mut n) = (centre, 1.0);
    let d = ctx.geo.parallax_px / z;
    let (mut lo, mut hi) = (d, d);
    for (c, z, _, _) in subs.into_iter().flatten() {
        for k in 0..3 {
            sum[k] += c[k];
        }
        n += 1.0;
        let d = ctx.geo.parallax_px / z;
        lo = lo.min(d);
        hi = hi.max(d);
    }
    ctx.reach.threshold(
        hi - lo - ctx.params.surface_tolerance_px,
        (2.0 * rel + 4.0 * EPS32) * (hi + lo),
    );
    if hi - lo > ctx.params.surface_tolerance_px {
        sum.map(|v| v / n)
    } else {
        centre
    }
}

/// Both eyes on one surface: their mean weighted by nearness to each eye and confidence; on
/// different surfaces the nearer; one eye alone: that eye.
/// Colour, middle distance, source bits and the distance's relative f32 error bound.
type Merged = ([f64; 3], f64, u8, f64);

fn merge(ctx: &Ctx, l: Option<Sample>, r: Option<Sample>) -> Option<Merged> {
    match (l, r) {
        (None, None) => None,
        (Some(l), None) => Some((l.color, l.z_middle, 1, l.rel)),
        (None, Some(r)) => Some((r.color, r.z_middle, 2, r.rel)),
        (Some(l), Some(r)) => {
            let rel = l.rel.max(r.rel);
            if ctx.same_surface(l.z_middle, r.z_middle, rel) {
                let wl = ctx.geo.w_left * l.confidence;
                let wr = (1.0 - ctx.geo.w_left) * r.confidence;
                // > 0: each confidence is >= 1/4 and the two position weights sum to 1.
                let total = wl + wr;
                let c = [0, 1, 2].map(|k| (wl * l.color[k] + wr * r.color[k]) / total);
                Some((c, (wl * l.z_middle + wr * r.z_middle) / total, 3, rel))
            } else if l.z_middle <= r.z_middle {
                Some((l.color, l.z_middle, 1, rel))
            } else {
                Some((r.color, r.z_middle, 2, rel))
            }
        }
    }
}
