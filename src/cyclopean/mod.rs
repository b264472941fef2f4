//! cyclopean: the middle (spectator) view of a stereo pair from each eye's colour and depth,
//! without rendering a third camera (seed 000).
//!
//! For each middle pixel the middle ray is walked to the surface each eye saw: start at the
//! fixation depth, project into the eye, read its depth there, reconstruct that surface point,
//! and take its middle-view depth as the next guess. That walk (seed, refine, the eyes' blend)
//! is [`crate::stereo::gather`], below the capabilities, since reproject's 3-D gather runs it
//! too; the frame types, the matcher and densify are in [`crate::stereo`] as well.
//!
//! - [`pass`]: the pass/twin contract, [`pass::gpu`] and [`pass::reference`] over one
//!   [`CyclopeanInput`] (gather or splat), both returning a [`crate::view::ViewOutput`].
//! - [`splat`], [`forward`], [`fill`], [`temporal`]: the splat-gather and forward-warp
//!   methods, the hole fill and the temporal history.

pub mod baseline;
pub mod edge_snap;
pub mod fill;
pub mod forward;
pub mod pass;
pub mod splat;
pub mod splat_reference;
pub mod temporal;

pub use pass::{CyclopeanInput, CyclopeanPass};
