//! Metric depth as 16-bit gray PNG in millimetres, the layout TUM/NYU-style loaders read
//! (`load_depth` with `scale: Some(1000.0)`): 0 = invalid.

use std::path::Path;

use image::codecs::png::{FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};

use super::atomic::atomic_write;
use super::image_types::{encode_dims, DepthMap};
use super::PngCompression;
use crate::error::{Error, Result};

/// Stored units per metre (millimetres).
pub const PNG16_UNITS_PER_METRE: f64 = 1000.0;

/// Writes `depth` (metres) as uint16 millimetres, rounded to nearest. Invalid depth (0,
/// negative, NaN, infinite) is written as 0. Returns how many valid pixels were written as 0
/// because they round above 65535 mm (65.535 m), the format's largest value.
pub fn save_depth_png16(path: &Path, depth: &DepthMap, compression: PngCompression) -> Result<u64> {
    encode_dims(path, depth.width, depth.height, 1, depth.data.len())?;
    let mut clipped = 0;
    atomic_write(path, |out| {
        clipped = encode_depth_png16(path, out, depth, compression)?;
        Ok(())
    })?;
    Ok(clipped)
}

/// Encodes [`save_depth_png16`]'s file into `out` and returns the clipped count; errors name
/// `path`.
pub fn encode_depth_png16(
    path: &Path,
    out: &mut std::io::BufWriter<std::fs::File>,
    depth: &DepthMap,
    compression: PngCompression,
) -> Result<u64> {
    encode_dims(path, depth.width, depth.height, 1, depth.data.len())?;
    let mut clipped = 0u64;
    let mm: Vec<u16> = depth
        .data
        .iter()
        .map(|&z| {
            if !(z.is_finite() && z > 0.0) {
                return 0;
            }
            let v = (f64::from(z) * PNG16_UNITS_PER_METRE).round();
            if v > f64::from(u16::MAX) {
                clipped += 1;
                0
            } else {
                // Valid depth under 0.5 mm would round to the invalid marker: keep it valid.
                (v as u16).max(1)
            }
        })
        .collect();
    // The encoder takes native-endian samples and writes them big-endian, as PNG requires.
    PngEncoder::new_with_quality(out, compression.image_type(), FilterType::Adaptive)
        .write_image(
            bytemuck::cast_slice(&mm),
            depth.width,
            depth.height,
            ExtendedColorType::L16,
        )
        .map_err(|e| Error::encode(path, e.to_string()))?;
    Ok(clipped)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::{list_dir, scratch_dir};
    use crate::io::{load_depth, DepthDecode};

    #[test]
    fn millimetres_round_trip_through_load_depth() {
        let dir = scratch_dir("png16");
        let path = dir.join("d.png");
        let data = vec![
            0.0,
            1.2344,
            1.2346,
            0.4,
            65.5,
            f32::NAN,
            -2.0,
            70.0,
            65.536,
            0.0002,
            3.0,
        ];
        let depth = DepthMap::new(11, 1, data.clone()).unwrap();
        let clipped = save_depth_png16(&path, &depth, PngCompression::Fast).unwrap();
        assert_eq!(clipped, 2, "70 m and 65.536 m exceed 65.535 m");
        let on_disk = image::open(&path).unwrap();
        assert_eq!(on_disk.color(), image::ColorType::L16);
        let raw = on_disk.into_luma16().into_raw();
        assert_eq!(raw, vec![0, 1234, 1235, 400, 65500, 0, 0, 0, 0, 1, 3000]);
        let back = load_depth(
            &path,
            &DepthDecode {
                scale: Some(1000.0),
                ..Default::default()
            },
        )
        .unwrap();
        for (i, (&z, &b)) in data.iter().zip(&back.data).enumerate() {
            if z.is_finite() && z > 0.001 && z <= 65.535 {
                assert!((z - b).abs() <= 0.0005 + 1e-6, "pixel {i}: {z} -> {b}");
            } else if !(z.is_finite() && z > 0.0) || z > 65.535 {
                assert_eq!(b, 0.0, "pixel {i}: {z} must be invalid");
            }
        }
    }

    #[test]
    fn a_wrong_size_writes_nothing() {
        let dir = scratch_dir("png16-bad");
        let bad = DepthMap {
            width: 2,
            height: 2,
            data: vec![1.0],
        };
        assert!(save_depth_png16(&dir.join("d.png"), &bad, PngCompression::Default).is_err());
        assert!(list_dir(&dir).is_empty());
    }
}
