//! Float64 CPU twin of the GPU stitch (shaders/stitch/stitch.frag): same steps, same texel
//! choices, unrounded colour and ray distance out.

use super::{
    equirect_angles, face_camera, pair_weight, CubeFace, FaceSet, Method, PairWeight, StitchParams, FAR_DISTANCE,
    REPROJECT_AGREE_REL, REPROJECT_STEPS, REPROJECT_TOLERANCE_PX,
};
use crate::error::Result;

type V3 = [f64; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn normalize(a: V3) -> V3 {
    scale(a, 1.0 / dot(a, a).sqrt().max(1e-30))
}
fn mix3(a: V3, b: V3, t: f64) -> V3 {
    add(scale(a, 1.0 - t), scale(b, t))
}

/// A face ready for sampling.
struct Face<'a> {
    color: &'a [u8],
    depth: &'a [f32],
    rot: [[f64; 3]; 3],
    eye: V3,
    f: f64,
    c: f64,
    n: i64,
}

impl Face<'_> {
    /// Face pixel (u, v) of a world-space direction; None unless in front of the face.
    fn project_dir(&self, v: V3) -> Option<(f64, f64)> {
        let r = &self.rot;
        let q = [
            r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
            r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
            r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2],
        ];
        // Directions more than ~89 deg off axis are never sampled meaningfully.
        if q[2] <= 1e-2 * dot(q, q).sqrt() {
            return None;
        }
        Some((self.f * q[0] / q[2] + self.c, self.f * q[1] / q[2] + self.c))
    }
    fn project_point(&self, x: V3) -> Option<(f64, f64)> {
        self.project_dir(sub(x, self.eye))
    }
    fn inside(&self, (u, v): (f64, f64)) -> bool {
        let hi = self.n as f64 - 0.5;
        u >= -0.5 && u <= hi && v >= -0.5 && v <= hi
    }
    fn texel(&self, x: i64, y: i64) -> [f64; 3] {
        let o = ((y.clamp(0, self.n - 1) * self.n + x.clamp(0, self.n - 1)) * 3) as usize;
        [self.color[o] as f64, self.color[o + 1] as f64, self.color[o + 2] as f64]
    }
    /// Bilinear colour, clamped to the face.
    fn color(&self, (u, v): (f64, f64)) -> V3 {
        let m = (self.n - 1) as f64;
        let (u, v) = (u.clamp(0.0, m), v.clamp(0.0, m));
        let (x0, y0) = (u.floor(), v.floor());
        let (fx, fy) = (u - x0, v - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = mix3(self.texel(x0, y0), self.texel(x0 + 1, y0), fx);
        let bottom = mix3(self.texel(x0, y0 + 1), self.texel(x0 + 1, y0 + 1), fx);
        mix3(top, bottom, fy)
    }
    /// View Z at the nearest texel; None for background.
    fn depth(&self, (u, v): (f64, f64)) -> Option<f64> {
        let x = ((u + 0.5).floor() as i64).clamp(0, self.n - 1);
        let y = ((v + 0.5).floor() as i64).clamp(0, self.n - 1);
        let z = self.depth[(y * self.n + x) as usize] as f64;
        (z.is_finite() && z > 0.0).then_some(z)
    }
    /// World direction (view z = 1) through face pixel (u, v).
    fn ray(&self, (u, v): (f64, f64)) -> V3 {
        let d = [(u - self.c) / self.f, (v - self.c) / self.f, 1.0];
        let r = &self.rot;
        [0, 1, 2].map(|i| r[i][0] * d[0] + r[i][1] * d[1] + r[i][2] * d[2])
    }
    /// World point at face pixel (u, v) and view Z `z`; background at FAR_DISTANCE along the ray.
    fn unproject(&self, uv: (f64, f64), z: Option<f64>) -> V3 {
        let ray = self.ray(uv);
        match z {
            Some(z) => add(self.eye, scale(ray, z)),
            None => add(self.eye, scale(normalize(ray), FAR_DISTANCE)),
        }
    }
    /// Colour along direction d (the point at infinity).
    fn plain(&self, d: V3) -> V3 {
        self.project_dir(d).map_or([0.0; 3], |uv| self.color(uv))
    }
    /// Distance along the ODS ray (o, d) to the surface this face sees along d (the sample
    /// [`Self::plain`] takes); None for sky or a direction behind the face.
    fn range(&self, o: V3, d: V3) -> Option<f64> {
        let uv = self.project_dir(d)?;
        let z = self.depth(uv)?;
        Some(dot(sub(self.unproject(uv, Some(z)), o), d))
    }
}

/// What one face says about an ODS ray.
#[derive(Debug, Clone, Copy)]
enum Candidate {
    Surface { t: f64, color: V3 },
    Background { color: V3 },
    Invalid,
}

/// Fixed-point walk of the ODS ray (o, d) against one face's depth (cyclopean-style): start at
/// the surface the face sees along d, move to the ray point nearest the reconstructed surface.
fn walk(face: &Face, o: V3, d: V3) -> Candidate {
    let Some(uv0) = face.project_dir(d) else {
        return Candidate::Invalid;
    };
    let mut t = match face.depth(uv0) {
        Some(z) => dot(sub(face.unproject(uv0, Some(z)), o), d),
        None => FAR_DISTANCE,
    };
    for step in 0..=REPROJECT_STEPS {
        if t.is_nan() || t <= 1e-6 {
            return Candidate::Invalid;
        }
        let x = add(o, scale(d, t));
        let Some(uv) = face.project_point(x) else {
            return Candidate::Invalid;
        };
        if !face.inside(uv) {
            return Candidate::Invalid;
        }
        let Some(z) = face.depth(uv) else {
            return Candidate::Background { color: face.color(uv) };
        };
        let y = face.unproject(uv, Some(z));
        let yo = sub(y, o);
        let t_new = dot(yo, d);
        if step == REPROJECT_STEPS {
            // On the ray within the tolerance (at the surface's range from the face eye)?
            let perp = sub(yo, scale(d, t_new));
            let range = dot(sub(y, face.eye), sub(y, face.eye)).sqrt();
            if dot(perp, perp).sqrt() > REPROJECT_TOLERANCE_PX * range / face.f {
                return Candidate::Invalid;
            }
            return Candidate::Surface {
                t: t_new,
                color: face.color(uv),
            };
        }
        t = t_new;
    }
    Candidate::Invalid
}

fn blend(faces: &[Face], pw: &PairWeight, d: V3) -> V3 {
    mix3(faces[pw.a].plain(d), faces[pw.b].plain(d), pw.w)
}

/// The pair's distance where the colour mixes both faces along d (blend, border weight,
/// reproject's last resort): weighted when both surfaces agree within
/// [`REPROJECT_AGREE_REL`], else the heavier face's (w < 0.5: A), so that no distance lies
/// between two surfaces; 0 for sky.
fn mix_range(faces: &[Face], pw: &PairWeight, o: V3, d: V3) -> f64 {
    let (ta, tb) = (faces[pw.a].range(o, d), faces[pw.b].range(o, d));
    let t = match (ta, tb) {
        (Some(a), Some(b)) if a > 0.0 && b > 0.0 && (a - b).abs() <= REPROJECT_AGREE_REL * a.min(b) => {
            Some(a * (1.0 - pw.w) + b * pw.w)
        }
        _ if pw.w < 0.5 => ta,
        _ => tb,
    };
    t.map_or(0.0, |t| t.max(0.0))
}

/// The seed's far guess of where surface point `iw`, seen by the face whose eye is `from`, would
/// appear to the other face's eye `to`: `normalize((iw - from) + (to - from)) * FAR_DISTANCE + to`.
/// With from = cPosMX, to = cPos this is the seed's `iwPos2` (`(iwPos - cPosMX) + dd`,
/// dd = cPos - cPosMX); with from = cPos, to = cPosMX its `iwzPos2` (`(iwzPos - cPos) - dd`).
/// Seen from `from`, the guess lies (within |to - from| / FAR_DISTANCE rad) along the direction
/// in which `to` sees the point at the same range, `to + (iw - from)`: sampling the `from` face
/// there warps it to the other eye, assuming the surface keeps its range.
fn far_guess(iw: V3, from: V3, to: V3) -> V3 {
    add(scale(normalize(add(sub(iw, from), sub(to, from))), FAR_DISTANCE), to)
}

/// Seed 001 "stitch with border weight" for one pixel of a pair's band: A is the seed's +Z face
/// (eye cPos), B its -X face (eye cPosMX). Projections behind a face fall back to that face's
/// sample at wPos.
fn border_weight(a: &Face, b: &Face, w: f64, d: V3) -> V3 {
    let (cpos, cposmx) = (a.eye, b.eye);
    let wpos = add(cpos, scale(d, FAR_DISTANCE));
    let (Some(pwz), Some(pwx)) = (a.project_point(wpos), b.project_point(wpos)) else {
        return mix3(a.plain(d), b.plain(d), w);
    };
    let (za, zb) = (a.depth(pwz), b.depth(pwx));
    let base_col = a.color(pwz);
    let col2_plain = b.color(pwx);
    if za.is_none() && zb.is_none() {
        return scale(add(base_col, col2_plain), 0.5);
    }
    let iwpos = b.unproject(pwx, zb);
    let iwpos2 = far_guess(iwpos, cposmx, cpos);
    let wpos2 = add(scale(iwpos, w), scale(iwpos2, 1.0 - w));
    let col2 = b.project_point(wpos2).map_or(col2_plain, |uv| b.color(uv));
    let iwzpos = a.unproject(pwz, za);
    let iwzpos2 = far_guess(iwzpos, cpos, cposmx);
    let wzpos2 = add(scale(iwzpos, 1.0 - w), scale(iwzpos2, w));
    let col1 = a.project_point(wzpos2).map_or(base_col, |uv| a.color(uv));
    let mut col = add(scale(col2, w), scale(col1, 1.0 - w));
    if w < 0.5 {
        let w2 = w / 0.5;
        col = add(scale(base_col, 1.0 - w2), scale(col, w2));
    }
    col
}

/// Depth-aware reprojection along the ODS ray from the pair's two faces: colour and distance
/// (0 where only background is seen).
fn reproject(faces: &[Face], pw: &PairWeight, o: V3, d: V3) -> (V3, f64) {
    let cands = [(walk(&faces[pw.a], o, d), 1.0 - pw.w), (walk(&faces[pw.b], o, d), pw.w)];
    let surfaces: Vec<(f64, V3, f64)> = cands
        .iter()
        .filter_map(|(c, wt)| match *c {
            Candidate::Surface { t, color } => Some((t, color, *wt)),
            _ => None,
        })
        .collect();
    match surfaces.as_slice() {
        [(t, c, _)] => return (*c, *t),
        [(ta, ca, wa), (tb, cb, wb)] => {
            if (ta - tb).abs() <= REPROJECT_AGREE_REL * ta.min(*tb) {
                return (add(scale(*ca, *wa), scale(*cb, *wb)), ta * wa + tb * wb);
            }
            return if ta <= tb { (*ca, *ta) } else { (*cb, *tb) };
        }
        _ => {}
    }
    let (mut sum, mut total) = ([0.0; 3], 0.0);
    let mut any = [0.0; 3];
    let mut n_bg = 0.0;
    for (c, wt) in cands {
        if let Candidate::Background { color } = c {
            sum = add(sum, scale(color, wt));
            total += wt;
            any = add(any, color);
            n_bg += 1.0;
        }
    }
    if total > 0.0 {
        (scale(sum, 1.0 / total), 0.0)
    } else if n_bg > 0.0 {
        (scale(any, 1.0 / n_bg), 0.0)
    } else {
        (blend(faces, pw, d), mix_range(faces, pw, o, d))
    }
}

/// Stitched colour (0..255, unrounded) of one eye's equirect, rows top-down.
pub fn stitch_reference(set: &FaceSet, params: &StitchParams) -> Result<Vec<V3>> {
    Ok(stitch_reference_eye(set, params)?.color)
}

/// One eye's stitch from the f64 twin, rows top-down.
#[derive(Debug, Clone)]
pub struct EyeReference {
    /// Colour, 0..=255 per channel, unrounded.
    pub color: Vec<V3>,
    /// Distance along the ODS ray from its origin on the viewing circle to the surface the
    /// colour came from, metres; 0 where that is sky.
    pub distance: Vec<f64>,
}

/// Stitched colour and ray distance of one eye's equirect, rows top-down.
pub fn stitch_reference_eye(set: &FaceSet, params: &StitchParams) -> Result<EyeReference> {
    set.validate()?;
    params.validate(set)?;
    let n = set.size();
    let cam = face_camera(n, set.fov_deg);
    let faces: Vec<Face> = CubeFace::ALL
        .iter()
        .zip(&set.faces)
        .map(|(f, img)| Face {
            color: &img.color.data,
            depth: &img.depth.data,
            rot: f.rotation(),
            eye: f.pose(&set.rig, set.side).position,
            f: cam.k.fx,
            c: cam.k.cx,
            n: n as i64,
        })
        .collect();
    let (w, h) = (params.width, params.height);
    let n = w as usize * h as usize;
    let mut out = EyeReference {
        color: Vec::with_capacity(n),
        distance: Vec::with_capacity(n),
    };
    for v in 0..h {
        for u in 0..w {
            let (lon, lat) = equirect_angles(u, v, w, h);
            let (o, d) = set.rig.ray(set.side, lon, lat);
            let pw = pair_weight(d, params.overlap_deg);
            // Border weight's warps move colour, not surfaces: its distance is blend's.
            let (c, t) = match params.method {
                Method::Blend => (blend(&faces, &pw, d), mix_range(&faces, &pw, o, d)),
                Method::BorderWeight if pw.in_band => (
                    border_weight(&faces[pw.a], &faces[pw.b], pw.w, d),
                    mix_range(&faces, &pw, o, d),
                ),
                Method::BorderWeight => (faces[pw.primary].plain(d), mix_range(&faces, &pw, o, d)),
                Method::Reproject => reproject(&faces, &pw, o, d),
            };
            out.color.push(c);
            // As the shader writes it: nothing behind the ray's origin.
            out.distance.push(t.max(0.0));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn angle(a: V3, b: V3) -> f64 {
        dot(normalize(a), normalize(b)).clamp(-1.0, 1.0).acos()
    }

    #[test]
    fn the_seed_far_guess_warps_a_face_towards_the_other_eye() {
        // Left-eye +Z (cPos) and -X (cPosMX) face eyes of the demo rig, a surface ~1.5 m away.
        let (cpos, cposmx) = ([-0.032, 0.0, 1.6], [0.0, 0.0, 1.632]);
        let x = [-1.2, 0.3, 2.5];
        for (from, to) in [(cposmx, cpos), (cpos, cposmx)] {
            let seen = sub(far_guess(x, from, to), from);
            let want = sub(add(to, sub(x, from)), from);
            // dd with the other sign would be off by ~2 |dd| / range = 0.04 rad.
            assert!(angle(seen, want) < 1e-4, "{}", angle(seen, want));
            assert!(angle(seen, sub(x, from)) > 1e-2);
        }
    }
}
