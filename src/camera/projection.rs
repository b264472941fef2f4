//! GL clip transforms built from intrinsics, under any [`Conventions`].

use super::mat4::Mat4;
use super::PinholeCamera;
use crate::convention::{Conventions, DepthPlanes, RowOrder};

/// Row-major 4x4 matrix taking an OpenCV view-space point (x right, y down, z forward) to clip
/// space, so that the pixel centre (u, v) of `cam` lands on window coordinate (u + 0.5, .) and
/// image row v is framebuffer row v (top-down) or H - 1 - v (bottom-up).
///
/// x_ndc = 2 (u + 0.5) / W - 1 with u = fx x / z + cx, hence the (2 cx + 1) / W term;
/// y likewise, with the sign set by the row order. w_clip = z.
pub fn clip_from_view_opencv(cam: &PinholeCamera, planes: &DepthPlanes, conv: &Conventions) -> [[f64; 4]; 4] {
    let (w, h) = (cam.width as f64, cam.height as f64);
    let k = &cam.k;
    let sx = 2.0 * k.fx / w;
    let ox = (2.0 * k.cx + 1.0) / w - 1.0;
    let (sy, oy) = match conv.row_order {
        // window y = v + 0.5: y_ndc = 2 (v + 0.5) / H - 1.
        RowOrder::TopDown => (2.0 * k.fy / h, (2.0 * k.cy + 1.0) / h - 1.0),
        // window y = H - (v + 0.5): y_ndc = 1 - 2 (v + 0.5) / H.
        RowOrder::BottomUp => (-2.0 * k.fy / h, 1.0 - (2.0 * k.cy + 1.0) / h),
    };
    let (a, b) = planes.clip_z_coefficients(conv);
    [
        [sx, 0.0, ox, 0.0],
        [0.0, sy, oy, 0.0],
        [0.0, 0.0, a, b],
        [0.0, 0.0, 1.0, 0.0],
    ]
}

/// Centre of projection of a perspective view-projection: the point whose clip x, y and w are
/// all 0 (null vector of those three rows, by cofactors). Not inv(V)'s origin: a stereo
/// projection with a clip-space shift (seed 004) projects from the offset eye.
pub fn projection_centre(vp: &Mat4) -> Option<[f64; 3]> {
    let rows = [vp[0], vp[1], vp[3]];
    let det3 = |c: [usize; 3]| {
        let m = |r: usize, k: usize| rows[r][c[k]];
        m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0))
            + m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0))
    };
    let c = [det3([1, 2, 3]), -det3([0, 2, 3]), det3([0, 1, 3]), -det3([0, 1, 2])];
    (c[3].abs() > 1e-300 && c.iter().all(|v| v.is_finite())).then(|| [c[0] / c[3], c[1] / c[3], c[2] / c[3]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Intrinsics;

    fn window_xy(m: &[[f64; 4]; 4], cam: &PinholeCamera, p: [f64; 3]) -> [f64; 2] {
        let c: Vec<f64> = m
            .iter()
            .map(|r| r[0] * p[0] + r[1] * p[1] + r[2] * p[2] + r[3])
            .collect();
        let (xn, yn) = (c[0] / c[3], c[1] / c[3]);
        [
            (xn + 1.0) * 0.5 * cam.width as f64,
            (yn + 1.0) * 0.5 * cam.height as f64,
        ]
    }

    #[test]
    fn point_at_u_10_7_lands_in_column_11_under_both_row_orders() {
        let cam = PinholeCamera {
            k: Intrinsics {
                fx: 300.0,
                fy: 310.0,
                cx: 31.5,
                cy: 20.25,
            },
            width: 64,
            height: 48,
        };
        let planes = DepthPlanes { near: 0.1, far: 100.0 };
        let p = cam.k.back_project(10.7, 5.2, 2.0);
        for conv in Conventions::all() {
            let m = clip_from_view_opencv(&cam, &planes, &conv);
            let [xw, yw] = window_xy(&m, &cam, p);
            assert!((xw - 11.2).abs() < 1e-9, "{conv:?}");
            assert_eq!(xw.floor() as i64, 11);
            let row = yw.floor() as i64;
            let expect = match conv.row_order {
                RowOrder::TopDown => 5,
                RowOrder::BottomUp => 48 - 1 - 5,
            };
            assert_eq!(row, expect, "{conv:?} yw={yw}");
        }
    }
}
