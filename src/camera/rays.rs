//! Pixel rays that do not depend on the conventions: a pixel's ray comes from the inverse of the
//! projection's clip x, y and w rows ([`ray_basis`]) at its exactly mirrored NDC ([`pixel_ndc`]),
//! so NDC depth range, reversed-Z and row order all trace the same rays. Used by the scene's ray
//! tracer and the cyclopean passes, on the GPU (shaders/common/camera.glsl) and in their twins.

use super::mat4::{self, Mat4};

/// The ray basis of a perspective view-projection `vp`: the inverse of the 3x3 that takes a
/// direction to its clip (x, y, w), so a pixel's ray is `basis (ndc_x, ndc_y, 1)`, in the upper
/// left 3x3 of a 4x4 (the rest identity). The depth conventions change only clip z and the row
/// order only the sign of clip y (the pixel's NDC y flips with it, exactly), so every convention
/// gives the same rays bit for bit. The ray through an unprojected NDC point (inv(vp) at some
/// NDC z, minus the eye) rounds differently under each convention: at 320 x 240 the demo's
/// floor-wall edge row cracked under Vulkan NDC and reversed-Z only (issue 47).
pub fn ray_basis(vp: &Mat4) -> Option<Mat4> {
    let mut m = mat4::IDENTITY;
    for (r, src) in [0, 1, 3].into_iter().enumerate() {
        m[r][..3].copy_from_slice(&vp[src][..3]);
    }
    mat4::inverse(&m)
}

/// NDC of pixel centre `p` (counted from 0) along an axis of `n` pixels, as `(2 p + 1 - n) / n`:
/// the numerator is exact, so the mirrored pixel `n - 1 - p` gets exactly the negated value
/// (`(p + 0.5) / n * 2 - 1` does not), and both row orders give the same ray.
pub fn pixel_ndc(p: f64, n: f64) -> f64 {
    (2.0 * p + 1.0 - n) / n
}

/// The direction `basis (ndc_x, ndc_y, 1)` (the upper-left 3x3 of `basis`): for the basis of a
/// projection, the view-space ray through NDC (x, y) scaled to GL z = -1 (clip w = 1).
pub fn view_ray(basis: &Mat4, ndc: [f64; 2]) -> [f64; 3] {
    [0, 1, 2].map(|r| basis[r][0] * ndc[0] + basis[r][1] * ndc[1] + basis[r][2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convention::{Conventions, DepthPlanes};

    #[test]
    fn every_convention_gives_the_same_rays_bit_for_bit() {
        let planes = DepthPlanes { near: 0.05, far: 100.0 };
        let base = Conventions::default();
        let ray = |conv: &Conventions, y: f64, n: f64| {
            let cam = crate::camera::PinholeCamera {
                k: crate::camera::Intrinsics {
                    fx: 500.0,
                    fy: 480.0,
                    cx: 319.5,
                    cy: 239.5,
                },
                width: 640,
                height: 480,
            };
            let p = crate::camera::gl_projection(&cam, &planes, conv);
            let b = ray_basis(&p).unwrap();
            // Bottom-up rows negate clip y; the mirrored pixel's NDC is exactly negated too.
            let y = if conv.row_order == base.row_order {
                y
            } else {
                n - 1.0 - y
            };
            view_ray(&b, [pixel_ndc(17.0, 640.0), pixel_ndc(y, n)])
        };
        let want = ray(&base, 123.0, 480.0);
        assert_eq!(want[2], -1.0);
        for conv in Conventions::all() {
            assert_eq!(ray(&conv, 123.0, 480.0), want, "{}", conv.label());
        }
    }
}
