//! Portable Float Map, grayscale (`Pf`) only.
//!
//! The header's scale is negative for little-endian and positive for big-endian data; its
//! magnitude is ignored. Rows are stored bottom-up and are flipped to top-down here.

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::files::input::{open_regular, read_body, read_prefix};
use crate::io::formats::netpbm::{HeaderReader, NETPBM_HEADER_CAP};
use crate::io::formats::raw_depth::{RawDepth, RawSamples};
use crate::io::image::types::{decode_dims, sample_count};

pub(crate) fn read_pfm(path: &Path) -> Result<RawDepth> {
    let (mut file, len) = open_regular(path)?;
    let bytes = read_prefix(path, &mut file, len, NETPBM_HEADER_CAP)?;
    let bad = |msg: String| Error::decode(path, format!("invalid PFM: {msg}"));
    let mut header = HeaderReader::new(&bytes);
    match header.token() {
        Some(b"Pf") => {}
        Some(b"PF") => return Err(bad("colour PFM (PF) is not depth; expected grayscale Pf".into())),
        _ => return Err(bad("expected magic Pf".into())),
    }
    let width: u64 = header.number("width").map_err(bad)?;
    let height: u64 = header.number("height").map_err(bad)?;
    let scale: f64 = header.number("scale").map_err(bad)?;
    if !scale.is_finite() || scale == 0.0 {
        return Err(bad(format!("scale {scale} must be finite and non-zero")));
    }
    let little_endian = scale < 0.0;
    let (width, height) = decode_dims(path, width, height)?;
    let offset = header.raster_offset().map_err(bad)?;
    let need = sample_count(width, height, 4).ok_or_else(|| bad("size overflows".into()))?;
    let have = len.saturating_sub(offset as u64);
    if have != need as u64 {
        return Err(bad(format!(
            "{width}x{height} needs {need} bytes of samples, file has {have}"
        )));
    }
    let raster = read_body(path, &mut file, offset as u64, need)?;
    let row_bytes = width as usize * 4;
    let mut data = Vec::with_capacity(need / 4);
    for row in raster.chunks_exact(row_bytes).rev() {
        data.extend(row.chunks_exact(4).map(|b| {
            let b = [b[0], b[1], b[2], b[3]];
            if little_endian {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            }
        }));
    }
    Ok(RawDepth {
        width,
        height,
        samples: RawSamples::F32(data),
    })
}

/// Builds a PFM file (rows given top-down, stored bottom-up), for tests.
#[cfg(test)]
pub(crate) fn build_pfm(width: usize, rows_top_down: &[f32], little_endian: bool) -> Vec<u8> {
    let height = rows_top_down.len() / width;
    let scale = if little_endian { "-1.0" } else { "1.0" };
    let mut out = format!("Pf\n{width} {height}\n{scale}\n").into_bytes();
    for row in rows_top_down.chunks_exact(width).rev() {
        for v in row {
            out.extend(if little_endian {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::scratch_dir;

    // Non-symmetric 3x2 image: a row flip or transposition would change it.
    const TOP_DOWN: [f32; 6] = [1.0, 2.0, 3.0, 4.0, f32::INFINITY, -6.5];

    fn floats(raw: RawDepth) -> Vec<f32> {
        match raw.samples {
            RawSamples::F32(v) => v,
            _ => panic!("expected f32 samples"),
        }
    }

    #[test]
    fn both_endiannesses_and_row_flip() {
        let dir = scratch_dir("pfm");
        for le in [true, false] {
            let path = dir.join(format!("d{le}.pfm"));
            std::fs::write(&path, build_pfm(3, &TOP_DOWN, le)).unwrap();
            let raw = read_pfm(&path).unwrap();
            assert_eq!((raw.width, raw.height), (3, 2));
            assert_eq!(floats(raw), TOP_DOWN.to_vec());
        }
        // The first stored row is the bottom one.
        let bytes = build_pfm(3, &TOP_DOWN, true);
        let raster = &bytes[bytes.len() - 24..];
        assert_eq!(f32::from_le_bytes([raster[0], raster[1], raster[2], raster[3]]), 4.0);
    }

    #[test]
    fn bad_files_are_decode_errors() {
        let dir = scratch_dir("pfm-bad");
        let path = dir.join("d.pfm");
        let mut truncated = build_pfm(3, &TOP_DOWN, true);
        truncated.pop();
        for bytes in [
            truncated,
            b"PF\n1 1\n-1.0\n\0\0\0\0\0\0\0\0\0\0\0\0".to_vec(),
            b"Pf\n1 1\n0\n\0\0\0\0".to_vec(),
            b"Pf\n1 1\nnan\n\0\0\0\0".to_vec(),
            b"Pf\n0 1\n-1\n".to_vec(),
            b"P5\n1 1\n255\n\0".to_vec(),
        ] {
            std::fs::write(&path, bytes).unwrap();
            let err = read_pfm(&path).unwrap_err();
            assert!(matches!(err, Error::Decode { .. }), "{err}");
            assert!(err.to_string().contains("d.pfm"));
        }
    }
}
