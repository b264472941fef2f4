//! Float64 CPU twin of the GPU refocus passes: same grid, same break rule, same triangulation,
//! exact ray/triangle depth and exact bilinear colour. The tests hold both GPU paths to it.

use super::{source_point, RefocusSource};
use crate::camera::PinholeCamera;
use crate::mesh::{frame_span, Grid, TRI1, TRI2};
use crate::refocus::BreakRule;

/// Unquantised reference result, rows top-down.
pub struct ReferenceImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// RGB in 0..=255, not rounded.
    pub rgb: Vec<[f64; 3]>,
    /// View-space Z in metres; 0 where not covered.
    pub depth: Vec<f64>,
    /// Per pixel, whether a kept triangle covers the pixel centre.
    pub mask: Vec<bool>,
}

/// Where a source-image point meets the kept mesh: the nearest view-space Z over every kept
/// triangle whose closed area contains (u, v), or None.
pub fn surface_depth(grid: &Grid, depth: &[f32], keep: &[u8], u: f64, v: f64) -> Option<f64> {
    let (w, h) = (grid.width, grid.height);
    if !(u >= -0.5 && u <= w as f64 - 0.5 && v >= -0.5 && v <= h as f64 - 0.5) {
        return None;
    }
    let candidates = |x: f64, n: u32| -> ([i64; 2], usize) {
        let i0 = ((x.floor() as i64) + 1).clamp(0, n as i64);
        if i0 > 0 && x == Grid::vertex_pos(i0, n) {
            ([i0, i0 - 1], 2)
        } else {
            ([i0, i0], 1)
        }
    };
    let (ci, ni) = candidates(u, w);
    let (cj, nj) = candidates(v, h);
    let mut best: Option<f64> = None;
    for &j in &cj[..nj] {
        for &i in &ci[..ni] {
            let bits = keep[j as usize * grid.cells_x() + i as usize];
            if bits == 0 {
                continue;
            }
            let (x0, x1) = (Grid::vertex_pos(i, w), Grid::vertex_pos(i + 1, w));
            let (y0, y1) = (Grid::vertex_pos(j, h), Grid::vertex_pos(j + 1, h));
            let a = (u - x0) / (x1 - x0);
            let b = (v - y0) / (y1 - y0);
            let z = |di: i64, dj: i64| grid.vertex_depth(depth, i + di, j + dj) as f64;
            // 1/Z is affine over the source image for a planar triangle seen from the source centre.
            let mut consider = |inv: f64| {
                let zz = 1.0 / inv;
                best = Some(best.map_or(zz, |bz: f64| bz.min(zz)));
            };
            if bits & TRI1 != 0 && a >= b {
                consider((1.0 - a) / z(0, 0) + (a - b) / z(1, 0) + b / z(1, 1));
            }
            if bits & TRI2 != 0 && a <= b {
                consider((1.0 - b) / z(0, 0) + a / z(1, 1) + (b - a) / z(0, 1));
            }
        }
    }
    best
}

/// Bilinear RGB at continuous source coordinate (u, v), edge texels clamped.
pub fn bilinear_rgb(src: &RefocusSource, u: f64, v: f64) -> [f64; 3] {
    let (w, h) = (src.rgb.width as i64, src.rgb.height as i64);
    let (x0, y0) = (u.floor(), v.floor());
    let (fx, fy) = (u - x0, v - y0);
    let texel = |x: i64, y: i64| {
        let (x, y) = (x.clamp(0, w - 1) as usize, y.clamp(0, h - 1) as usize);
        let o = (y * w as usize + x) * 3;
        [
            src.rgb.data[o] as f64,
            src.rgb.data[o + 1] as f64,
            src.rgb.data[o + 2] as f64,
        ]
    };
    let (x0, y0) = (x0 as i64, y0 as i64);
    let (c00, c10, c01, c11) = (
        texel(x0, y0),
        texel(x0 + 1, y0),
        texel(x0, y0 + 1),
        texel(x0 + 1, y0 + 1),
    );
    let mut out = [0.0; 3];
    for c in 0..3 {
        let top = c00[c] + (c10[c] - c00[c]) * fx;
        let bottom = c01[c] + (c11[c] - c01[c]) * fx;
        out[c] = top + (bottom - top) * fy;
    }
    out
}

/// Reference refocus of `src` into `target` (same pose).
pub fn refocus_reference(src: &RefocusSource, rule: &BreakRule, target: &PinholeCamera) -> ReferenceImage {
    refocus_reference_with(src, rule, target, false)
}

/// [`refocus_reference`], and with `rgb_everywhere` the colour of every pixel whose source point
/// lies inside the source frame ([`frame_span`] on both axes, as the passes' lookups decide),
/// covered or not; depth and mask are the same either way.
pub fn refocus_reference_with(
    src: &RefocusSource,
    rule: &BreakRule,
    target: &PinholeCamera,
    rgb_everywhere: bool,
) -> ReferenceImage {
    let (span_u, span_v) = (frame_span(src.rgb.width), frame_span(src.rgb.height));
    let grid = Grid {
        width: src.depth.width,
        height: src.depth.height,
    };
    let keep = grid.keep_mask(&src.depth.data, rule);
    let n = target.width as usize * target.height as usize;
    let mut out = ReferenceImage {
        width: target.width,
        height: target.height,
        rgb: vec![[0.0; 3]; n],
        depth: vec![0.0; n],
        mask: vec![false; n],
    };
    for y in 0..target.height {
        for x in 0..target.width {
            let [u, v] = source_point(&src.k, &target.k, x as f64, y as f64);
            let o = y as usize * target.width as usize + x as usize;
            if let Some(z) = surface_depth(&grid, &src.depth.data, &keep, u, v) {
                out.depth[o] = z;
                out.mask[o] = true;
                out.rgb[o] = bilinear_rgb(src, u, v);
            } else if rgb_everywhere && (span_u.0..=span_u.1).contains(&u) && (span_v.0..=span_v.1).contains(&v) {
                out.rgb[o] = bilinear_rgb(src, u, v);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;
    use crate::io::{DepthMap, RgbImage};

    fn source(w: u32, h: u32, depth: impl Fn(u32, u32) -> f32) -> RefocusSource {
        let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i * 37 % 251) as u8).collect();
        let d: Vec<f32> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| depth(x, y))
            .collect();
        RefocusSource::new(
            RgbImage::new(w, h, rgb).unwrap(),
            DepthMap::new(w, h, d).unwrap(),
            Intrinsics {
                fx: 100.0,
                fy: 90.0,
                cx: (w as f64 - 1.0) / 2.0,
                cy: (h as f64 - 1.0) / 2.0,
            },
        )
        .unwrap()
    }

    #[test]
    fn scale_one_reproduces_every_pixel_of_a_plane() {
        let src = source(7, 5, |x, y| 1.0 + 0.01 * x as f32 + 0.02 * y as f32);
        let cam = PinholeCamera {
            k: src.k,
            width: 7,
            height: 5,
        };
        let r = refocus_reference(&src, &BreakRule::default(), &cam);
        for i in 0..35 {
            assert!(r.mask[i]);
            assert_eq!(r.depth[i], src.depth.data[i] as f64);
            for c in 0..3 {
                assert_eq!(r.rgb[i][c], src.rgb.data[i * 3 + c] as f64);
            }
        }
    }

    #[test]
    fn depth_of_a_slanted_plane_is_exact_between_vertices() {
        // Plane Z = 2 + 0.1 X: back-projected vertices lie on it, so every interior point does too.
        let k = Intrinsics {
            fx: 100.0,
            fy: 90.0,
            cx: 3.0,
            cy: 2.0,
        };
        let plane = |u: f64| 2.0 / (1.0 - 0.1 * (u - k.cx) / k.fx); // Z solving Z = 2 + 0.1 (u-cx) Z / fx
        let src = source(7, 5, |x, _| plane(x as f64) as f32);
        let grid = Grid { width: 7, height: 5 };
        let keep = grid.keep_mask(&src.depth.data, &BreakRule::default());
        for &(u, v) in &[(1.3, 2.7), (4.5, 0.5), (5.99, 3.01)] {
            let z = surface_depth(&grid, &src.depth.data, &keep, u, v).unwrap();
            // Vertex depths are f32-rounded: relative error up to 2^-24 each.
            assert!((z - plane(u)).abs() / plane(u) < 1e-7, "u={u}: {z} vs {}", plane(u));
        }
    }

    #[test]
    fn wide_angle_leaves_the_uncovered_border_empty_and_keeps_discontinuities_open() {
        let src = source(8, 8, |x, _| if x < 4 { 1.0 } else { 3.0 });
        let mut cam = PinholeCamera {
            k: src.k,
            width: 8,
            height: 8,
        };
        cam.k.fx *= 0.5;
        cam.k.fy *= 0.5;
        let r = refocus_reference(&src, &BreakRule::default(), &cam);
        // Target column 0 maps to source u = 3.5 - 3.5 * 2 = -3.5: outside.
        assert!(!r.mask[0]);
        // Row 4, target column 3.5 +- 0.25 straddles the depth step between source columns 3
        // and 4: the cells there are broken, so the step is not bridged.
        let covered: Vec<bool> = (0..8).map(|x| r.mask[4 * 8 + x]).collect();
        assert_eq!(covered, vec![false, false, true, true, true, true, false, false]);
        assert_eq!(r.depth[4 * 8 + 3], 1.0);
        assert_eq!(r.depth[4 * 8 + 4], 3.0);
    }
}
