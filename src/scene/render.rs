//! The scene ray-traced on the GPU (shaders/scene/raytrace.frag) for any GL camera (view V,
//! projection P, conventions); its f64 twin with the same ray construction is
//! [`super::reference`]. Both give colour, view distance and window depth, rows top-down.

use crate::camera::mat4::{self, Mat4};
use crate::camera::projection_centre;
pub use crate::camera::rays::{pixel_ndc, ray_basis};
use crate::convention::{Conventions, RowOrder};
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use crate::pass::{mat4_std140, Device, Draw, Format, Target, ToDevice};
use crate::pass::{ProgramKind, ShaderProgram, Timing};
use crate::world::{Scene, Shape, MAX_OBJECTS};

crate::param_block! {
    /// The ray tracer's parameters: shaders/scene/scene_params.glsl, member for member.
    pub struct RaytraceParams("RaytraceParams") {
        u_ray_basis: [[f32; 4]; 4],
        u_view_proj: [[f32; 4]; 4],
        u_view: [[f32; 4]; 4],
        u_eye: [f32; 3],
        u_ods_radius: f32,
        u_ods_centre: [f32; 3],
        u_ods_fade_start: f32,
        u_size: [f32; 2],
        u_count: i32,
        u_ods: i32,
        u_kind: [[i32; 4]; MAX_OBJECTS],
        u_a: [[f32; 4]; MAX_OBJECTS],
        u_b: [[f32; 4]; MAX_OBJECTS],
        u_c: [[f32; 4]; MAX_OBJECTS],
        u_d: [[f32; 4]; MAX_OBJECTS],
    }
}

/// A GL camera: world -> eye `view`, eye -> clip `proj` (matching `conv`), image size.
#[derive(Debug, Clone, Copy)]
pub struct GlCamera {
    /// World -> eye transform (eye looks down -Z, GL convention), row-major.
    pub view: Mat4,
    /// Eye -> clip projection under `conv`, row-major.
    pub proj: Mat4,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// NDC depth range, reversed-Z and row order of `proj` and of the depth written.
    pub conv: Conventions,
}

/// A rendered view: colour, view distance (0 = miss) and window depth (far value = miss).
#[derive(Debug, Clone)]
pub struct SceneImage {
    /// Colour, 8-bit RGB.
    pub color: RgbImage,
    /// View Z in metres (along the ray for ODS views); 0 where the ray misses.
    pub view_z: DepthMap,
    /// Window depth under the camera's conventions; the far value where the ray misses.
    pub device_depth: DepthMap,
}

impl GlCamera {
    pub(super) fn matrices(&self) -> Result<(Mat4, Mat4, [f64; 3])> {
        let vp = mat4::mul(&self.proj, &self.view);
        mat4::inverse(&vp).ok_or_else(|| Error::param("camera view-projection", "singular"))?;
        let basis = ray_basis(&vp).ok_or_else(|| Error::param("camera projection", "not perspective"))?;
        let eye = projection_centre(&vp).ok_or_else(|| Error::param("camera projection", "not perspective"))?;
        Ok((vp, basis, eye))
    }

    /// Image row of framebuffer row `y`.
    pub(super) fn image_row(&self, y: u32) -> u32 {
        match self.conv.row_order {
            RowOrder::BottomUp => self.height - 1 - y,
            RowOrder::TopDown => y,
        }
    }
}

enum Camera<'a> {
    Gl(&'a GlCamera),
    Ods {
        centre: [f64; 3],
        radius: f64,
        fade_start: f64,
        width: u32,
        height: u32,
    },
}

/// A scene as a parameter block, ready to render any GL camera (GL or Vulkan).
pub struct SceneRenderer {
    device: Device,
    scene: Scene,
}

impl SceneRenderer {
    /// Checks `scene` for rendering on `device` (the program is built on first use).
    pub fn new(device: impl ToDevice, scene: &Scene) -> Result<Self> {
        scene.validate()?;
        Ok(SceneRenderer {
            device: device.to_device()?,
            scene: scene.clone(),
        })
    }

    /// Ray-traces `cam`'s view (rows top-down), with its times.
    pub fn render(&mut self, cam: &GlCamera) -> Result<(SceneImage, Timing)> {
        self.render_with(Camera::Gl(cam))
    }

    /// An omni-directional stereo equirectangular view (rows top-down): colour and distance
    /// along each pixel's ray (`view_z`), `device_depth` all 0. `radius` is the signed eye offset
    /// (-ipd/2 left, +ipd/2 right), faded to 0 from latitude `fade_start` (radians) to the poles.
    pub fn render_ods(
        &mut self,
        centre: [f64; 3],
        radius: f64,
        fade_start: f64,
        width: u32,
        height: u32,
    ) -> Result<(SceneImage, Timing)> {
        if !(centre.iter().all(|c| c.is_finite())
            && radius.is_finite()
            && (0.0..std::f64::consts::FRAC_PI_2).contains(&fade_start))
        {
            return Err(Error::param(
                "ods camera",
                format!("centre {centre:?}, radius {radius}, fade start {fade_start}"),
            ));
        }
        self.render_with(Camera::Ods {
            centre,
            radius,
            fade_start,
            width,
            height,
        })
    }

    fn render_with(&mut self, camera: Camera) -> Result<(SceneImage, Timing)> {
        let gl_default;
        let (cam, ods) = match camera {
            Camera::Gl(c) => (c, None),
            Camera::Ods {
                centre,
                radius,
                fade_start,
                width,
                height,
            } => {
                let conv = Conventions {
                    row_order: RowOrder::TopDown,
                    ..Conventions::default()
                };
                gl_default = GlCamera {
                    view: mat4::IDENTITY,
                    proj: [
                        [1.0, 0.0, 0.0, 0.0],
                        [0.0, 1.0, 0.0, 0.0],
                        [0.0, 0.0, -1.0, -0.1],
                        [0.0, 0.0, -1.0, 0.0],
                    ],
                    width,
                    height,
                    conv,
                };
                (&gl_default, Some((centre, radius, fade_start)))
            }
        };
        let (vp, basis, eye) = cam.matrices()?;
        let (w, h) = (cam.width, cam.height);
        self.device.check_image_size("camera size", w, h)?;
        let mut block: RaytraceParams = bytemuck::Zeroable::zeroed();
        block.u_count = self.scene.objects.len() as i32;
        for (i, o) in self.scene.objects.iter().enumerate() {
            let v4 = |v: [f64; 3], w: f64| [v[0] as f32, v[1] as f32, v[2] as f32, w as f32];
            let (kind, a, b, c, d) = match o.shape {
                Shape::Plane {
                    point,
                    normal,
                    bounds_min,
                    bounds_max,
                } => (
                    0,
                    v4(point, 0.0),
                    v4(normal, 0.0),
                    v4(bounds_min, 0.0),
                    v4(bounds_max, 0.0),
                ),
                Shape::Sphere { center, radius } => (1, v4(center, radius), [0.0; 4], [0.0; 4], [0.0; 4]),
                Shape::Cuboid { min, max } => (2, v4(min, 0.0), v4(max, 0.0), [0.0; 4], [0.0; 4]),
            };
            block.u_kind[i] = [kind, o.pattern as i32, 0, 0];
            (block.u_a[i], block.u_b[i], block.u_c[i], block.u_d[i]) = (a, b, c, d);
        }
        block.u_ray_basis = mat4_std140(&basis);
        block.u_view_proj = mat4_std140(&vp);
        block.u_view = mat4_std140(&cam.view);
        block.u_eye = eye.map(|v| v as f32);
        block.u_size = [w as f32, h as f32];
        block.u_ods = ods.is_some() as i32;
        if let Some((centre, radius, fade)) = ods {
            block.u_ods_centre = centre.map(|v| v as f32);
            block.u_ods_radius = radius as f32;
            block.u_ods_fade_start = fade as f32;
        }
        let target = Target {
            width: w,
            height: h,
            outputs: vec![Some(Format::Rgba8), Some(Format::R32F), Some(Format::R32F)],
            rows: cam.conv.row_order,
            depth_test: None,
        };
        let program = ShaderProgram::new(cam.conv, ProgramKind::SceneRaytrace);
        let draw = Draw::fullscreen(program, bytemuck::bytes_of(&block), &[], w, h);
        let mut out = self.device.render(&target, &[draw])?;
        let color = out.take(0, "scene ray trace")?;
        let view_z = out.take_floats(1, "scene ray trace")?;
        let device = out.take_floats(2, "scene ray trace")?;
        Ok((
            SceneImage {
                color: RgbImage::new(w, h, color)?,
                view_z: DepthMap::new(w, h, view_z)?,
                device_depth: DepthMap::new(w, h, device)?,
            },
            out.timing,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{gl_projection, Pose};
    use crate::convention::DepthPlanes;

    #[test]
    fn projection_centre_of_a_posed_pinhole_is_its_position() {
        let cam = crate::world::demo_camera(64, 48);
        let pose = Pose::yawed(0.4, [0.3, -0.2, 1.5]);
        let planes = DepthPlanes {
            near: 0.1,
            far: f64::INFINITY,
        };
        for conv in Conventions::all() {
            let vp = mat4::mul(&gl_projection(&cam, &planes, &conv), &pose.gl_view());
            let c = projection_centre(&vp).unwrap();
            for k in 0..3 {
                assert!((c[k] - pose.position[k]).abs() < 1e-12, "{conv:?} {c:?}");
            }
        }
    }
}
