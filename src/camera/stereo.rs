//! Stereo camera model: two parallel (not toed-in) eye frusta sharing one virtual screen at the
//! convergence distance (seed 004), the D3D-style texture reprojection between them (seed 002),
//! the stereo culling frustum and the parallax budget check.
//!
//! View space: x right, y up, and `Z` the positive distance along the optical axis (the view Z of
//! [`DepthPlanes`], which ends up in clip w). The GL form takes right-handed eye coordinates (the
//! camera looks down -z, so Z = -z); the D3D form takes left-handed ones (Z = z).
//!
//! Eye placement: eye `e` sits at x = `e.side()` * interaxial / 2 with `side` = -1 (left) or +1
//! (right) and interaxial = separation * (screen width at the convergence plane). The per-eye
//! clip shift is the seed's `clip.x += side * separation * (clip.w - convergence)`, so the NDC x
//! shift is `side * separation * (1 - convergence / Z)`: right minus left is 2 * [`parallax`] in
//! NDC (range 2 wide) and exactly [`parallax`] in texture space (range 1 wide).

use crate::convention::{Conventions, DepthPlanes, RowOrder};
use crate::error::{Error, Result};

/// Which eye. `side()` is the seed's sign: -1 for left, +1 for right.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Eye {
    /// The left eye.
    Left,
    /// The right eye.
    Right,
}

impl Eye {
    /// Left, then right.
    pub const BOTH: [Eye; 2] = [Eye::Left, Eye::Right];

    /// -1 for left, +1 for right: the eye sits at x = side * interaxial / 2.
    pub fn side(self) -> f64 {
        match self {
            Eye::Left => -1.0,
            Eye::Right => 1.0,
        }
    }

    /// The other eye.
    pub fn other(self) -> Eye {
        match self {
            Eye::Left => Eye::Right,
            Eye::Right => Eye::Left,
        }
    }
}

/// Side of an optional eye; `None` is the mono (centre) view.
fn side_of(view: Option<Eye>) -> f64 {
    view.map_or(0.0, Eye::side)
}

fn check_separation(separation: f64) -> Result<()> {
    if !separation.is_finite() || separation < 0.0 {
        return Err(Error::param(
            "separation",
            format!("{separation} must be finite and >= 0"),
        ));
    }
    Ok(())
}

fn check_positive(name: &str, v: f64) -> Result<()> {
    if !v.is_finite() || v <= 0.0 {
        return Err(Error::param(name, format!("{v} must be finite and > 0")));
    }
    Ok(())
}

/// Depth of a point for parallax purposes: positive, +inf allowed (parallax = separation).
fn check_depth(name: &str, depth: f64) -> Result<()> {
    if depth.is_nan() || depth <= 0.0 {
        return Err(Error::param(name, format!("{depth} must be > 0 (+inf allowed)")));
    }
    Ok(())
}

/// Validated stereo parameters in the seed's normalised form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoParams {
    separation: f64,
    convergence: f64,
}

impl StereoParams {
    /// `separation` = interaxial / screen width (>= 0; 0 is the mono camera exactly),
    /// `convergence` = view distance of zero parallax (> 0).
    pub fn new(separation: f64, convergence: f64) -> Result<Self> {
        check_separation(separation)?;
        check_positive("convergence", convergence)?;
        Ok(StereoParams {
            separation,
            convergence,
        })
    }

    /// From the physical interaxial (eye distance, view units) and the width of the virtual screen
    /// at the convergence plane (e.g. [`Frustum::width_at`]`(convergence)`).
    pub fn from_interaxial(interaxial: f64, screen_width: f64, convergence: f64) -> Result<Self> {
        if !interaxial.is_finite() || interaxial < 0.0 {
            return Err(Error::param(
                "interaxial",
                format!("{interaxial} must be finite and >= 0"),
            ));
        }
        check_positive("screen width", screen_width)?;
        Self::new(interaxial / screen_width, convergence)
    }

    /// Separation: interaxial over the virtual screen width (texture units).
    pub fn separation(&self) -> f64 {
        self.separation
    }

    /// Convergence: the zero-parallax distance, view units.
    pub fn convergence(&self) -> f64 {
        self.convergence
    }

    /// Distance between the eyes in view units for this frustum.
    pub fn interaxial(&self, frustum: &Frustum) -> f64 {
        self.separation * frustum.width_at(self.convergence)
    }
}

/// Image-space parallax (range [0, 1] across the image) of a point at view distance `depth`:
/// `separation * (1 - convergence / depth)`. Zero at the convergence plane, `separation` at
/// infinity (`depth = +inf` is accepted and gives exactly `separation`).
///
/// Errors: invalid separation/convergence, or `depth` NaN or <= 0 (no image position exists).
pub fn parallax(separation: f64, convergence: f64, depth: f64) -> Result<f64> {
    check_separation(separation)?;
    check_positive("convergence", convergence)?;
    check_depth("depth", depth)?;
    Ok(separation * (1.0 - convergence / depth))
}

/// Mono frustum as tangents of its side planes: a view point (x, y, Z) is inside when
/// left <= x / Z <= right and bottom <= y / Z <= top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    left: f64,
    right: f64,
    bottom: f64,
    top: f64,
}

impl Frustum {
    /// Symmetric frustum from the vertical field of view (radians, in (0, pi)) and aspect = w / h.
    pub fn from_fov_y(fov_y: f64, aspect: f64) -> Result<Self> {
        if !(fov_y > 0.0 && fov_y < std::f64::consts::PI) {
            return Err(Error::param("fov_y", format!("{fov_y} rad outside (0, pi)")));
        }
        check_positive("aspect", aspect)?;
        let t = (0.5 * fov_y).tan();
        Self::from_tangents(-aspect * t, aspect * t, -t, t)
    }

    /// glFrustum-style bounds of the window on the near plane at distance `near`.
    pub fn from_near_bounds(left: f64, right: f64, bottom: f64, top: f64, near: f64) -> Result<Self> {
        check_positive("near", near)?;
        Self::from_tangents(left / near, right / near, bottom / near, top / near)
    }

    /// Directly from the tangents (left < right, bottom < top, all finite).
    pub fn from_tangents(left: f64, right: f64, bottom: f64, top: f64) -> Result<Self> {
        for (name, v) in [("left", left), ("right", right), ("bottom", bottom), ("top", top)] {
            if !v.is_finite() {
                return Err(Error::param(format!("frustum {name}"), format!("{v} is not finite")));
            }
        }
        if right <= left || top <= bottom {
            return Err(Error::param(
                "frustum",
                format!("need left < right and bottom < top, got [{left}, {right}] x [{bottom}, {top}]"),
            ));
        }
        Ok(Frustum {
            left,
            right,
            bottom,
            top,
        })
    }

    /// (left, right, bottom, top) tangents.
    pub fn tangents(&self) -> (f64, f64, f64, f64) {
        (self.left, self.right, self.bottom, self.top)
    }

    /// Width of the frustum's cross-section at view distance `depth`.
    pub fn width_at(&self, depth: f64) -> f64 {
        (self.right - self.left) * depth
    }
}

fn check_planes(planes: &DepthPlanes) -> Result<()> {
    check_positive("near", planes.near)?;
    if planes.far.is_nan() || planes.far <= planes.near {
        return Err(Error::param(
            "far",
            format!("{} must be > near = {}", planes.far, planes.near),
        ));
    }
    Ok(())
}

/// Rows of the projection over (x, y, Z, 1), column-vector convention. The shared core of the
/// GL and D3D forms; the stereo shift only touches the x row.
fn view_z_rows(
    frustum: &Frustum,
    planes: &DepthPlanes,
    conv: &Conventions,
    stereo: Option<(Eye, &StereoParams)>,
) -> Result<[[f64; 4]; 4]> {
    check_planes(planes)?;
    let (l, r, b, t) = frustum.tangents();
    // NDC y points down for top-down row order (Vulkan), so the picture stays upright in memory.
    let ys = match conv.row_order {
        RowOrder::BottomUp => 1.0,
        RowOrder::TopDown => -1.0,
    };
    let mut x_z = -(r + l) / (r - l);
    let mut x_w = 0.0;
    if let Some((eye, p)) = stereo {
        // x_clip += side * sep * (w - conv) with w = Z.
        let k = eye.side() * p.separation;
        x_z += k;
        x_w = -k * p.convergence;
    }
    let (za, zb) = planes.clip_z_coefficients(conv);
    Ok([
        [2.0 / (r - l), 0.0, x_z, x_w],
        [0.0, ys * 2.0 / (t - b), -ys * (t + b) / (t - b), 0.0],
        [0.0, 0.0, za, zb],
        [0.0, 0.0, 1.0, 0.0],
    ])
}

/// Column-major (index = col * 4 + row) for right-handed eye coordinates: Z = -z flips column 2.
fn to_gl(m: &[[f64; 4]; 4]) -> [f64; 16] {
    let mut out = [0.0; 16];
    for (i, row) in m.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            out[j * 4 + i] = if j == 2 { -v } else { v };
        }
    }
    out
}

/// Row-vector form (clip = p * M) for left-handed eye coordinates (Z = z): the transpose.
fn to_d3d(m: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut out = [[0.0; 4]; 4];
    for (i, row) in m.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            out[j][i] = v;
        }
    }
    out
}

/// Mono perspective projection, OpenGL style: column-major array for
/// `glUniformMatrix4fv(.., transpose = false, ..)`, right-handed eye space (looking down -z),
/// clip = M * p. Depth row from [`DepthPlanes::clip_z_coefficients`] under `conv`.
pub fn mono_projection_gl(frustum: &Frustum, planes: &DepthPlanes, conv: &Conventions) -> Result<[f64; 16]> {
    Ok(to_gl(&view_z_rows(frustum, planes, conv, None)?))
}

/// Mono perspective projection, D3D9 style: `m[row][col]`, row vectors (clip = p * M),
/// left-handed eye space (looking down +z). Use [`NdcDepthRange::ZeroToOne`] for D3D's z in [0, 1].
///
/// [`NdcDepthRange::ZeroToOne`]: crate::convention::NdcDepthRange::ZeroToOne
pub fn mono_projection_d3d(frustum: &Frustum, planes: &DepthPlanes, conv: &Conventions) -> Result<[[f64; 4]; 4]> {
    Ok(to_d3d(&view_z_rows(frustum, planes, conv, None)?))
}

/// Seed 004's stereo projection, GL form: the mono matrix with `p13 - side * separation` and
/// `-side * separation * convergence` in the x row, i.e. clip = [`clip_shift`](mono * p).
pub fn stereo_projection_gl(
    frustum: &Frustum,
    planes: &DepthPlanes,
    conv: &Conventions,
    eye: Eye,
    params: &StereoParams,
) -> Result<[f64; 16]> {
    Ok(to_gl(&view_z_rows(frustum, planes, conv, Some((eye, params)))?))
}

/// Seed 004's stereo projection, D3D form: `m[2][0] = p13 + side * separation`,
/// `m[3][0] = -side * separation * convergence`.
pub fn stereo_projection_d3d(
    frustum: &Frustum,
    planes: &DepthPlanes,
    conv: &Conventions,
    eye: Eye,
    params: &StereoParams,
) -> Result<[[f64; 4]; 4]> {
    Ok(to_d3d(&view_z_rows(frustum, planes, conv, Some((eye, params)))?))
}

/// clip = M * p for a column-major matrix.
pub fn gl_transform(m: &[f64; 16], p: [f64; 4]) -> [f64; 4] {
    std::array::from_fn(|i| m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i] * p[3])
}

/// clip = p * M for a row-major, row-vector matrix.
pub fn d3d_transform(p: [f64; 4], m: &[[f64; 4]; 4]) -> [f64; 4] {
    std::array::from_fn(|j| p[0] * m[0][j] + p[1] * m[1][j] + p[2] * m[2][j] + p[3] * m[3][j])
}

/// Seed 004's vertex-shader form: `clip.x += side * separation * (clip.w - convergence)`.
pub fn clip_shift(clip: [f64; 4], eye: Eye, params: &StereoParams) -> [f64; 4] {
    let [x, y, z, w] = clip;
    [x + eye.side() * params.separation * (w - params.convergence), y, z, w]
}

/// Seed 002's reprojection in texture space (x in [0, 1] across the image) between views at a
/// known view distance: `x_to = x + (side_to - side_from) / 2 * separation * (1 - convergence / Z)`.
/// `None` is the mono (centre) view, so left -> right moves by `S - S c / Z` and centre -> eye by
/// half that, with the seed's per-eye signs.
///
/// Errors: non-finite `x`, invalid separation/convergence, or `view_depth` NaN or <= 0.
pub fn reproject_texture_x(
    x: f64,
    from: Option<Eye>,
    to: Option<Eye>,
    separation: f64,
    convergence: f64,
    view_depth: f64,
) -> Result<f64> {
    if !x.is_finite() {
        return Err(Error::param("texture x", format!("{x} is not finite")));
    }
    let p = parallax(separation, convergence, view_depth)?;
    Ok(x + 0.5 * (side_of(to) - side_of(from)) * p)
}

/// Which single culling frustum to build for a stereo pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CullingKind {
    /// The smallest frustum with the union of both eyes' directions that holds both eye frusta:
    /// each side plane passes through the outer eye and is parallel to the other eye's outer
    /// plane. Apex behind the mono eye at Z = -convergence / (1 + 1 / separation).
    Enclosing,
    /// Seed 004's culling frustum: the side planes are the right eye's left plane and the left
    /// eye's right plane. Beyond the screen it holds every point either eye sees; in front of it,
    /// only points both eyes see (no object out of the screen in one eye only). Apex in front of
    /// the mono eye at Z = +convergence / (1 + 1 / separation), where the two frusta start to overlap.
    ScreenWindow,
}

/// One frustum for culling both eyes, as inward planes over view (x, y, Z): a point is inside
/// when `a x + b y + c Z + d >= 0` for all four. Near/far are the mono ones (the eyes only move
/// along x, so their Z planes coincide); top/bottom are the mono planes for the same reason.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoCullingFrustum {
    /// Signed view Z where the left and right planes meet.
    pub apex_z: f64,
    /// Left, right, bottom, top (normals not normalised).
    pub planes: [[f64; 4]; 4],
}

impl StereoCullingFrustum {
    /// Eyes at x = -/+ i/2 with i = separation * width at convergence. Outer edges have slopes
    /// kl = left - i / (2c), kr = right + i / (2c); the side planes through x = -/+ i/2 (enclosing)
    /// or +/- i/2 (screen window) at Z = 0 meet where (kr - kl) Z = -/+ i, i.e.
    /// Z = -/+ i c / (W + i) = -/+ c / (1 + 1 / separation).
    pub fn new(frustum: &Frustum, params: &StereoParams, kind: CullingKind) -> Self {
        let (l, r, b, t) = frustum.tangents();
        let sep = params.separation;
        let c = params.convergence;
        let half_slope = 0.5 * sep * (r - l); // i / (2c)
        let half_iax = half_slope * c; // i / 2
        let (kl, kr) = (l - half_slope, r + half_slope);
        let (d, sign) = match kind {
            CullingKind::Enclosing => (half_iax, -1.0),
            CullingKind::ScreenWindow => (-half_iax, 1.0),
        };
        StereoCullingFrustum {
            // c / (1 + 1/sep) written to stay exact (0) at sep = 0.
            apex_z: sign * c * sep / (1.0 + sep),
            planes: [
                [1.0, 0.0, -kl, d],
                [-1.0, 0.0, kr, d],
                [0.0, 1.0, -b, 0.0],
                [0.0, -1.0, t, 0.0],
            ],
        }
    }

    /// Whether view point (x, y, Z) is inside all four planes.
    pub fn contains(&self, p: [f64; 3]) -> bool {
        self.planes
            .iter()
            .all(|q| q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] >= 0.0)
    }
}

/// Seed 004's parallax budget: scene content should lie in [convergence / 2, 100 * convergence].
/// Nearer than convergence / 2 the parallax passes -separation (eye strain); farther than
/// 100 * convergence it is above 99 % of separation (no depth differentiation). Returns one
/// warning per violated bound, empty when the range fits. `far_scene` may be +inf (a sky).
///
/// Errors: `near_scene` not finite or <= 0, `far_scene` NaN or < `near_scene`, invalid convergence.
pub fn parallax_budget(near_scene: f64, far_scene: f64, convergence: f64) -> Result<Vec<String>> {
    check_positive("near scene depth", near_scene)?;
    check_positive("convergence", convergence)?;
    if far_scene.is_nan() || far_scene < near_scene {
        return Err(Error::param(
            "far scene depth",
            format!("{far_scene} must be >= near scene depth {near_scene}"),
        ));
    }
    // Parallax as a fraction of separation, independent of separation.
    let fraction = |z: f64| 1.0 - convergence / z;
    let mut warnings = Vec::new();
    if near_scene < 0.5 * convergence {
        warnings.push(format!(
            "nearest scene depth {near_scene} is closer than convergence / 2 = {}: parallax {:.3} x separation \
             (beyond -separation), expect eye strain",
            0.5 * convergence,
            fraction(near_scene)
        ));
    }
    if far_scene > 100.0 * convergence {
        warnings.push(format!(
            "farthest scene depth {far_scene} is beyond 100 x convergence = {}: parallax {:.4} x separation \
             (above 0.99), distant content looks flat",
            100.0 * convergence,
            fraction(far_scene)
        ));
    }
    Ok(warnings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convention::NdcDepthRange;

    use crate::test_rng::Rng;

    fn cases(rng: &mut Rng) -> Vec<(Frustum, DepthPlanes, StereoParams)> {
        let mut out = Vec::new();
        for k in 0..40 {
            let frustum = if k % 2 == 0 {
                Frustum::from_fov_y(rng.range(0.2, 2.5), rng.range(0.5, 2.5)).unwrap()
            } else {
                // Off-axis.
                let near = rng.range(0.01, 1.0);
                let l = rng.range(-1.0, 0.3) * near;
                let b = rng.range(-1.0, 0.3) * near;
                Frustum::from_near_bounds(
                    l,
                    l + rng.range(0.2, 2.0) * near,
                    b,
                    b + rng.range(0.2, 2.0) * near,
                    near,
                )
                .unwrap()
            };
            let near = rng.range(0.01, 1.0);
            let far = if k % 5 == 0 {
                f64::INFINITY
            } else {
                near * rng.range(2.0, 1e4)
            };
            let sep = if k % 7 == 0 { 0.0 } else { rng.range(0.0, 0.1) };
            let params = StereoParams::new(sep, rng.range(0.5, 20.0)).unwrap();
            out.push((frustum, DepthPlanes { near, far }, params));
        }
        out
    }

    /// A view point in (x, y, Z), roughly around the frustum, and its GL and D3D eye coordinates.
    fn point(rng: &mut Rng, f: &Frustum, zmax: f64) -> ([f64; 3], [f64; 4], [f64; 4]) {
        let (l, r, b, t) = f.tangents();
        let z = rng.range(1e-3, zmax);
        let x = rng.range(l - 0.5, r + 0.5) * z;
        let y = rng.range(b - 0.5, t + 0.5) * z;
        ([x, y, z], [x, y, -z, 1.0], [x, y, z, 1.0])
    }

    fn close(a: f64, b: f64, scale: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * scale.max(1.0)
    }

    #[test]
    fn stereo_matrix_equals_clip_shift_of_mono() {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        for (f, planes, params) in cases(&mut rng) {
            for conv in Conventions::all() {
                let mono_gl = mono_projection_gl(&f, &planes, &conv).unwrap();
                let mono_d3d = mono_projection_d3d(&f, &planes, &conv).unwrap();
                for eye in Eye::BOTH {
                    let st_gl = stereo_projection_gl(&f, &planes, &conv, eye, &params).unwrap();
                    let st_d3d = stereo_projection_d3d(&f, &planes, &conv, eye, &params).unwrap();
                    for _ in 0..50 {
                        let (_, pg, pd) = point(&mut rng, &f, 100.0);
                        let want = clip_shift(gl_transform(&mono_gl, pg), eye, &params);
                        let got = gl_transform(&st_gl, pg);
                        let want_d = clip_shift(d3d_transform(pd, &mono_d3d), eye, &params);
                        let got_d = d3d_transform(pd, &st_d3d);
                        // Scale: magnitude of the summed terms of the x row.
                        let scale = want[0].abs() + params.separation() * (pg[2].abs() + params.convergence());
                        for i in 0..4 {
                            assert!(close(got[i], want[i], scale, 1e-12), "{conv:?} {eye:?} i={i}");
                            assert!(close(got_d[i], want_d[i], scale, 1e-12), "{conv:?} {eye:?} i={i}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn gl_and_d3d_forms_give_identical_clip_coordinates() {
        let mut rng = Rng(7);
        for (f, planes, params) in cases(&mut rng) {
            for conv in Conventions::all() {
                let pairs = [
                    (
                        mono_projection_gl(&f, &planes, &conv).unwrap(),
                        mono_projection_d3d(&f, &planes, &conv).unwrap(),
                    ),
                    (
                        stereo_projection_gl(&f, &planes, &conv, Eye::Left, &params).unwrap(),
                        stereo_projection_d3d(&f, &planes, &conv, Eye::Left, &params).unwrap(),
                    ),
                    (
                        stereo_projection_gl(&f, &planes, &conv, Eye::Right, &params).unwrap(),
                        stereo_projection_d3d(&f, &planes, &conv, Eye::Right, &params).unwrap(),
                    ),
                ];
                for (gl, d3d) in &pairs {
                    // Same memory layout up to the handedness flip of column 2.
                    for i in 0..4 {
                        for j in 0..4 {
                            let s = if i == 2 { -1.0 } else { 1.0 };
                            assert_eq!(gl[i * 4 + j], s * d3d[i][j]);
                        }
                    }
                    for _ in 0..50 {
                        let (_, pg, pd) = point(&mut rng, &f, 100.0);
                        // Negation and the summation order are exact/equal: bitwise equality.
                        assert_eq!(gl_transform(gl, pg), d3d_transform(pd, d3d), "{conv:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn ndc_difference_between_eyes_is_twice_the_image_parallax() {
        let mut rng = Rng(11);
        for (f, planes, params) in cases(&mut rng) {
            let conv = Conventions::default();
            let left = stereo_projection_gl(&f, &planes, &conv, Eye::Left, &params).unwrap();
            let right = stereo_projection_gl(&f, &planes, &conv, Eye::Right, &params).unwrap();
            for _ in 0..200 {
                let (p, pg, _) = point(&mut rng, &f, 50.0 * params.convergence());
                let (cl, cr) = (gl_transform(&left, pg), gl_transform(&right, pg));
                assert_eq!(cl[3], p[2]);
                let (xl, xr) = (cl[0] / cl[3], cr[0] / cr[3]);
                let want = 2.0 * parallax(params.separation(), params.convergence(), p[2]).unwrap();
                let scale = xl.abs() + xr.abs() + want.abs();
                assert!(close(xr - xl, want, scale, 1e-12), "{} vs {want}", xr - xl);
                // Texture space (x_tex = (x_ndc + 1) / 2): exactly the image parallax.
                assert!(close(0.5 * (xr - xl), 0.5 * want, scale, 1e-12));
            }
        }
    }

    #[test]
    fn zero_parallax_at_convergence_and_separation_at_infinity() {
        let mut rng = Rng(13);
        for (f, planes, params) in cases(&mut rng) {
            let (sep, c) = (params.separation(), params.convergence());
            assert_eq!(parallax(sep, c, c).unwrap(), 0.0);
            assert_eq!(parallax(sep, c, f64::INFINITY).unwrap(), sep);
            // 1 - 1e-12 of separation, up to rounding.
            assert!((parallax(sep, c, 1e12 * c).unwrap() - sep).abs() <= 2e-12 * sep);
            for conv in Conventions::all() {
                let left = stereo_projection_d3d(&f, &planes, &conv, Eye::Left, &params).unwrap();
                let right = stereo_projection_d3d(&f, &planes, &conv, Eye::Right, &params).unwrap();
                let mono = mono_projection_d3d(&f, &planes, &conv).unwrap();
                for _ in 0..20 {
                    let (l, r, b, t) = f.tangents();
                    let on_screen = [rng.range(l, r) * c, rng.range(b, t) * c, c, 1.0];
                    let (cl, cr, cm) = (
                        d3d_transform(on_screen, &left),
                        d3d_transform(on_screen, &right),
                        d3d_transform(on_screen, &mono),
                    );
                    let (xl, xr, xm) = (cl[0] / cl[3], cr[0] / cr[3], cm[0] / cm[3]);
                    assert!((xl - xm).abs() <= 1e-12 && (xr - xm).abs() <= 1e-12, "{xl} {xr} {xm}");
                    // Far away the eyes differ by 2 * separation in NDC.
                    let z = 1e12 * c;
                    let far = [rng.range(l, r) * z, rng.range(b, t) * z, z, 1.0];
                    let (cl, cr) = (d3d_transform(far, &left), d3d_transform(far, &right));
                    let d = cr[0] / cr[3] - cl[0] / cl[3];
                    assert!((d - 2.0 * sep).abs() <= 1e-10, "{d} vs {}", 2.0 * sep);
                }
            }
        }
    }

    #[test]
    fn zero_separation_is_the_mono_camera_exactly() {
        let mut rng = Rng(17);
        for (f, planes, params) in cases(&mut rng) {
            let zero = StereoParams::new(0.0, params.convergence()).unwrap();
            for conv in Conventions::all() {
                let mono_gl = mono_projection_gl(&f, &planes, &conv).unwrap();
                let mono_d3d = mono_projection_d3d(&f, &planes, &conv).unwrap();
                for eye in Eye::BOTH {
                    assert_eq!(stereo_projection_gl(&f, &planes, &conv, eye, &zero).unwrap(), mono_gl);
                    assert_eq!(stereo_projection_d3d(&f, &planes, &conv, eye, &zero).unwrap(), mono_d3d);
                    let (_, pg, _) = point(&mut rng, &f, 10.0);
                    let c = gl_transform(&mono_gl, pg);
                    assert_eq!(clip_shift(c, eye, &zero), c);
                }
            }
            let (l, r, b, t) = f.tangents();
            let cull = StereoCullingFrustum::new(&f, &zero, CullingKind::Enclosing);
            assert_eq!(cull.apex_z, 0.0);
            assert_eq!(cull.planes[0], [1.0, 0.0, -l, 0.0]);
            assert_eq!(cull.planes[1], [-1.0, 0.0, r, 0.0]);
            assert_eq!(cull.planes[2], [0.0, 1.0, -b, 0.0]);
            assert_eq!(cull.planes[3], [0.0, -1.0, t, 0.0]);
        }
    }

    #[test]
    fn projection_maps_frustum_corners_and_depth_planes_under_every_convention() {
        let f = Frustum::from_near_bounds(-0.3, 0.5, -0.2, 0.4, 0.5).unwrap();
        let planes = DepthPlanes { near: 0.5, far: 40.0 };
        for conv in Conventions::all() {
            let m = mono_projection_gl(&f, &planes, &conv).unwrap();
            let (zn, zf) = conv.ndc_z_near_far();
            let ys = if conv.row_order == RowOrder::TopDown { -1.0 } else { 1.0 };
            for (z, zndc) in [(0.5, zn), (40.0, zf)] {
                let s = z / 0.5;
                // Bottom-left and top-right window corners (GL eye space, z = -Z).
                let bl = gl_transform(&m, [-0.3 * s, -0.2 * s, -z, 1.0]);
                let tr = gl_transform(&m, [0.5 * s, 0.4 * s, -z, 1.0]);
                let ndc = |c: [f64; 4]| [c[0] / c[3], c[1] / c[3], c[2] / c[3]];
                let (a, b) = (ndc(bl), ndc(tr));
                for (got, want) in [
                    (a[0], -1.0),
                    (a[1], -ys),
                    (a[2], zndc),
                    (b[0], 1.0),
                    (b[1], ys),
                    (b[2], zndc),
                ] {
                    assert!((got - want).abs() < 1e-12, "{conv:?} {got} vs {want}");
                }
            }
        }
        // The seed's GL matrix shape: p33, p34 and w = -z.
        let gl = Conventions::default();
        let m = mono_projection_gl(&f, &planes, &gl).unwrap();
        let (n, fa) = (0.5, 40.0);
        assert!((m[10] + (fa + n) / (fa - n)).abs() < 1e-12);
        assert!((m[14] + 2.0 * fa * n / (fa - n)).abs() < 1e-12);
        assert_eq!(m[11], -1.0);
        // D3D: m[2][2] = f / (f - n), m[3][2] = -n f / (f - n), m[2][3] = 1.
        let d3d = Conventions {
            ndc_depth: NdcDepthRange::ZeroToOne,
            ..Conventions::default()
        };
        let m = mono_projection_d3d(&f, &planes, &d3d).unwrap();
        assert!((m[2][2] - fa / (fa - n)).abs() < 1e-12);
        assert!((m[3][2] + n * fa / (fa - n)).abs() < 1e-12);
        assert_eq!(m[2][3], 1.0);
    }

    #[test]
    fn eye_centre_of_projection_is_at_half_interaxial() {
        let mut rng = Rng(19);
        for (f, planes, params) in cases(&mut rng) {
            let iax = params.interaxial(&f);
            let back = StereoParams::from_interaxial(iax, f.width_at(params.convergence()), params.convergence());
            assert!((back.unwrap().separation() - params.separation()).abs() <= 1e-15);
            for eye in Eye::BOTH {
                let m = stereo_projection_d3d(&f, &planes, &Conventions::default(), eye, &params).unwrap();
                let e = eye.side() * 0.5 * iax;
                for _ in 0..20 {
                    // Two points on one ray from the eye project to the same NDC.
                    let v = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 1.0];
                    let (a, b) = (rng.range(0.1, 5.0), rng.range(5.0, 500.0));
                    let ca = d3d_transform([e + a * v[0], a * v[1], a, 1.0], &m);
                    let cb = d3d_transform([e + b * v[0], b * v[1], b, 1.0], &m);
                    let (xa, xb) = (ca[0] / ca[3], cb[0] / cb[3]);
                    assert!((xa - xb).abs() <= 1e-12 * (1.0 + xa.abs()), "{eye:?} {xa} {xb}");
                }
            }
        }
    }

    #[test]
    fn reprojection_helper_maps_one_eye_image_onto_the_other() {
        let mut rng = Rng(23);
        for (f, planes, params) in cases(&mut rng) {
            let (sep, c) = (params.separation(), params.convergence());
            for conv in Conventions::all() {
                let mono = mono_projection_gl(&f, &planes, &conv).unwrap();
                let left = stereo_projection_gl(&f, &planes, &conv, Eye::Left, &params).unwrap();
                let right = stereo_projection_gl(&f, &planes, &conv, Eye::Right, &params).unwrap();
                let tex = |m: &[f64; 16], p: [f64; 4]| {
                    let q = gl_transform(m, p);
                    0.5 * (q[0] / q[3] + 1.0)
                };
                for _ in 0..50 {
                    let (p, pg, _) = point(&mut rng, &f, 30.0 * c);
                    let views = [
                        (Some(Eye::Left), tex(&left, pg)),
                        (None, tex(&mono, pg)),
                        (Some(Eye::Right), tex(&right, pg)),
                    ];
                    for &(from, xf) in &views {
                        for &(to, xt) in &views {
                            let got = reproject_texture_x(xf, from, to, sep, c, p[2]).unwrap();
                            let scale = xf.abs() + xt.abs() + sep * c / p[2];
                            assert!(close(got, xt, scale, 1e-12), "{from:?}->{to:?} {got} vs {xt}");
                        }
                    }
                    // The seed's literal form, left -> right: x + S - S c / z.
                    let (xl, xr) = (views[0].1, views[2].1);
                    assert!(close(xl + sep - sep * c / p[2], xr, xl.abs() + sep * c / p[2], 1e-12));
                }
            }
        }
    }

    #[test]
    fn culling_frustums_hold_what_the_eyes_see() {
        let mut rng = Rng(29);
        let conv = Conventions::default();
        let (mut checked, mut in_one_only) = (0usize, 0usize);
        for (f, planes, params) in cases(&mut rng) {
            let c = params.convergence();
            let enclosing = StereoCullingFrustum::new(&f, &params, CullingKind::Enclosing);
            let window = StereoCullingFrustum::new(&f, &params, CullingKind::ScreenWindow);
            let eyes = Eye::BOTH.map(|e| stereo_projection_d3d(&f, &planes, &conv, e, &params).unwrap());
            let half_iax = 0.5 * params.interaxial(&f);
            let wide = Frustum::from_tangents(
                f.tangents().0 - 1.0,
                f.tangents().1 + 1.0,
                f.tangents().2,
                f.tangents().3,
            )
            .unwrap();
            for _ in 0..2000 {
                let (p, _, pd) = point(&mut rng, &wide, 4.0 * c);
                // Inside-ness of each eye with a margin, to skip points on a boundary.
                let mut margin = f64::INFINITY;
                let inside = eyes.map(|m| {
                    let q = d3d_transform(pd, &m);
                    let s = [q[3] - q[0], q[3] + q[0], q[3] - q[1], q[3] + q[1]];
                    margin = s.iter().fold(margin, |a, v| a.min(v.abs() / q[3]));
                    s.iter().all(|&v| v >= 0.0)
                });
                for cull in [&enclosing, &window] {
                    for q in &cull.planes {
                        let v = q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3];
                        margin = margin.min(v.abs() / p[2]);
                    }
                }
                if margin < 1e-9 {
                    continue;
                }
                checked += 1;
                let (either, both) = (inside[0] || inside[1], inside[0] && inside[1]);
                in_one_only += (either && !both) as usize;
                if either {
                    assert!(enclosing.contains(p), "{p:?}");
                }
                // Screen window: either eye beyond the screen, both eyes in front of it.
                let want = if p[2] >= c { either } else { both };
                assert_eq!(window.contains(p), want, "{p:?} c={c} {inside:?}");
            }
            // Side planes: the window's are the eyes' outer planes; the enclosing ones pass through
            // the outer eye and run parallel to the other eye's outer plane (constant offset i).
            for _ in 0..20 {
                let z = rng.range(0.01, 10.0 * c);
                let (l, r, b, t) = f.tangents();
                let y = rng.range(b, t) * z;
                // Right eye's left boundary (x_clip = -w) and left eye's right boundary (x_clip = w).
                let x_rl = 0.5 * params.interaxial(&f) + (l - 0.5 * params.separation() * (r - l)) * z;
                let x_lr = -0.5 * params.interaxial(&f) + (r + 0.5 * params.separation() * (r - l)) * z;
                let qr = d3d_transform([x_rl, y, z, 1.0], &eyes[1]);
                let ql = d3d_transform([x_lr, y, z, 1.0], &eyes[0]);
                assert!((qr[0] + qr[3]).abs() <= 1e-12 * z.max(1.0) && (ql[0] - ql[3]).abs() <= 1e-12 * z.max(1.0));
                let eval = |q: &[f64; 4], x: f64| q[0] * x + q[1] * y + q[2] * z + q[3];
                let tol = 1e-12 * (z + half_iax).max(1.0);
                assert!(eval(&window.planes[0], x_rl).abs() <= tol);
                assert!(eval(&window.planes[1], x_lr).abs() <= tol);
                assert!((eval(&enclosing.planes[0], x_rl) - 2.0 * half_iax).abs() <= tol);
                assert!((eval(&enclosing.planes[1], x_lr) - 2.0 * half_iax).abs() <= tol);
            }
            assert!(eval_at(&enclosing.planes[0], [-half_iax, 0.0, 0.0]).abs() <= 1e-15);
            assert!(eval_at(&enclosing.planes[1], [half_iax, 0.0, 0.0]).abs() <= 1e-15);
            // Apex: the seed's c / (1 + 1 / separation), behind (enclosing) or in front (window),
            // equal to where the two side planes intersect.
            let sep = params.separation();
            if sep > 0.0 {
                let seed = c / (1.0 + 1.0 / sep);
                assert!((enclosing.apex_z + seed).abs() <= 1e-14 * seed.max(1.0));
                assert!((window.apex_z - seed).abs() <= 1e-14 * seed.max(1.0));
                for cull in [&enclosing, &window] {
                    let [pl, pr, _, _] = cull.planes;
                    // x = -(c_l Z + d_l) = c_r Z + d_r  =>  Z = -(d_l + d_r) / (c_l + c_r).
                    let z = -(pl[3] + pr[3]) / (pl[2] + pr[2]);
                    assert!(
                        (z - cull.apex_z).abs() <= 1e-12 * seed.max(1.0),
                        "{z} vs {}",
                        cull.apex_z
                    );
                }
            }
        }
        assert!(checked > 70_000 && in_one_only > 1_000, "{checked} {in_one_only}");
    }

    fn eval_at(q: &[f64; 4], p: [f64; 3]) -> f64 {
        q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3]
    }

    #[test]
    fn parallax_budget_warns_outside_half_to_hundred_times_convergence() {
        assert!(parallax_budget(1.0, 200.0, 2.0).unwrap().is_empty());
        let near = parallax_budget(0.9, 200.0, 2.0).unwrap();
        assert_eq!(near.len(), 1);
        assert!(near[0].contains("convergence / 2"), "{}", near[0]);
        let far = parallax_budget(1.0, 200.5, 2.0).unwrap();
        assert_eq!(far.len(), 1);
        assert!(far[0].contains("100 x convergence"), "{}", far[0]);
        assert_eq!(parallax_budget(0.1, f64::INFINITY, 2.0).unwrap().len(), 2);
        // The seed's landmarks: -separation at c / 2, 99 % of separation at 100 c.
        assert_eq!(parallax(0.05, 2.0, 1.0).unwrap(), -0.05);
        assert!((parallax(0.05, 2.0, 200.0).unwrap() - 0.99 * 0.05).abs() < 1e-15);
        for (n, f, c) in [
            (0.0, 1.0, 1.0),
            (f64::NAN, 1.0, 1.0),
            (1.0, 0.5, 1.0),
            (1.0, f64::NAN, 1.0),
            (1.0, 2.0, 0.0),
        ] {
            assert!(parallax_budget(n, f, c).is_err(), "{n} {f} {c}");
        }
    }

    #[test]
    fn invalid_parameters_are_errors_never_nan() {
        assert!(StereoParams::new(-0.01, 1.0).is_err());
        assert!(StereoParams::new(f64::NAN, 1.0).is_err());
        assert!(StereoParams::new(0.1, 0.0).is_err());
        assert!(StereoParams::new(0.1, f64::INFINITY).is_err());
        assert!(StereoParams::from_interaxial(0.065, 0.0, 1.0).is_err());
        for d in [0.0, -1.0, f64::NAN, f64::NEG_INFINITY] {
            assert!(parallax(0.1, 1.0, d).is_err(), "{d}");
            assert!(reproject_texture_x(0.5, Some(Eye::Left), None, 0.1, 1.0, d).is_err());
        }
        assert!(reproject_texture_x(f64::NAN, None, None, 0.1, 1.0, 2.0).is_err());
        assert!(Frustum::from_fov_y(0.0, 1.0).is_err());
        assert!(Frustum::from_fov_y(std::f64::consts::PI, 1.0).is_err());
        assert!(Frustum::from_fov_y(1.0, f64::NAN).is_err());
        assert!(Frustum::from_tangents(1.0, -1.0, -1.0, 1.0).is_err());
        assert!(Frustum::from_near_bounds(-1.0, 1.0, -1.0, 1.0, 0.0).is_err());
        let f = Frustum::from_fov_y(1.0, 1.5).unwrap();
        let conv = Conventions::default();
        for planes in [
            DepthPlanes { near: 0.0, far: 10.0 },
            DepthPlanes { near: 1.0, far: 1.0 },
            DepthPlanes {
                near: 1.0,
                far: f64::NAN,
            },
        ] {
            assert!(mono_projection_gl(&f, &planes, &conv).is_err(), "{planes:?}");
        }
        // Infinite far plane is fine and finite.
        let m = mono_projection_gl(
            &f,
            &DepthPlanes {
                near: 0.1,
                far: f64::INFINITY,
            },
            &conv,
        )
        .unwrap();
        assert!(m.iter().all(|v| v.is_finite()));
        assert_eq!(Eye::Left.side(), -1.0);
        assert_eq!(Eye::Right.side(), 1.0);
        assert_eq!(Eye::Left.other(), Eye::Right);
    }
}
