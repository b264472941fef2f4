//! Camera models: pinhole intrinsics and the projections built from them.

mod intrinsics;
mod projection;

pub use intrinsics::{Intrinsics, PinholeCamera, MAX_IMAGE_SIDE};
pub use projection::clip_from_view_opencv;
