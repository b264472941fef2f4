//! Image, depth and mask I/O.
//!
//! All rasters are stored rows top-down (row 0 = top of the picture), whatever the file
//! format's own row order. Every `save_*` goes through [`atomic_write`], so a failed write
//! never leaves a partial file under the final name. Loaders refuse width or height of 0 or
//! above [`MAX_DIMENSION`] before allocating pixel memory.

pub(crate) use crate::error::excerpt;

mod atomic;
mod colour;
mod decode;
mod depth;
mod depth_png16;
mod depth_preview;
mod depth_ranks;
mod depth_summary;
mod depth_trunc;
mod depth_values;
mod disparity_fit;
mod disparity_summary;
mod encoding;
mod exr_io;
mod file_set;
mod grey_png;
mod image_types;
mod input;
mod json;
mod mask;
mod netpbm;
mod npy;
mod npz;
mod output_paths;
mod outputs;
mod pfm;
mod pgm;
mod raw_depth;
mod rgb;

#[cfg(test)]
mod dataset_tests;
#[cfg(test)]
pub(crate) mod test_util;

pub use atomic::{atomic_write, probe_writable, TEMP_PREFIX};
pub use colour::{load_colour, ColourImage};
pub use depth::{
    check_rgbd_sizes, depth_dimensions, load_depth, load_depth_with_key, rgb_dimensions, save_depth_exr,
    save_depth_exr_with, save_depth_npy, DepthDecode,
};
pub use depth_png16::{save_depth_png16, Png16Units, PNG16_UNITS_PER_METRE};
pub use depth_preview::{depth_preview, depth_preview_range, save_depth_preview, PreviewRange, PREVIEW_PERCENTILES};
pub use depth_summary::{DepthSummary, DepthWarning, PLAUSIBLE_MEDIAN_M};
pub use depth_trunc::{check_depth_trunc, truncate_depth};
pub use depth_values::{
    check_usable_depth, clear_unusable_depth, usable_depth_value, MAX_DEPTH_VALUE, MIN_DEPTH_VALUE,
};
pub use disparity_fit::{fit_disparity_scale, ScaleFit, CANDIDATE_SCALES, CLEARLY_BETTER};
pub use disparity_summary::{DisparitySummary, DisparityWarning, PLAUSIBLE_P95_WIDTH_SHARE};
pub use encoding::{Encoding, ExrCompression, PngCompression};
pub(crate) use file_set::remove_own_file;
pub use file_set::{
    remove_orphan_temporaries, write_paths_all_or_none, FileSet, FileWriter, OutDir, PathWriter, Replaces,
    MANIFEST_NAME,
};
pub use image_types::{valid_fraction, DepthMap, Mask, RgbImage, MAX_DIMENSION};
pub(crate) use input::{check_file_len, open_regular};
pub use input::{check_output_pixels, max_pixels, set_max_pixels, DEFAULT_MAX_PIXELS};
pub use json::{load_json, read_text, MAX_JSON_BYTES, MAX_JSON_MAGNITUDE};
pub use mask::{load_mask_png, save_mask_png, save_mask_png_with, MASK_FILLED};
pub use npy::{load_npy, save_npy_f32, NpyArray, NpyDtype};
pub use npz::load_npz_array;
pub use output_paths::{check_out_dir, check_outputs, NamedPath};
pub use outputs::{
    file_crc32, file_records, write_float_exrs, DepthFormats, FileFormats, FileRecord, OutputSet, RgbFormat, ViewFiles,
    ViewNames,
};
pub use rgb::{load_rgb, save_rgb, save_rgb_with};
// The encoders one by one, for the lab's per-codec benchmark (`viewsynth_lab::bench::codecs`).
pub use depth::{encode_depth_exr, encode_depth_npy};
pub use depth_png16::encode_depth_png16;
pub use mask::encode_mask_png;
pub use rgb::encode_rgb;
