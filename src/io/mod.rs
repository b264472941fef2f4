//! Image, depth and mask I/O.
//!
//! All rasters are stored rows top-down (row 0 = top of the picture), whatever the file
//! format's own row order. Every `save_*` goes through [`atomic_write`], so a failed write
//! never leaves a partial file under the final name. Loaders refuse width or height of 0 or
//! above [`MAX_DIMENSION`] before allocating pixel memory.

mod atomic;
mod decode;
mod depth;
mod depth_summary;
mod encoding;
mod exr_io;
mod image_types;
mod mask;
mod netpbm;
mod npy;
mod npz;
mod pfm;
mod pgm;
mod rgb;

#[cfg(test)]
mod dataset_tests;
#[cfg(test)]
mod test_util;

pub use atomic::atomic_write;
pub use depth::{load_depth, load_depth_with_key, save_depth_exr, save_depth_exr_with, save_depth_npy, DepthDecode};
pub use depth_summary::{DepthSummary, DepthWarning, PLAUSIBLE_MEDIAN_M};
pub use encoding::{Encoding, ExrCompression, PngCompression};
pub use image_types::{DepthMap, Mask, RgbImage, MAX_DIMENSION};
pub use mask::{load_mask_png, save_mask_png, save_mask_png_with};
pub use npy::{load_npy, save_npy_f32, NpyArray, NpyDtype};
pub use npz::load_npz_array;
pub use rgb::{load_rgb, save_rgb, save_rgb_with};
