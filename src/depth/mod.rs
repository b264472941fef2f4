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

use serde::{Deserialize, Serialize};

/// Smallest magnitude of a stored depth value (any kind, after `--depth-scale`) that is not a
/// hole: below it the reciprocal overflows f32 near the subnormals (which GPUs flush to zero,
/// so a 1e-40 became 0 on the GPU, 0/0 = NaN, while the f64 twin called it valid), and it is
/// 1 um of view Z, 1e-6 px of disparity, or within [`FAR_EPS`] of a reversed-Z far plane.
pub const MIN_DEPTH_VALUE: f32 = 1e-6;
/// Largest magnitude of a stored depth value that is not a hole: the bound of every
/// real-valued option and file number (`job::MAX_OPTION_MAGNITUDE`, `io::MAX_JSON_MAGNITUDE`);
/// beyond it back-projection times focal lengths, and squared distances, overflow f32.
/// Renderers' sentinels (Blender's 1e10 background) fall here and are holes, like +-Inf.
pub const MAX_DEPTH_VALUE: f32 = 1e6;

/// Whether a stored depth value is within the magnitudes every pass computes finitely; 0 is
/// left to each encoding (a hole for view Z, the near plane for device depth).
#[inline]
pub fn usable_depth_value(v: f32) -> bool {
    v == 0.0 || (v.is_finite() && (MIN_DEPTH_VALUE..=MAX_DEPTH_VALUE).contains(&v.abs()))
}

/// Whether `v` is finite but outside [`usable_depth_value`]: the values the rule turns into
/// holes (NaN and infinities are holes already and are kept as they are).
#[inline]
fn out_of_range(v: f32) -> bool {
    v.is_finite() && !usable_depth_value(v)
}

/// Makes every stored value outside [`usable_depth_value`] a hole (NaN), the one rule that
/// every depth input (files, Python arrays, stress cases) goes through before a pass sees it,
/// so that a pixel the mask calls valid has finite outputs. Returns how many were changed.
pub fn clear_unusable_depth(data: &mut [f32]) -> usize {
    let mut n = 0;
    for v in data.iter_mut().filter(|v| out_of_range(**v)) {
        *v = f32::NAN;
        n += 1;
    }
    n
}

/// Refuses a depth map holding a finite value outside [`usable_depth_value`] (the values
/// [`clear_unusable_depth`] makes holes), naming `what`, how many and the first one.
///
/// This is the input check of every pass (refocus, cyclopean, reproject, stitch): the loaders
/// and the Python bindings apply [`clear_unusable_depth`] first, so only a library caller who
/// builds a [`crate::io::DepthMap`] by hand can meet it, and gets an error instead of NaN where
/// the mask says valid. NaN and +-Inf are holes and pass.
pub fn check_usable_depth(what: &str, data: &[f32]) -> crate::Result<()> {
    let mut bad = data.iter().enumerate().filter(|(_, v)| out_of_range(**v));
    let Some((i, v)) = bad.next() else {
        return Ok(());
    };
    let n = 1 + bad.count();
    Err(crate::Error::param(
        what,
        format!(
            "{n} value(s) outside the usable magnitudes [{MIN_DEPTH_VALUE:e}, {MAX_DEPTH_VALUE:e}] \
             (first {v:e} at index {i}); make them holes first with \
             viewsynth::depth::clear_unusable_depth, as the loaders do"
        ),
    ))
}

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
