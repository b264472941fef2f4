//! Depth encodings: how a depth map's stored value describes the surface a pixel sees, in one
//! place for every capability, `compare` and the loaders.
//!
//! - [`DepthEncoding`]: view-space Z, view distance along the pixel's ray, device (window)
//!   depth written with near/far planes, or disparity of a rectified pair; f64 encode/decode
//!   against view Z, and the inverse-depth form the GPU passes evaluate.
//! - [`DepthKind`]: the encoding's name without its parameters (what a JSON file or a
//!   `--depth-kind` flag says); cyclopean takes it because its device-depth planes are the
//!   eyes' projection matrices.
//! - [`background`]: the far-plane (background) rule of device depth and its constants, which
//!   the shaders mirror.
//!
//! Conventions (NDC range, reversed-Z) are an argument, not part of the encoding: a frame's
//! conventions also fix its row order, so they travel with the frame and are passed here.
//!
//! **Valid implies finite** (the one rule, for every capability): a stored depth value is
//! usable when it is 0 or its magnitude is in [[`MIN_DEPTH_VALUE`], [`MAX_DEPTH_VALUE`]].
//! Loaders and the Python bindings turn the others into holes ([`clear_unusable_depth`]);
//! every pass's input check refuses them from library callers ([`check_usable_depth`]:
//! `RefocusSource::validate`, `StereoFrame::validate`, `ReprojectSource::validate`,
//! `FaceSet::validate`); and after readback any pixel whose depth is still not finite gets
//! mask 0 and depth 0 ([`crate::view::clear_non_finite`]).

pub mod background;
mod encoding;
#[cfg(test)]
mod tests;

pub use background::{is_background, ndc_z_of_window_depth, window_depth_of_ndc_z, FAR_EPS};
pub use encoding::DepthEncoding;
// The usable magnitudes live with the loaders, which apply them to every file they read (the
// files layer sits below this one); here they stay under the depth vocabulary's names.
pub use crate::io::{check_usable_depth, clear_unusable_depth, usable_depth_value, MAX_DEPTH_VALUE, MIN_DEPTH_VALUE};

use serde::{Deserialize, Serialize};

/// An encoding's name, without its parameters (the vocabulary of JSON files and CLI flags).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DepthKind {
    /// Window depth from a depth buffer, in [0, 1], under the frame's conventions; background
    /// is the far value (1, or 0 with reversed-Z), see [`background`].
    Device,
    /// Linear view-space distance along the viewing direction (OpenCV z, GL -z_eye), metres;
    /// background is 0, negative, NaN or Inf.
    ViewZ,
    /// Euclidean distance from the eye along the pixel's ray, metres; background as view Z.
    ViewDistance,
    /// Disparity in pixels of a rectified pair; <= 0 or not finite is unknown.
    Disparity,
}

impl DepthKind {
    /// The name files and flags use: `device`, `view-z`, `view-distance`, `disparity`.
    pub fn name(self) -> &'static str {
        match self {
            DepthKind::Device => "device",
            DepthKind::ViewZ => "view-z",
            DepthKind::ViewDistance => "view-distance",
            DepthKind::Disparity => "disparity",
        }
    }
}
