//! Metric depth as 16-bit gray PNG, `round(metres * units)` with the units per metre chosen
//! ([`Png16Units`]: 1000, millimetres, by default; 5000 for TUM-style loaders): 0 = invalid.
//! The units are recorded beside the file (manifest, dataset index), because a loader that
//! assumes other units reads a plausible wrong depth.

use std::path::Path;

use image::codecs::png::{FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};

use crate::error::{Error, Result};
use crate::io::files::atomic::atomic_write;
use crate::io::image::types::{encode_dims, DepthMap};
use crate::io::PngCompression;
use serde::Serialize;

/// Stored units per metre by default (millimetres).
pub const PNG16_UNITS_PER_METRE: f64 = 1000.0;

/// Raw units per metre of a 16-bit depth PNG: finite and > 0 (checked by [`Png16Units::new`]),
/// so it is never NaN and compares as a number.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Serialize)]
#[serde(transparent)]
pub struct Png16Units(f64);

impl Eq for Png16Units {}

impl Default for Png16Units {
    fn default() -> Self {
        Png16Units::MILLIMETRES
    }
}

impl Png16Units {
    /// 1000 units per metre, the default (NYU toolbox, Open3D, ScanNet, SUN RGB-D read it).
    pub const MILLIMETRES: Png16Units = Png16Units(PNG16_UNITS_PER_METRE);

    /// `units_per_metre`, refused unless finite and > 0 (the error names `depth-png-scale`).
    pub fn new(units_per_metre: f64) -> Result<Self> {
        if !(units_per_metre.is_finite() && units_per_metre > 0.0) {
            return Err(Error::param(
                "depth-png-scale",
                format!(
                    "{units_per_metre}: raw units per metre must be finite and > 0 (1000 for millimetres, 5000 for TUM)"
                ),
            ));
        }
        Ok(Png16Units(units_per_metre))
    }

    /// Units per metre.
    pub fn get(self) -> f64 {
        self.0
    }

    /// The largest depth the file can hold, metres: 65535 units.
    pub fn max_depth_m(self) -> f64 {
        f64::from(u16::MAX) / self.0
    }

    /// Whether these are the default units (left out of a batch's settings JSON, so batches
    /// made before the option resume).
    pub fn is_default(&self) -> bool {
        *self == Png16Units::MILLIMETRES
    }
}

/// Writes `depth` (metres) as uint16 `metres * units`, rounded to nearest. Invalid depth (0,
/// negative, NaN, infinite) is written as 0. Returns how many valid pixels were written as 0
/// (invalid, never a wrong depth) because they round above 65535 units
/// ([`Png16Units::max_depth_m`]: 65.535 m in millimetres, 13.107 m at 5000 units per metre);
/// the callers record the count beside the file.
pub fn save_depth_png16(path: &Path, depth: &DepthMap, units: Png16Units, compression: PngCompression) -> Result<u64> {
    encode_dims(path, depth.width, depth.height, 1, depth.data.len())?;
    let mut clipped = 0;
    atomic_write(path, |out| {
        clipped = encode_depth_png16(path, out, depth, units, compression)?;
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
    units: Png16Units,
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
            let v = (f64::from(z) * units.get()).round();
            if v > f64::from(u16::MAX) {
                clipped += 1;
                0
            } else {
                // Valid depth under half a unit would round to the invalid marker: keep it valid.
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
        let clipped = save_depth_png16(&path, &depth, Png16Units::MILLIMETRES, PngCompression::Fast).unwrap();
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
    fn other_units_round_trip_through_a_plain_division() {
        let dir = scratch_dir("png16-tum");
        let path = dir.join("d.png");
        let tum = Png16Units::new(5000.0).unwrap();
        assert!((tum.max_depth_m() - 13.107).abs() < 1e-12);
        // 2.415 m is 12075 TUM units; 13.2 m lies beyond 13.107 m: written invalid and counted.
        let depth = DepthMap::new(3, 1, vec![2.415, 13.2, 0.0]).unwrap();
        assert_eq!(save_depth_png16(&path, &depth, tum, PngCompression::Fast).unwrap(), 1);
        let raw = image::open(&path).unwrap().into_luma16().into_raw();
        assert_eq!(raw, vec![12075, 0, 0]);
        assert_eq!(f64::from(raw[0]) / 5000.0, 2.415);
        for bad in [0.0, -1000.0, f64::NAN, f64::INFINITY] {
            let e = Png16Units::new(bad).unwrap_err().to_string();
            assert!(e.contains("depth-png-scale"), "{e}");
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
        assert!(save_depth_png16(&dir.join("d.png"), &bad, Png16Units::default(), PngCompression::Default).is_err());
        assert!(list_dir(&dir).is_empty());
    }
}
