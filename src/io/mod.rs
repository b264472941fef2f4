//! Image, depth and mask I/O.
//!
//! All rasters are stored rows top-down (row 0 = top of the picture), whatever the file
//! format's own row order. Every `save_*` goes through [`atomic_write`], so a failed write
//! never leaves a partial file under the final name. Loaders refuse width or height of 0 or
//! above [`MAX_DIMENSION`] before allocating pixel memory.
//!
//! Folders by concern: `files/` (atomic saves, the output folder, all-or-none file sets,
//! guarded opening of inputs), `formats/` (the file formats byte by byte), `image/` (the
//! rasters, colour images and masks), `depth/` (depth and disparity files and their checks);
//! `json.rs` reads JSON within limits. This module is their facade: the rest of the library
//! and the front ends name `crate::io::X`.

pub(crate) use crate::error::excerpt;

mod depth;
mod files;
mod formats;
mod image;
mod json;

#[cfg(test)]
mod dataset_tests;
#[cfg(test)]
pub(crate) mod test_util;

pub use depth::disparity_fit::{fit_disparity_scale, ScaleFit, CANDIDATE_SCALES, CLEARLY_BETTER};
pub use depth::disparity_summary::{DisparitySummary, DisparityWarning, PLAUSIBLE_P95_WIDTH_SHARE};
pub use depth::file::{
    check_rgbd_sizes, depth_dimensions, load_depth, load_depth_with_key, rgb_dimensions, save_depth_exr,
    save_depth_exr_with, save_depth_npy, DepthDecode,
};
pub use depth::png16::{save_depth_png16, Png16Units, PNG16_UNITS_PER_METRE};
pub use depth::preview::{depth_preview, depth_preview_range, save_depth_preview, PreviewRange, PREVIEW_PERCENTILES};
pub use depth::summary::{DepthSummary, DepthWarning, PLAUSIBLE_MEDIAN_M};
pub use depth::trunc::{check_depth_trunc, truncate_depth};
pub use depth::values::{
    check_usable_depth, clear_unusable_depth, usable_depth_value, MAX_DEPTH_VALUE, MIN_DEPTH_VALUE,
};
pub use files::atomic::{atomic_write, probe_writable, TEMP_PREFIX};
pub(crate) use files::file_set::remove_own_file;
pub use files::file_set::{FileSet, FileWriter, Replaces, MANIFEST_NAME};
pub(crate) use files::input::{check_file_len, open_regular};
// For the output layer's path rule and float maps (`crate::output`).
pub(crate) use depth::file::encode_map_exr;
pub(crate) use files::atomic::parent_dir;
pub use files::input::{check_output_pixels, max_pixels, set_max_pixels, DEFAULT_MAX_PIXELS};
pub use files::out_dir::OutDir;
pub use files::staging::remove_orphan_temporaries;
pub use files::write_paths::{write_paths_all_or_none, PathWriter};
pub use formats::encoding::{Encoding, ExrCompression, PngCompression};
pub use formats::npy::{load_npy, save_npy_f32, NpyArray};
pub use formats::npy_header::NpyDtype;
pub use formats::npz::load_npz_array;
pub use image::colour::{load_colour, ColourImage};
pub use image::mask::{load_mask_png, save_mask_png, save_mask_png_with, MASK_FILLED};
pub use image::rgb::{load_rgb, save_rgb, save_rgb_with};
pub use image::types::{valid_fraction, DepthMap, Mask, RgbImage, MAX_DIMENSION};
pub use json::{load_json, read_text, MAX_JSON_BYTES, MAX_JSON_MAGNITUDE};
// The encoders one by one, for the lab's per-codec benchmark (`viewsynth_lab::bench::codecs`).
pub use depth::file::{encode_depth_exr, encode_depth_npy};
pub use depth::png16::encode_depth_png16;
pub use image::mask::encode_mask_png;
pub use image::rgb::encode_rgb;
