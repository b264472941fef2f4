//! PGM (P5 binary, P2 plain) read with raw sample values, for integer depth.
//!
//! Unlike the `image` crate, samples are NOT rescaled to the full range when maxval is not
//! 255/65535: depth needs the stored integers. Two-byte samples are big-endian, as the
//! Netpbm spec requires; files that break this are fixed by `DepthDecode::swap_bytes`.

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::files::input::{check_file_len, open_regular, read_body, read_prefix};
use crate::io::formats::netpbm::{HeaderReader, NETPBM_HEADER_CAP};
use crate::io::formats::raw_depth::{RawDepth, RawSamples};
use crate::io::image::types::{decode_dims, sample_count};

pub(crate) fn read_pgm(path: &Path) -> Result<RawDepth> {
    let (mut file, len) = open_regular(path)?;
    let prefix = read_prefix(path, &mut file, len, NETPBM_HEADER_CAP)?;
    let bad = |msg: String| Error::decode(path, format!("invalid PGM: {msg}"));
    let mut header = HeaderReader::new(&prefix);
    let plain = match header.token() {
        Some(b"P5") => false,
        Some(b"P2") => true,
        _ => return Err(bad("expected magic P5 or P2 (grayscale)".into())),
    };
    let width: u64 = header.number("width").map_err(bad)?;
    let height: u64 = header.number("height").map_err(bad)?;
    let maxval: u32 = header.number("maxval").map_err(bad)?;
    if !(1..=65535).contains(&maxval) {
        return Err(bad(format!("maxval {maxval} outside 1..=65535")));
    }
    let (width, height) = decode_dims(path, width, height)?;
    let count = sample_count(width, height, 1).ok_or_else(|| bad("size overflows".into()))?;
    let wide = maxval > 255;

    let samples = if plain {
        // The samples are text right after the maxval. At most 6 bytes a sample ("65535 ")
        // plus comments: refuse what cannot be a plain PGM of this size rather than read it.
        let offset = header.position() as u64;
        let body_len = len.saturating_sub(offset);
        let most = (count as u64).saturating_mul(8).saturating_add(1 << 20);
        check_file_len(path, body_len, most, &format!("a plain {width}x{height} PGM"))?;
        let body = read_body(path, &mut file, offset, body_len as usize)?;
        read_plain(HeaderReader::new(&body), count, wide).map_err(bad)?
    } else {
        let offset = header.raster_offset().map_err(bad)?;
        let body_len = len.saturating_sub(offset as u64);
        let need = count.checked_mul(if wide { 2 } else { 1 });
        // Trailing bytes are allowed (a PGM file may hold several images) but never read.
        match need.filter(|n| *n as u64 <= body_len) {
            Some(n) => {
                let data = read_body(path, &mut file, offset as u64, n)?;
                if wide {
                    RawSamples::U16(data.chunks_exact(2).map(|b| u16::from_be_bytes([b[0], b[1]])).collect())
                } else {
                    RawSamples::U8(data)
                }
            }
            None => {
                return Err(bad(format!(
                    "truncated: {width}x{height} needs {} bytes of samples, file has {body_len}",
                    need.unwrap_or(usize::MAX),
                )))
            }
        }
    };
    Ok(RawDepth { width, height, samples })
}

fn read_plain(mut header: HeaderReader<'_>, count: usize, wide: bool) -> std::result::Result<RawSamples, String> {
    let mut values = Vec::new();
    for _ in 0..count {
        values.push(header.number::<u16>("sample")?);
    }
    Ok(if wide {
        RawSamples::U16(values)
    } else {
        // maxval <= 255, but a sample above 255 would not fit u8.
        RawSamples::U8(
            values
                .into_iter()
                .map(|v| u8::try_from(v).map_err(|_| format!("sample {v} exceeds 255")))
                .collect::<std::result::Result<_, _>>()?,
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::scratch_dir;

    fn samples_u16(raw: RawDepth) -> Vec<u16> {
        match raw.samples {
            RawSamples::U16(v) => v,
            _ => panic!("expected u16 samples"),
        }
    }

    #[test]
    fn binary_16_bit_is_big_endian_and_not_rescaled() {
        let dir = scratch_dir("pgm-16");
        let path = dir.join("d.pgm");
        let mut bytes = b"P5\n# comment\n3 1\n4095\n".to_vec();
        bytes.extend_from_slice(&[0x01, 0x02, 0x00, 0x00, 0x0F, 0xFF]);
        std::fs::write(&path, bytes).unwrap();
        let raw = read_pgm(&path).unwrap();
        assert_eq!((raw.width, raw.height), (3, 1));
        assert_eq!(samples_u16(raw), vec![0x0102, 0, 4095]);
    }

    #[test]
    fn plain_and_8_bit() {
        let dir = scratch_dir("pgm-plain");
        let path = dir.join("d.pgm");
        std::fs::write(&path, b"P2 2 2 1000\n1 2\n# c\n999 0\n").unwrap();
        assert_eq!(samples_u16(read_pgm(&path).unwrap()), vec![1, 2, 999, 0]);
        std::fs::write(&path, b"P5 2 1 255\n\x07\x08").unwrap();
        assert!(matches!(read_pgm(&path).unwrap().samples, RawSamples::U8(v) if v == [7, 8]));
    }

    #[test]
    fn bad_files_are_decode_errors() {
        let dir = scratch_dir("pgm-bad");
        let path = dir.join("d.pgm");
        for bytes in [
            &b"P5 2 2 65535\n\x00\x01\x00"[..],
            b"P6 1 1 255\n\x00\x00\x00",
            b"P5 0 1 255\n",
            b"P5 99999 1 255\n",
            b"P5 1 1 70000\n\x00",
            b"P5 1 1",
            b"P2 2 1 255\n1",
        ] {
            std::fs::write(&path, bytes).unwrap();
            let err = read_pgm(&path).unwrap_err();
            assert!(matches!(err, Error::Decode { .. }), "{err}");
            assert!(err.to_string().contains("d.pgm"));
        }
    }
}
