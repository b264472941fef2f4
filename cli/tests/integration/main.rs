//! Integration tests: one binary. GPU tests need EGL with GL 4.5 (Mesa llvmpipe in CI); a
//! missing EGL fails them with the library's error, never a skip.

mod batch;
mod bounds;
mod cli;
mod cli_batch;
mod cli_batch_augment;
mod cli_batch_identity;
mod cli_cameras_cv;
mod cli_compare;
mod cli_depth_out;
mod cli_end_to_end;
mod cli_formats;
mod cli_help;
mod cli_manifest_tum;
mod cli_output;
mod cli_outputs_table;
mod cli_plausibility;
mod cli_reproject_stitch;
mod cli_sequence;
mod cli_units;
mod cli_warning_flags;
mod common;
mod compare;
mod compare_robust;
mod conventions_sweep;
mod cyclopean;
mod cyclopean_dense;
mod cyclopean_fill;
mod cyclopean_given_dense;
mod cyclopean_one_eye;
mod cyclopean_real;
mod cyclopean_temporal;
mod deletion;
mod device_choice;
mod gl_objects;
mod gpu_context;
mod hostile;
mod hostile_round3;
mod hostile_round4;
mod hostile_round4_outputs;
mod limits;
mod matcher;
mod memory_flat;
mod messages;
mod pass_contract;
mod readback;
mod refocus_accuracy;
mod refocus_conventions;
mod refocus_edge_cases;
mod refocus_oracle;
mod refocus_rgb_everywhere;
mod reproject;
mod scene;
mod shader_library;
mod stitch;
mod stress;
#[cfg(feature = "vulkan")]
mod vulkan_cli;
#[cfg(feature = "vulkan")]
mod vulkan_cyclopean;
#[cfg(feature = "vulkan")]
mod vulkan_passes;
#[cfg(feature = "vulkan")]
mod vulkan_refocus;
