//! cyclopean: the middle (spectator) view of a stereo pair from each eye's colour and depth,
//! without rendering a third camera (seed 000).
//!
//! For each middle pixel the middle ray is walked to the surface each eye saw: start at the
//! fixation depth, project into the eye, read its depth there, reconstruct that surface point,
//! and take its middle-view depth as the next guess. That walk (seed, refine, the eyes' blend)
//! is [`crate::stereo::gather`], below the capabilities, since reproject's 3-D gather runs it
//! too; the frame types, the matcher and densify are in [`crate::stereo`] as well.
//!
//! - [`pipeline`]: one view from decoded inputs, the pipeline both front ends run: the range
//!   search, the matcher and densify for disparities, the render by the chosen method, the
//!   holes from the dense frame, the history, the fill and the mask.
//! - [`pass`]: the pass/twin contract, [`pass::gpu`] and [`pass::reference`] over one
//!   [`CyclopeanInput`] (gather or splat), both returning a [`crate::view::ViewOutput`].
//! - [`splat`], [`forward`], [`fill`], [`temporal`]: the splat-gather and forward-warp
//!   methods, the hole fill and the temporal history.

pub mod baseline;
pub mod edge_snap;
pub mod fill;
pub mod fill_reference;
pub mod forward;
mod method;
pub mod pass;
pub mod pipeline;
pub mod splat;
pub mod splat_reference;
pub mod temporal;
pub mod temporal_reference;

pub use method::CyclopeanMethod;
pub use pass::{CyclopeanInput, CyclopeanPass};
