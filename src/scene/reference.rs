//! The f64 twin of the GPU ray tracer ([`super::render`], shaders/scene/raytrace.frag): the same
//! rays from the same camera matrices, traced through the scene in f64.

use super::render::{GlCamera, SceneImage};
use crate::camera::mat4;
use crate::camera::rays::pixel_ndc;
use crate::convention::DepthPlanes;
use crate::error::Result;
use crate::io::{DepthMap, RgbImage};
use crate::world::{pattern_color, Scene};

/// f64 twin of the shader: same rays, same rounding of colour to 8 bits.
pub fn trace_gl_reference(scene: &Scene, cam: &GlCamera) -> Result<SceneImage> {
    let (vp, basis, eye) = cam.matrices()?;
    let (w, h) = (cam.width as usize, cam.height as usize);
    let mut color = vec![0u8; w * h * 3];
    let mut view_z = vec![0f32; w * h];
    let far = cam.conv.clear_depth() as f32;
    let mut device = vec![far; w * h];
    for y in 0..cam.height {
        for x in 0..cam.width {
            let ndc = [pixel_ndc(x as f64, w as f64), pixel_ndc(y as f64, h as f64), 1.0, 0.0];
            let d = mat4::transform(&basis, ndc);
            let dir = [d[0], d[1], d[2]];
            let Some(hit) = scene.trace(eye, dir) else { continue };
            let o = cam.image_row(y) as usize * w + x as usize;
            let c = pattern_color(&hit);
            for k in 0..3 {
                color[o * 3 + k] = c[k].round().clamp(0.0, 255.0) as u8;
            }
            view_z[o] = -mat4::transform_point(&cam.view, hit.p)[2] as f32;
            let z = mat4::transform_point(&vp, hit.p)[2];
            device[o] = DepthPlanes::window_depth_of_ndc_z(&cam.conv, z) as f32;
        }
    }
    Ok(SceneImage {
        color: RgbImage::new(cam.width, cam.height, color)?,
        view_z: DepthMap::new(cam.width, cam.height, view_z)?,
        device_depth: DepthMap::new(cam.width, cam.height, device)?,
    })
}
