//! Binary masks as 8-bit gray PNG (0 / 255 on disk, 0 / 1 in memory).

use std::path::Path;

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder, ImageFormat};

use crate::error::{Error, Result};
use crate::io::files::atomic::atomic_write;
use crate::io::formats::decode::{decode_image, Decoded, Samples};
use crate::io::image::types::{encode_dims, Mask};

/// Writes 8-bit gray: 0 -> 0, [`MASK_FILLED`] -> itself, any other nonzero value -> 255.
pub fn save_mask_png(path: &Path, mask: &Mask) -> Result<()> {
    save_mask_png_with(path, mask, crate::io::PngCompression::default())
}

/// The mask value of a pixel that was filled (cyclopean `--fill`), not rendered: kept as it is
/// in the PNG, where every other nonzero value is written 255.
pub const MASK_FILLED: u8 = 128;

/// [`save_mask_png`] with a chosen compression.
pub fn save_mask_png_with(path: &Path, mask: &Mask, compression: crate::io::PngCompression) -> Result<()> {
    atomic_write(path, |out| encode_mask_png(path, out, mask, compression))
}

/// Encodes [`save_mask_png_with`]'s file into `out`; errors name `path`.
pub fn encode_mask_png(
    path: &Path,
    out: &mut std::io::BufWriter<std::fs::File>,
    mask: &Mask,
    compression: crate::io::PngCompression,
) -> Result<()> {
    encode_dims(path, mask.width, mask.height, 1, mask.data.len())?;
    // The file's bytes go into this thread's buffer, kept between masks (no image-sized
    // allocation per file on a batch's encode threads).
    MASK_BYTES.with_borrow_mut(|bytes| {
        bytes.clear();
        bytes.extend(mask.data.iter().map(|&v| match v {
            0 => 0,
            MASK_FILLED => MASK_FILLED,
            _ => 255,
        }));
        let encoded = PngEncoder::new_with_quality(out, compression.image_type(), compression.mask_filter())
            .write_image(bytes, mask.width, mask.height, ExtendedColorType::L8)
            .map_err(|e| Error::encode(path, e.to_string()));
        if bytes.capacity() > KEEP_MASK_BYTES {
            *bytes = Vec::new();
        }
        encoded
    })
}

/// Largest mask buffer a thread keeps between files (a 4096 x 4096 mask).
const KEEP_MASK_BYTES: usize = 1 << 24;

thread_local! {
    static MASK_BYTES: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Reads a PNG mask: a pixel is 1 when any of its colour samples is nonzero (alpha is
/// ignored), else 0. Gray, gray+alpha, RGB and RGBA at 8 or 16 bits are accepted.
pub fn load_mask_png(path: &Path) -> Result<Mask> {
    let Decoded {
        width,
        height,
        channels,
        samples,
    } = decode_image(path, Some(ImageFormat::Png))?;
    let colour = match channels {
        1 | 2 => 1,
        _ => 3,
    };
    let data = match &samples {
        Samples::U8(s) => set_pixels(s, channels, colour, |v| v != 0),
        Samples::U16(s) => set_pixels(s, channels, colour, |v| v != 0),
        Samples::F32(s) => set_pixels(s, channels, colour, |v| v != 0.0),
    };
    Mask::new(width, height, data).map_err(|e| Error::decode(path, e.to_string()))
}

fn set_pixels<T: Copy>(samples: &[T], channels: usize, colour: usize, nonzero: impl Fn(T) -> bool) -> Vec<u8> {
    samples
        .chunks_exact(channels.max(1))
        .map(|px| u8::from(px.iter().take(colour).any(|&v| nonzero(v))))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::{list_dir, scratch_dir};

    #[test]
    fn round_trip_and_on_disk_values() {
        let dir = scratch_dir("mask");
        let path = dir.join("m.png");
        let mask = Mask::new(3, 2, vec![0, 1, 0, 7, 0, 1]).unwrap();
        save_mask_png(&path, &mask).unwrap();
        let on_disk = image::open(&path).unwrap();
        assert_eq!(on_disk.color(), image::ColorType::L8);
        assert_eq!(on_disk.into_luma8().into_raw(), vec![0, 255, 0, 255, 0, 255]);
        assert_eq!(load_mask_png(&path).unwrap().data, vec![0, 1, 0, 1, 0, 1]);
    }

    #[test]
    fn colour_masks_ignore_alpha() {
        let dir = scratch_dir("mask-rgba");
        let path = dir.join("m.png");
        let px = vec![0, 0, 0, 255, 1, 0, 0, 0, 0, 0, 0, 0];
        image::RgbaImage::from_raw(3, 1, px).unwrap().save(&path).unwrap();
        assert_eq!(load_mask_png(&path).unwrap().data, vec![0, 1, 0]);
    }

    #[test]
    fn errors_name_the_file() {
        let dir = scratch_dir("mask-bad");
        let path = dir.join("m.png");
        std::fs::write(&path, b"\x89PNG\r\n\x1a\nnope").unwrap();
        let err = load_mask_png(&path).unwrap_err();
        assert!(matches!(err, Error::Decode { .. }) && err.to_string().contains("m.png"));
        let err = load_mask_png(&dir.join("gone.png")).unwrap_err();
        assert!(matches!(err, Error::Io { .. }) && err.to_string().contains("gone.png"));
        let bad = Mask {
            width: 2,
            height: 2,
            data: vec![1],
        };
        let out = dir.join("sub");
        std::fs::create_dir(&out).unwrap();
        assert!(save_mask_png(&out.join("x.png"), &bad).is_err());
        assert!(list_dir(&out).is_empty());
    }
}
