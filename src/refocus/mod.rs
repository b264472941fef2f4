//! refocus: one RGB image + metric depth + intrinsics -> RGB, metric depth and validity mask at
//! other focal lengths, same pose. No hole filling: what the source did not see stays invalid.
//!
//! - [`crate::mesh`]: the 2.5D grid mesh and its break rule, shared by every path (re-exported
//!   here: the break rule is a refocus setting).
//! - `render`: the GPU refocus, described once as pass steps and run by the GL or the Vulkan
//!   executor: the full-screen pass, which evaluates the kept triangles analytically per pixel
//!   (same pose only), or the mesh pass (`mesh`: the same triangles rasterised into the MRT
//!   target with a depth test).
//! - [`reference`](mod@reference): the float64 CPU twin both are tested against.
//! - [`pass`]: the pass/twin contract, [`pass::gpu`] and [`pass::reference`] over one
//!   [`RefocusInput`], both returning a [`crate::view::ViewOutput`].
//! - [`manifest`]: targets from focal lists or zoom scales, their file tags and the manifest
//!   (the files go through the output layer, [`crate::output::write_view`]).

pub mod batch;
pub mod manifest;
pub(crate) mod mesh;
pub mod pass;
pub mod reference;
mod render;

pub use crate::mesh::{axis_lookup, frame_span, valid_depth, BreakRule, Grid};
pub use mesh::TRI_TEX_WIDTH;
pub use pass::RefocusInput;
pub use render::{PendingRefocus, RefocusOutput, RefocusParams, Refocuser};

use crate::camera::{Intrinsics, PinholeCamera};
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use serde::{Deserialize, Serialize};

/// A validated refocus input: colour and depth of the same size, and the source intrinsics.
pub struct RefocusSource {
    /// 8-bit colour, rows top-down.
    pub rgb: RgbImage,
    /// View-space Z in metres, pixel-aligned with `rgb`; invalid where not finite and > 0.
    pub depth: DepthMap,
    /// Source intrinsics, pixels (OpenCV: pixel (u, v) centred at (u, v)).
    pub k: Intrinsics,
}

impl RefocusSource {
    /// Checks the source ([`RefocusSource::validate`]).
    pub fn new(rgb: RgbImage, depth: DepthMap, k: Intrinsics) -> Result<Self> {
        let src = RefocusSource { rgb, depth, k };
        src.validate()?;
        Ok(src)
    }

    /// Checks the intrinsics, that colour and depth are the same size, that neither side is 0,
    /// and that every depth value is usable ([`crate::depth::check_usable_depth`]). The fields
    /// are public, so the renderers and the twin check again.
    pub fn validate(&self) -> Result<()> {
        let RefocusSource { rgb, depth, k } = self;
        k.validate("source intrinsics")?;
        if (rgb.width, rgb.height) != (depth.width, depth.height) {
            return Err(Error::SizeMismatch {
                message: format!(
                    "colour is {}x{} but depth is {}x{}; they must be pixel-aligned",
                    rgb.width, rgb.height, depth.width, depth.height
                ),
            });
        }
        // The upper bound is the GPU context's (Refocuser::new checks it).
        if rgb.width == 0 || rgb.height == 0 {
            return Err(Error::param(
                "source size",
                format!("{}x{} has a zero side", rgb.width, rgb.height),
            ));
        }
        crate::depth::check_usable_depth("source depth", &depth.data)
    }

    /// The source camera: intrinsics and image size.
    pub fn camera(&self) -> PinholeCamera {
        PinholeCamera {
            k: self.k,
            width: self.rgb.width,
            height: self.rgb.height,
        }
    }

    /// (min, max) of the valid depths, None when no pixel is valid.
    pub fn depth_range(&self) -> Option<(f64, f64)> {
        self.depth
            .data
            .iter()
            .filter(|z| valid_depth(**z))
            .fold(None, |acc, &z| {
                let z = z as f64;
                Some(acc.map_or((z, z), |(lo, hi): (f64, f64)| (lo.min(z), hi.max(z))))
            })
    }
}

/// Largest source side refocus takes on `device`: the grid has a cell per pixel plus a border
/// ring, and its (w + 1) x (h + 1) cells are texels of one texture.
pub fn max_source_side(device: &crate::pass::Device) -> u32 {
    device.max_image_side().saturating_sub(1)
}

/// Source pixel coordinate seen by target pixel (x, y) under the same pose:
/// u = cx + (x - cx') fx / fx' (and likewise v).
pub fn source_point(src: &Intrinsics, dst: &Intrinsics, x: f64, y: f64) -> [f64; 2] {
    [
        src.cx + (x - dst.cx) * (src.fx / dst.fx),
        src.cy + (y - dst.cy) * (src.fy / dst.fy),
    ]
}

/// How the GPU renders a refocus.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Grid mesh rasterised into an MRT framebuffer with a depth test (any pose).
    Mesh,
    /// One full-screen pass evaluating the same triangles analytically (same pose, faster).
    #[default]
    Fullscreen,
}

impl std::str::FromStr for Method {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "mesh" => Ok(Method::Mesh),
            "fullscreen" | "fast" => Ok(Method::Fullscreen),
            _ => Err(Error::param("method", format!("'{s}': expected mesh or fullscreen"))),
        }
    }
}

pub use crate::output::OutputSet;
