//! Integration tests: one binary. GPU tests need EGL with GL 4.5 (Mesa llvmpipe in CI); a
//! missing EGL fails them with the library's error, never a skip.

mod cli;
mod cli_reproject_stitch;
mod common;
mod compare;
mod cyclopean;
mod gpu_context;
mod hostile;
mod refocus_accuracy;
mod refocus_conventions;
mod refocus_edge_cases;
mod reproject;
mod scene;
mod stitch;
mod stress;
