//! In-memory raster types shared by the loaders, the savers and the rest of the crate.

use std::path::Path;

use crate::error::{Error, Result};

/// Largest accepted width or height. Bounds every allocation a file header can request.
pub const MAX_DIMENSION: u32 = 16384;

/// 8-bit RGB, rows top-down (row 0 = top of the picture), interleaved RGB.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 3` bytes, R G B per pixel, row after row.
    pub data: Vec<u8>,
}

/// f32 per pixel, rows top-down. Used for metric depth (metres, view-space Z) and disparity.
/// NaN, infinite, zero or negative values mean "no measurement".
#[derive(Debug, Clone, PartialEq)]
pub struct DepthMap {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` values, row after row.
    pub data: Vec<f32>,
}

/// u8 per pixel (0 or 1 semantically; written to PNG as 0/255), rows top-down.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mask {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` bytes, row after row.
    pub data: Vec<u8>,
}

impl RgbImage {
    /// Fails with `SizeMismatch` unless `data.len() == width * height * 3`.
    pub fn new(width: u32, height: u32, data: Vec<u8>) -> Result<Self> {
        check_len("RgbImage", width, height, 3, data.len())?;
        Ok(Self { width, height, data })
    }

    /// Pixel at column `x`, row `y` (top-down); `None` outside the image.
    pub fn get(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        let i = pixel_index(self.width, self.height, x, y)?.checked_mul(3)?;
        match self.data.get(i..i.checked_add(3)?)? {
            [r, g, b] => Some([*r, *g, *b]),
            _ => None,
        }
    }
}

impl DepthMap {
    /// Fails with `SizeMismatch` unless `data.len() == width * height`.
    pub fn new(width: u32, height: u32, data: Vec<f32>) -> Result<Self> {
        check_len("DepthMap", width, height, 1, data.len())?;
        Ok(Self { width, height, data })
    }

    /// Value at column `x`, row `y` (top-down); `None` outside the map.
    pub fn get(&self, x: u32, y: u32) -> Option<f32> {
        self.data.get(pixel_index(self.width, self.height, x, y)?).copied()
    }

    /// Fraction of pixels holding depth (Z > 0; NaN counts as none): an output's coverage
    /// when no mask was rendered.
    pub fn coverage(&self) -> f64 {
        valid_fraction(&self.data, |z| *z > 0.0)
    }
}

impl Mask {
    /// Fails with `SizeMismatch` unless `data.len() == width * height`.
    pub fn new(width: u32, height: u32, data: Vec<u8>) -> Result<Self> {
        check_len("Mask", width, height, 1, data.len())?;
        Ok(Self { width, height, data })
    }

    /// Fraction of pixels the mask marks valid (non-zero): an output's coverage.
    pub fn coverage(&self) -> f64 {
        valid_fraction(&self.data, |m| *m != 0)
    }

    /// Value at column `x`, row `y` (top-down); `None` outside the mask.
    pub fn get(&self, x: u32, y: u32) -> Option<u8> {
        self.data.get(pixel_index(self.width, self.height, x, y)?).copied()
    }
}

fn pixel_index(width: u32, height: u32, x: u32, y: u32) -> Option<usize> {
    if x >= width || y >= height {
        return None;
    }
    (y as usize).checked_mul(width as usize)?.checked_add(x as usize)
}

/// `width * height * channels`, or `None` on overflow.
pub(crate) fn sample_count(width: u32, height: u32, channels: usize) -> Option<usize> {
    (width as usize).checked_mul(height as usize)?.checked_mul(channels)
}

fn check_len(what: &str, width: u32, height: u32, channels: usize, len: usize) -> Result<()> {
    match sample_count(width, height, channels) {
        Some(n) if n == len => Ok(()),
        _ => Err(Error::SizeMismatch {
            message: format!(
                "{what} {width}x{height} with {channels} channel(s) needs \
                 {width}*{height}*{channels} samples, got {len}"
            ),
        }),
    }
}

fn dims_problem(width: u64, height: u64) -> Option<String> {
    let max = u64::from(MAX_DIMENSION);
    if width == 0 || height == 0 || width > max || height > max {
        Some(format!(
            "image size {width}x{height} is not supported: width and height must be 1..={max}"
        ))
    } else {
        None
    }
}

/// Dimension and pixel-budget check for a file being read (from its header, before the
/// pixels are read); returns the sizes as u32.
pub(crate) fn decode_dims(path: &Path, width: u64, height: u64) -> Result<(u32, u32)> {
    match dims_problem(width, height) {
        Some(msg) => Err(Error::decode(path, msg)),
        None => {
            crate::io::files::input::check_budget(path, width, height)?;
            // Both are <= MAX_DIMENSION here, so the casts are lossless.
            Ok((width as u32, height as u32))
        }
    }
}

/// Dimension check for an in-memory raster about to be written to `path`.
pub(crate) fn encode_dims(path: &Path, width: u32, height: u32, channels: usize, len: usize) -> Result<()> {
    if let Some(msg) = dims_problem(u64::from(width), u64::from(height)) {
        return Err(Error::encode(path, msg));
    }
    check_len(&path.display().to_string(), width, height, channels, len)
}

/// Coverage: the fraction of `values` that `valid` accepts (0 for none at all). The one formula
/// behind every "coverage" the library, the CLI's manifests and the Python package report
/// (also `metrics::valid_fraction`).
pub fn valid_fraction<T>(values: &[T], valid: impl Fn(&T) -> bool) -> f64 {
    values.iter().filter(|v| valid(v)).count() as f64 / values.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    #[test]
    fn coverage_of_masks_and_depth() {
        let mask = super::Mask::new(2, 2, vec![0, 255, 1, 0]).unwrap();
        assert_eq!(mask.coverage(), 0.5);
        let depth = crate::io::DepthMap::new(2, 2, vec![1.5, 0.0, f32::NAN, -1.0]).unwrap();
        assert_eq!(depth.coverage(), 0.25);
    }

    use super::*;

    #[test]
    fn new_checks_length() {
        assert!(RgbImage::new(2, 2, vec![0; 12]).is_ok());
        assert!(matches!(
            RgbImage::new(2, 2, vec![0; 11]),
            Err(Error::SizeMismatch { .. })
        ));
        assert!(DepthMap::new(3, 1, vec![0.0; 3]).is_ok());
        assert!(DepthMap::new(3, 1, vec![0.0; 4]).is_err());
        assert!(Mask::new(1, 2, vec![0; 2]).is_ok());
        assert!(Mask::new(u32::MAX, u32::MAX, vec![]).is_err());
    }

    #[test]
    fn get_is_top_down_row_major_and_bounded() {
        let img = RgbImage::new(2, 1, vec![1, 2, 3, 4, 5, 6]).unwrap();
        assert_eq!(img.get(1, 0), Some([4, 5, 6]));
        assert_eq!(img.get(2, 0), None);
        let d = DepthMap::new(2, 2, vec![0.0, 1.0, 2.0, 3.0]).unwrap();
        assert_eq!(d.get(0, 1), Some(2.0));
        assert_eq!(d.get(0, 2), None);
        // Inconsistent public fields must not panic.
        let bad = Mask {
            width: 5,
            height: 5,
            data: vec![],
        };
        assert_eq!(bad.get(1, 1), None);
    }

    #[test]
    fn dims_are_bounded() {
        let p = Path::new("x.png");
        assert!(decode_dims(p, 0, 5).is_err());
        assert!(decode_dims(p, 16385, 5).is_err());
        assert_eq!(decode_dims(p, 16384, 1).unwrap(), (16384, 1));
        let err = decode_dims(p, 1, 0).unwrap_err().to_string();
        assert!(err.contains("x.png"), "{err}");
        assert!(encode_dims(p, 0, 0, 1, 0).is_err());
    }
}
