//! viewsynth: headless GPU view synthesis from RGB-D and stereo images.
//!
//! The library renders new views of a captured or synthetic scene on OpenGL 4.5 core through
//! EGL (NVIDIA's EGL device platform, or Mesa llvmpipe without a GPU): the same view at other
//! focal lengths ([`refocus`]), the middle view of a stereo pair ([`cyclopean`]), one eye from
//! another ([`reproject`]) and an omni-directional stereo panorama from cube faces
//! ([`stitch`]). Every GPU pass has a float64 CPU twin beside it, and the tests hold the two to
//! tolerances derived from the numerics. The `viewsynth` binary is a thin command line over
//! [`job`]: it parses options into a checked job and runs it; everything else lives here, with
//! typed errors ([`Error`]).
//!
//! Modules, bottom layer first:
//!
//! - [`error`]: the library's typed error; every variant names the file or parameter at fault.
//! - [`field`]: the request fields a message names, spelled by each front end (`--tau-rel`,
//!   `tau_rel`).
//! - [`convention`]: NDC depth range, reversed-Z and row order as runtime switches; device
//!   depth <-> view Z in f32 and f64.
//! - [`camera`]: intrinsics (and their files), poses, projections, the stereo camera model and
//!   fixation from gaze vergence.
//! - [`depth`]: one depth encoding (view Z, view distance, device depth, disparity) with f64
//!   encode/decode and the background rule.
//! - [`io`]: colour, depth and mask files (loaders with a pixel budget, atomic all-or-none
//!   savers, out-dir confinement).
//! - [`alloc`]: fallible allocation of image-sized buffers (out of memory is an error).
//! - [`cpu_time`]: the process's CPU time, for the benchmarks' host-CPU figures.
//! - [`gpu`]: the EGL context and device choice, RAII GL objects, programs, readback, timers.
//! - [`progress`]: the stages of long runs (demo, report) handed to the caller.
//! - [`view`]: the output shape shared by every GPU pass and its f64 twin.
//! - [`output`]: the output layer, a view's files written into an all-or-none file set.
//! - [`ssim`]: structural similarity, f64.
//! - [`metrics`]: error measures of the tests, reports and benchmarks (PSNR, masks, depth).
//! - [`world`]: the built-in scenes as data (shapes) and their f64 ray tracer.
//! - [`stereo`]: a stereo pair's geometry below the capabilities: frame types, the camera
//!   file, frames from disparities, the stereo matcher, densify and the middle-ray walk.
//! - [`mesh`]: the 2.5D grid mesh of a depth map and its break rule (refocus, cyclopean's
//!   forward warp).
//! - [`scene`]: ground-truth frames of the built-in scenes, ray-traced on the GPU.
//! - [`refocus`]: same-pose re-rendering at other focal lengths, one frame or a pipelined batch.
//! - [`cyclopean`]: the middle (spectator) view of a stereo pair, five methods.
//! - [`reproject`]: one view of a stereo rig to another eye.
//! - [`stitch`]: ODS 360 equirects from over-wide cube faces.
//! - [`compare`]: two renderings compared across conventions, with CI thresholds (feature
//!   `compare`, on by default; the command line needs it, the Python package builds without it).
//! - [`pass`]: backend-neutral pass descriptions and the vocabulary both executors share (the
//!   shader library, timing, the GPU policy, the image-size rule); it knows no backend. [`gpu`]
//!   holds the GL executor beside the GL layer, [`vulkan`] the Vulkan backend (ash) with its
//!   executor, running the same GLSL: mirror images.
//! - [`job`]: one checked job per command-line command, and the code that runs it.
//!
//! The measuring lab (evaluation against ground truth, the report, benchmarks, stress cases and
//! the demo) is the `viewsynth-lab` crate above this one, and the `viewsynth` command line is
//! the `viewsynth-cli` crate above both.

#![warn(missing_docs)]

pub mod alloc;
pub mod camera;
#[cfg(feature = "compare")]
pub mod compare;
pub mod convention;
pub mod cpu_time;
pub mod cyclopean;
pub mod depth;
pub mod error;
pub mod field;
pub mod gpu;
pub mod io;
pub mod job;
pub mod mesh;
pub mod metrics;
pub mod output;
pub mod pass;
pub mod progress;
pub mod refocus;
pub mod reproject;
pub mod scene;
pub mod ssim;
pub mod stereo;
pub mod stitch;
pub mod view;
#[cfg(feature = "vulkan")]
pub mod vulkan;
#[cfg(not(feature = "vulkan"))]
#[path = "vulkan_off.rs"]
pub mod vulkan;
pub mod world;

#[cfg(test)]
mod test_data;
#[cfg(test)]
mod test_rng;

pub use error::{Error, Result};
pub use field::{Field, Message, Spelling};
