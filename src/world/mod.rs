//! world: the built-in analytic RGB-D scenes as data, ray traced in f64 on the CPU: the demo input and an exact
//! ground truth for any pinhole camera (same pose, other intrinsics).
//!
//! World frame = the demo camera's OpenCV frame (x right, y down, z forward). A textured back
//! wall at z = 6, a floor at y = 1.2, a sphere and a tilted plate in front: depth
//! discontinuities, slanted surfaces and texture at several frequencies. Any posed pinhole
//! camera can look at it ([`render_posed`]), e.g. the eyes of a stereo rig. Below the
//! capabilities: the scene command ([`crate::scene`], its GPU tracer), the stereo frames of
//! the scene and the stitch's faces and truth all read it.

mod shapes;

pub use shapes::{boxes_scene, builtin, demo_scene, Hit, Object, Scene, Shape, EDGE_SLACK, MAX_OBJECTS};

use crate::camera::{PinholeCamera, Pose};
use crate::io::{DepthMap, RgbImage};

/// Procedural texture, smooth enough that resampling error reflects geometry, not aliasing.
pub fn pattern_color(hit: &Hit) -> [f64; 3] {
    let [x, y, z] = hit.p;
    let stripes = |a: f64, f: f64| 0.5 + 0.5 * (a * f).sin();
    match hit.material {
        0 => [
            200.0 * stripes(x, 3.0) + 30.0,
            120.0 * stripes(y, 5.0) + 60.0,
            180.0 * stripes(x + y, 1.7) + 40.0,
        ],
        1 => {
            let checker = (((x * 2.0).floor() + (z * 2.0).floor()) as i64).rem_euclid(2) as f64;
            [
                90.0 + 100.0 * checker * stripes(x, 11.0),
                80.0 + 60.0 * stripes(z, 4.0),
                70.0 + 40.0 * checker,
            ]
        }
        2 => [
            230.0 * stripes(y, 9.0) + 20.0,
            60.0 + 80.0 * stripes(x, 13.0),
            40.0 + 30.0 * stripes(z, 7.0),
        ],
        _ => [
            40.0 + 200.0 * stripes(x - y, 20.0),
            200.0 * stripes(y, 2.0) + 40.0,
            90.0,
        ],
    }
}

/// First surface hit of the demo scene along origin + t dir (t > 0), world coordinates.
pub fn trace(origin: [f64; 3], dir: [f64; 3]) -> Option<Hit> {
    DEMO.with(|s| s.trace(origin, dir))
}

thread_local! {
    static DEMO: Scene = shapes::demo_scene();
}

/// Colour (0..255, unrounded) of a hit.
pub fn hit_color(hit: &Hit) -> [f64; 3] {
    pattern_color(hit)
}

/// Colour (rounded to 8 bits) and view-space Z of the scene seen by `cam` at the identity pose
/// (the demo camera's own frame); 0 depth where no surface is hit.
pub fn render(cam: &PinholeCamera) -> (RgbImage, DepthMap) {
    render_posed(cam, &Pose::IDENTITY)
}

/// Colour (rounded to 8 bits) and view-space Z (OpenCV, distance along the optical axis) of the
/// demo scene seen by `cam` at `pose`; 0 depth where no surface is hit. Rows top-down.
pub fn render_posed(cam: &PinholeCamera, pose: &Pose) -> (RgbImage, DepthMap) {
    DEMO.with(|s| render_scene(s, cam, pose))
}

/// [`render_posed`] for any scene.
pub fn render_scene(scene: &Scene, cam: &PinholeCamera, pose: &Pose) -> (RgbImage, DepthMap) {
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut rgb = vec![0u8; w * h * 3];
    let mut depth = vec![0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            // The ray has unit view-space z, so its parameter t is the view-space Z.
            let dir = pose.ray(cam, x as f64, y as f64);
            if let Some(hit) = scene.trace(pose.position, dir) {
                let o = y * w + x;
                depth[o] = hit.t as f32;
                let c = pattern_color(&hit);
                for k in 0..3 {
                    rgb[o * 3 + k] = c[k].round().clamp(0.0, 255.0) as u8;
                }
            }
        }
    }
    (
        RgbImage::new(cam.width, cam.height, rgb).expect("sizes match by construction"),
        DepthMap::new(cam.width, cam.height, depth).expect("sizes match by construction"),
    )
}

/// The demo camera: VGA-like intrinsics scaled to `width` x `height`.
pub fn demo_camera(width: u32, height: u32) -> PinholeCamera {
    let f = 525.0 * width as f64 / 640.0;
    PinholeCamera {
        k: crate::camera::Intrinsics {
            fx: f,
            fy: f,
            cx: (width as f64 - 1.0) / 2.0,
            cy: (height as f64 - 1.0) / 2.0,
        },
        width,
        height,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_has_background_holes_and_a_depth_range() {
        let cam = demo_camera(160, 120);
        let (_, depth) = render(&cam);
        let valid: Vec<f32> = depth.data.iter().copied().filter(|z| *z > 0.0).collect();
        assert!(valid.len() > depth.data.len() / 2, "mostly covered");
        let lo = valid.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = valid.iter().copied().fold(0.0, f32::max);
        assert!(lo > 1.5 && lo < 3.0 && (hi - 6.0).abs() < 0.5, "{lo}..{hi}");
        // Wall pixel at the image centre row, far left column: z = 6 exactly.
        let (_, wide) = render(&PinholeCamera {
            k: crate::camera::Intrinsics { fx: 40.0, ..cam.k },
            ..cam
        });
        assert_eq!(wide.data[0], 0.0, "a wide view sees past the wall's edge");
    }
}
