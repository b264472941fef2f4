//! [`DepthEncoding`]: what a stored depth value means, with f64 encode/decode against view Z.

use super::background::{is_background, ndc_z_of_window_depth, window_depth_of_ndc_z};
use super::DepthKind;
use crate::convention::{Conventions, DepthPlanes, NdcDepthRange};
use crate::error::{Error, Result};
use crate::io::DepthMap;

/// What a depth map holds, with the parameters needed to turn it into view Z.
///
/// Every decode returns `None` for invalid or background values (the one validity rule): view
/// Z and view distance <= 0 or not finite, device depth by [`is_background`], disparity <= 0 or
/// not finite, and any result that is not a finite Z > 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DepthEncoding {
    /// View-space Z (distance along the optical axis), metres.
    ViewZ,
    /// Distance from the eye along the pixel's ray, metres: Z times the ray's length per unit Z,
    /// `sqrt(1 + x^2 + y^2)` with (x, y) the pixel's normalised image coordinates
    /// ([`DepthEncoding::ray_length`]).
    ViewDistance,
    /// Window depth in [0, 1] from a depth buffer under the frame's conventions, written with
    /// these planes; the far value (1, or 0 with reversed-Z) is background.
    Device {
        /// Near and far planes the depth buffer was written with.
        planes: DepthPlanes,
    },
    /// Disparity in pixels of a rectified pair: Z = baseline * focal / (d + doffs) (Middlebury
    /// 2014). Valid iff finite and d > 0 (Middlebury 2003 stores 0 for unknown).
    Disparity {
        /// Focal length, pixels.
        focal_px: f64,
        /// Distance between the two cameras' centres, in the unit of the decoded Z (metres).
        baseline: f64,
        /// Difference of the two principal points' x, pixels (Middlebury's `doffs`).
        doffs: f64,
    },
}

impl DepthEncoding {
    /// The encoding's name without its parameters.
    pub fn kind(&self) -> DepthKind {
        match self {
            DepthEncoding::ViewZ => DepthKind::ViewZ,
            DepthEncoding::ViewDistance => DepthKind::ViewDistance,
            DepthEncoding::Device { .. } => DepthKind::Device,
            DepthEncoding::Disparity { .. } => DepthKind::Disparity,
        }
    }

    /// The encoding of `kind` where device depth was written with `planes`; disparity needs
    /// its own parameters and is an error.
    pub fn with_planes(kind: DepthKind, planes: DepthPlanes) -> Result<Self> {
        match kind {
            DepthKind::ViewZ => Ok(DepthEncoding::ViewZ),
            DepthKind::ViewDistance => Ok(DepthEncoding::ViewDistance),
            DepthKind::Device => Ok(DepthEncoding::Device { planes }),
            DepthKind::Disparity => Err(Error::param(
                "depth kind",
                "disparity needs focal length, baseline and doffs, not depth planes",
            )),
        }
    }

    /// Length of the ray through normalised image point (x, y) = ((u - cx) / fx, (v - cy) / fy)
    /// per unit view Z: what [`DepthEncoding::ViewDistance`] multiplies Z by.
    pub fn ray_length(x: f64, y: f64) -> f64 {
        (1.0 + x * x + y * y).sqrt()
    }

    /// Checks the parameters: 0 < near < far for device depth; focal and baseline finite and
    /// > 0 and doffs finite for disparity.
    pub fn validate(&self) -> Result<()> {
        match *self {
            DepthEncoding::ViewZ | DepthEncoding::ViewDistance => Ok(()),
            DepthEncoding::Device { planes } => {
                if !(planes.near.is_finite() && planes.near > 0.0 && planes.far > planes.near) {
                    return Err(Error::param(
                        "depth planes",
                        format!("near {} / far {}: need 0 < near < far", planes.near, planes.far),
                    ));
                }
                Ok(())
            }
            DepthEncoding::Disparity {
                focal_px,
                baseline,
                doffs,
            } => {
                if !(focal_px.is_finite() && focal_px > 0.0 && baseline.is_finite() && baseline > 0.0) {
                    return Err(Error::param(
                        "disparity focal/baseline",
                        format!("{focal_px} px, {baseline}: both must be finite and > 0"),
                    ));
                }
                if !doffs.is_finite() {
                    return Err(Error::param("doffs", format!("{doffs} is not finite")));
                }
                Ok(())
            }
        }
    }

    /// An error naming `what` when this encoding is not one of `accepted` (e.g. view distance
    /// where no intrinsics give the pixels' rays).
    pub fn check_accepted(&self, what: &str, accepted: &[DepthKind]) -> Result<()> {
        let kind = self.kind();
        if accepted.contains(&kind) {
            return Ok(());
        }
        let names: Vec<&str> = accepted.iter().map(|k| k.name()).collect();
        Err(Error::param(
            what,
            format!("{} depth is not accepted here: give {}", kind.name(), names.join(", ")),
        ))
    }

    /// (alpha, beta) with q = 1/Z = alpha * stored + beta for the kinds whose inverse depth is
    /// affine in the stored value (device depth: 1/Z is affine in NDC z; disparity:
    /// (d + doffs) / (f B)); None for view Z and view distance.
    pub fn affine_inverse_depth(&self, conv: &Conventions) -> Option<(f64, f64)> {
        match *self {
            DepthEncoding::ViewZ | DepthEncoding::ViewDistance => None,
            DepthEncoding::Device { planes } => {
                // z_ndc = A + B / Z  =>  q = (z_ndc - A) / B, z_ndc = 2 d - 1 or d.
                let (a, b) = planes.clip_z_coefficients(conv);
                Some(match conv.ndc_depth {
                    NdcDepthRange::MinusOneToOne => (2.0 / b, (-1.0 - a) / b),
                    NdcDepthRange::ZeroToOne => (1.0 / b, -a / b),
                })
            }
            DepthEncoding::Disparity {
                focal_px,
                baseline,
                doffs,
            } => {
                let fb = focal_px * baseline;
                Some((1.0 / fb, doffs / fb))
            }
        }
    }

    /// Inverse view Z of a stored value in f64, the way the GPU passes evaluate it (1/stored,
    /// or affine in the stored value); None where invalid. View distance needs the pixel's ray
    /// ([`Self::view_z`]) and gives None here: callers that have no rays refuse it first
    /// ([`Self::check_accepted`]).
    pub fn inverse_depth(&self, conv: &Conventions, stored: f64) -> Option<f64> {
        if !stored.is_finite() {
            return None;
        }
        let q = match self {
            DepthEncoding::ViewZ => 1.0 / stored,
            DepthEncoding::ViewDistance => return None,
            DepthEncoding::Device { .. } => {
                if is_background(stored, conv) {
                    return None;
                }
                let (al, be) = self.affine_inverse_depth(conv)?;
                al * stored + be
            }
            DepthEncoding::Disparity { .. } => {
                if stored <= 0.0 {
                    return None;
                }
                let (al, be) = self.affine_inverse_depth(conv)?;
                al * stored + be
            }
        };
        (q.is_finite() && q > 0.0).then_some(q)
    }

    /// View Z (0 where invalid) of every stored value, as f32 of 1 / [`Self::inverse_depth`].
    /// View distance gives 0 everywhere (no rays here; see [`Self::inverse_depth`]).
    pub fn view_z_map(&self, conv: &Conventions, depth: &DepthMap) -> DepthMap {
        DepthMap {
            width: depth.width,
            height: depth.height,
            data: depth
                .data
                .iter()
                .map(|&d| self.inverse_depth(conv, d as f64).map_or(0.0, |q| (1.0 / q) as f32))
                .collect(),
        }
    }

    /// The summary of `depth` decoded to view Z in metres (see [`Self::view_z_map`]), with the
    /// checks for degenerate device depth when it is device depth.
    pub fn summary(&self, conv: &Conventions, depth: &DepthMap) -> crate::io::DepthSummary {
        let z = self.view_z_map(conv, depth);
        let s = crate::io::DepthSummary::of(&z);
        match *self {
            DepthEncoding::Device { planes } => s.with_device_planes(&z, planes),
            _ => s,
        }
    }

    /// View Z of stored value `stored` seen through a pixel whose ray has length `ray_length`
    /// per unit Z ([`Self::ray_length`]; read by view distance only), in f64; None where
    /// invalid. Device depth is inverted in closed form, Z = B / (z_ndc - A).
    pub fn view_z(&self, conv: &Conventions, stored: f64, ray_length: f64) -> Option<f64> {
        if !stored.is_finite() {
            return None;
        }
        let z = match *self {
            DepthEncoding::ViewZ => {
                if stored <= 0.0 {
                    return None;
                }
                stored
            }
            DepthEncoding::ViewDistance => {
                if stored <= 0.0 {
                    return None;
                }
                stored / ray_length
            }
            DepthEncoding::Device { planes } => {
                if is_background(stored, conv) {
                    return None;
                }
                planes.view_z_of_ndc_z(conv, ndc_z_of_window_depth(stored, conv))
            }
            DepthEncoding::Disparity { .. } => return self.inverse_depth(conv, stored).map(|q| 1.0 / q),
        };
        (z.is_finite() && z > 0.0).then_some(z)
    }

    /// The stored value of a surface at view Z `view_z` (> 0) through a pixel whose ray has
    /// length `ray_length` per unit Z, in f64: the inverse of [`Self::view_z`].
    pub fn encode(&self, conv: &Conventions, view_z: f64, ray_length: f64) -> f64 {
        match *self {
            DepthEncoding::ViewZ => view_z,
            DepthEncoding::ViewDistance => view_z * ray_length,
            DepthEncoding::Device { planes } => window_depth_of_ndc_z(planes.ndc_z_of_view_z(conv, view_z), conv),
            DepthEncoding::Disparity {
                focal_px,
                baseline,
                doffs,
            } => focal_px * baseline / view_z - doffs,
        }
    }
}
