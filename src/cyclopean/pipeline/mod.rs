//! The cyclopean pipeline both front ends run (the job's files, Python's arrays): from decoded
//! inputs to the view, downwards only. [`CyclopeanPlan::frame`] places the eyes (two images
//! alone: the range search and the stereo matcher, [`estimate`]; with the fill, densified
//! disparities), [`CyclopeanPlan::synthesise`] renders by the plan's method and takes the holes
//! from the dense frame, the history and the fill, and makes the mask. A sequence keeps its
//! renderers between frames ([`Reused`]).

mod estimate;
mod plan;
mod reuse;
mod synthesise;

pub use estimate::{default_max_disparity, INFERRED_CONFIDENCE};
pub(crate) use plan::GatherSettings;
pub use plan::{CyclopeanPlan, Framed, InputName, StereoInput, StereoKind};
pub use reuse::Reused;
pub use synthesise::Synthesised;
