//! viewsynth-lab: the measuring lab above the `viewsynth` library.
//!
//! Everything here measures the library rather than being part of what users render with: every
//! method's error against ground truth next to its run time, the report written from it, the
//! benchmarks, the stiff and extreme cases, and the demo. It uses only the library's public API,
//! so what it measures is what a user of the library gets. The `viewsynth` command line
//! (`viewsynth-cli`) runs its jobs as `viewsynth report`, `bench`, `stress` and `demo`.
//!
//! Modules:
//!
//! - [`eval`]: every method's error against ground truth next to its run time, one file per
//!   capability, and the GPU-vs-reference image check.
//! - [`report`]: the evaluation written as Markdown, CSV and SVG.
//! - [`bench`](mod@bench): every benchmark: single-frame timings, the pipelined refocus batch
//!   against its synchronous baseline (`bench::batch`) with its per-codec CPU and bytes
//!   (`bench::codecs`), every pass on each device (`bench::passes`).
//! - [`passes`]: every pass of the library described once and run on any device: the rows of
//!   the GL-against-Vulkan agreement table and of the per-pass benchmark.
//! - [`progress`]: the stages of long runs (demo, report, bench, stress) handed to the caller.
//! - [`stats`]: the median of the timings.
//! - [`stress`]: stiff and extreme cases of every capability, GPU f32 against f64.
//! - [`demo`]: the built-in scene rendered, refocused and synthesised, with its report.
//! - [`job`]: the checked jobs of `viewsynth bench`, `report` and `stress`, run through a
//!   [`job::LabHost`] (the library's [`viewsynth::job::Host`] and the lab's events), with the
//!   lab's own errors.

#![warn(missing_docs)]

pub mod bench;
pub mod demo;
pub mod eval;
pub mod job;
pub mod passes;
pub mod progress;
pub mod report;
pub mod stats;
pub mod stress;
