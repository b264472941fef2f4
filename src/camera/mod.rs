//! Camera models: pinhole intrinsics and the projections built from them.

mod intrinsics;
pub mod intrinsics_file;
pub mod mat4;
pub mod pose;
mod projection;
pub mod rays;
pub mod stereo;
pub mod vergence;

pub use intrinsics::{Intrinsics, PinholeCamera, MAX_INTRINSIC, MIN_FOCAL_PX};
pub use intrinsics_file::{IntrinsicsFile, IntrinsicsFormat};
pub use pose::{gl_projection, Pose};
pub use projection::{clip_from_view_opencv, projection_centre};
