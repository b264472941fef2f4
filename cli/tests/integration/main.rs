//! The command line's end-to-end tests: one binary, grouped by concern; each runs the
//! `viewsynth` binary (GPU commands need EGL with GL 4.5, Mesa llvmpipe in CI; a missing EGL
//! fails, never skips). The library's own tests are the `viewsynth_tests` crate; its helpers
//! are re-exported by `common`.

/// `refocus --batch` and `viewsynth manifest`: resume, identity, augmentation, memory per frame.
mod batch;
/// The binary's shared helpers (`bin`, `scratch`, clean-failure checks) and refocus end to end.
mod cli;
/// The library tests' helpers, and `viewsynth cyclopean` on the files they write.
mod common;
/// `viewsynth compare`: thresholds and exit codes, masks, JSON, FLIP, convention checks.
mod compare;
/// `viewsynth cyclopean`: files against the library, real pairs, one eye, sequences, cameras.
mod cyclopean;
/// Device choice: `info`, `--device`, `--require-gpu`, the software-renderer warnings.
mod device;
/// Help that is true and findable.
mod help;
/// The lab's commands: `demo`, `report` and `stress` end to end.
mod lab;
/// The output layer: files per output and format, deletion, outputs over inputs, the terminal.
mod outputs;
/// refocus: formats, units, depth outputs, plausibility warnings, colour everywhere.
mod refocus;
/// `viewsynth reproject` and `viewsynth stitch` end to end.
mod reproject_stitch;
/// Hostile input and failure: every option and commit step, files and processes, resource
/// limits, bounds on user counts, messages.
mod safety;
/// `--backend vulkan`: commands, the validation layer, the same files as GL.
#[cfg(feature = "vulkan")]
mod vulkan;
