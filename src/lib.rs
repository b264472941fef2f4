//! viewsynth: headless GPU view synthesis from RGB-D and stereo images.
//!
//! Library first: every capability is a typed API here; `src/bin/viewsynth.rs` is a thin CLI.

pub mod error;
pub mod io;

pub use error::{Error, Result};
