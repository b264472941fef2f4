//! mesh: the 2.5D grid mesh of a depth map and its break rule ([`grid`]), and its triangles as
//! texel rows ([`codes`]): below the capabilities, since refocus renders it and cyclopean's
//! forward warp splats each eye through it.

mod codes;
mod grid;

pub use codes::code_rows;
pub use grid::{axis_lookup, frame_span, valid_depth, BreakRule, Grid};
pub(crate) use grid::{TRI1, TRI2};
