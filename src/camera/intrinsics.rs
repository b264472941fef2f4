//! Pinhole intrinsics in the OpenCV convention: pixel (u, v) has its centre at continuous
//! coordinate (u, v); v grows downwards; view space is x right, y down, z forward.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Largest magnitude of an intrinsic (pixels): the bound of every real-valued option
/// (`job::MAX_OPTION_MAGNITUDE`), so an intrinsics file is held to what the flags accept.
pub const MAX_INTRINSIC: f64 = 1e6;
/// Smallest focal length (pixels): below it the field of view is within a hair of 180 degrees
/// and back-projection divides by a number whose reciprocal leaves f32's precision (5e-324
/// made every ray infinite).
pub const MIN_FOCAL_PX: f64 = 1e-3;

/// Pinhole intrinsics in pixels, OpenCV convention: pixel (u, v) has its centre at (u, v), v grows
/// downwards, and a view-space point (x, y, z) lands at (fx x / z + cx, fy y / z + cy).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Intrinsics {
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels (rows downwards).
    pub cy: f64,
}

impl Intrinsics {
    /// Finite values, focal lengths in [[`MIN_FOCAL_PX`], [`MAX_INTRINSIC`]] and principal point
    /// magnitudes at most [`MAX_INTRINSIC`]; `what` names the camera in the error.
    pub fn validate(&self, what: &str) -> Result<()> {
        for (name, v) in [("fx", self.fx), ("fy", self.fy), ("cx", self.cx), ("cy", self.cy)] {
            if !v.is_finite() {
                return Err(Error::param(format!("{what} {name}"), format!("{v} is not finite")));
            }
        }
        for (name, v) in [("fx", self.fx), ("fy", self.fy)] {
            if !(MIN_FOCAL_PX..=MAX_INTRINSIC).contains(&v) {
                return Err(Error::param(
                    format!("{what} {name}"),
                    format!("{v:e} must be in [{MIN_FOCAL_PX:e}, {MAX_INTRINSIC:e}] px"),
                ));
            }
        }
        for (name, v) in [("cx", self.cx), ("cy", self.cy)] {
            if v.abs() > MAX_INTRINSIC {
                return Err(Error::param(
                    format!("{what} {name}"),
                    format!("{v:e}: magnitude must be <= {MAX_INTRINSIC:e} px"),
                ));
            }
        }
        Ok(())
    }

    /// Pixel coordinates of a view-space point (z > 0 in front of the camera).
    pub fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [self.fx * p[0] / p[2] + self.cx, self.fy * p[1] / p[2] + self.cy]
    }

    /// View-space point at pixel (u, v) with view-space Z = z.
    pub fn back_project(&self, u: f64, v: f64, z: f64) -> [f64; 3] {
        [(u - self.cx) * z / self.fx, (v - self.cy) * z / self.fy, z]
    }
}

/// Intrinsics plus image size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PinholeCamera {
    /// The intrinsics.
    #[serde(flatten)]
    pub k: Intrinsics,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

impl PinholeCamera {
    /// Finite intrinsics and non-zero sides. The largest side is the GPU context's
    /// (`Gpu::check_image_size`), checked where the camera is rendered.
    pub fn validate(&self, what: &str) -> Result<()> {
        self.k.validate(what)?;
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if v == 0 {
                return Err(Error::param(format!("{what} {name}"), "0: must be at least 1"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_parameter() {
        let k = Intrinsics {
            fx: 500.0,
            fy: f64::NAN,
            cx: 1.0,
            cy: 1.0,
        };
        let e = k.validate("source").unwrap_err().to_string();
        assert!(e.contains("source fy"), "{e}");
        let k = Intrinsics {
            fx: 0.0,
            fy: 1.0,
            cx: 1.0,
            cy: 1.0,
        };
        assert!(k.validate("target").unwrap_err().to_string().contains("target fx"));
        let cam = PinholeCamera {
            k: Intrinsics {
                fx: 1.0,
                fy: 1.0,
                cx: 0.0,
                cy: 0.0,
            },
            width: 0,
            height: 2,
        };
        assert!(cam.validate("output").unwrap_err().to_string().contains("output width"));
    }

    #[test]
    fn back_projection_inverts_projection() {
        let k = Intrinsics {
            fx: 525.0,
            fy: 520.0,
            cx: 319.5,
            cy: 239.5,
        };
        let p = k.back_project(10.7, 400.25, 3.5);
        let uv = k.project(p);
        assert!((uv[0] - 10.7).abs() < 1e-12 && (uv[1] - 400.25).abs() < 1e-12);
    }
}
