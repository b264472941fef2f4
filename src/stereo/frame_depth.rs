//! What a stereo frame's eye depth maps hold: device depth or view Z, the two kinds whose planes
//! are the eyes' own projections. A type of its own (rather than [`DepthKind`]) so a frame or a
//! camera file can never hold a view distance or a disparity; `DepthKind::from` hands it to the
//! general depth code.

use crate::depth::DepthKind;
use serde::{Deserialize, Serialize};

/// What both eyes' depth maps hold; in files, `"device"` or `"view-z"` (the [`DepthKind`] names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FrameDepth {
    /// Window depth from the eye's depth buffer, in [0, 1], under the frame's conventions; its
    /// near and far planes are the eye's projection's.
    Device,
    /// Linear view-space distance along the eye's viewing direction (GL -z_eye), metres;
    /// background is 0, negative, NaN or Inf.
    ViewZ,
}

impl FrameDepth {
    /// The name files use: `device` or `view-z`.
    pub fn name(self) -> &'static str {
        DepthKind::from(self).name()
    }
}

impl From<FrameDepth> for DepthKind {
    fn from(kind: FrameDepth) -> Self {
        match kind {
            FrameDepth::Device => DepthKind::Device,
            FrameDepth::ViewZ => DepthKind::ViewZ,
        }
    }
}

impl TryFrom<DepthKind> for FrameDepth {
    /// The kind refused, for the caller to name in its error.
    type Error = DepthKind;

    fn try_from(kind: DepthKind) -> Result<Self, DepthKind> {
        match kind {
            DepthKind::Device => Ok(FrameDepth::Device),
            DepthKind::ViewZ => Ok(FrameDepth::ViewZ),
            other @ (DepthKind::ViewDistance | DepthKind::Disparity) => Err(other),
        }
    }
}
