//! 8-bit RGB loading and saving.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};

use crate::error::{Error, Result};
use crate::io::files::atomic::atomic_write;
use crate::io::formats::decode::{decode_image, Decoded, Samples};
use crate::io::formats::exr::write_f32_channels;
use crate::io::image::types::{encode_dims, RgbImage};

const JPEG_QUALITY: u8 = 95;

/// Loads PNG, JPEG, PPM/PNM or EXR (format sniffed from the content) as 8-bit RGB.
///
/// Alpha is dropped (not composited), gray is replicated to RGB, 16-bit samples keep their
/// high byte (`v >> 8`). EXR is taken as linear and mapped by `round(clamp(v, 0, 1) * 255)`
/// with NaN -> 0: no tone mapping and no sRGB encoding, so HDR highlights clip.
pub fn load_rgb(path: &Path) -> Result<RgbImage> {
    let Decoded {
        width,
        height,
        channels,
        samples,
    } = decode_image(path, None)?;
    let data = match samples {
        // 8-bit RGB is already the image's bytes: kept as decoded, no pass over the pixels.
        Samples::U8(s) if channels == 3 => s,
        Samples::U8(s) => to_rgb8(&s, channels, |v| v),
        Samples::U16(s) => to_rgb8(&s, channels, |v| (v >> 8) as u8),
        Samples::F32(s) => to_rgb8(&s, channels, unit_to_u8),
    };
    RgbImage::new(width, height, data).map_err(|e| Error::decode(path, e.to_string()))
}

/// Saves by extension (case-insensitive): `.png`, `.jpg`/`.jpeg` (quality 95), or `.exr`
/// (three f32 channels R, G, B holding `v / 255`, linear, no sRGB decoding, ZIP compressed).
pub fn save_rgb(path: &Path, img: &RgbImage) -> Result<()> {
    save_rgb_with(path, img, &crate::io::Encoding::default())
}

/// [`save_rgb`] with chosen PNG/EXR compression.
pub fn save_rgb_with(path: &Path, img: &RgbImage, encoding: &crate::io::Encoding) -> Result<()> {
    let ext = lowercase_extension(path);
    if !matches!(ext.as_str(), "png" | "jpg" | "jpeg" | "exr") {
        return Err(Error::encode(
            path,
            "unknown RGB output format: expected .png .jpg .jpeg .exr",
        ));
    }
    encode_dims(path, img.width, img.height, 3, img.data.len())?;
    atomic_write(path, |out| encode_rgb(path, out, img, &ext, encoding))
}

/// Encodes `img` into `out` as `ext` says (png, jpg/jpeg or exr); errors name `path`.
pub fn encode_rgb(
    path: &Path,
    out: &mut BufWriter<File>,
    img: &RgbImage,
    ext: &str,
    encoding: &crate::io::Encoding,
) -> Result<()> {
    encode_dims(path, img.width, img.height, 3, img.data.len())?;
    let (w, h) = (img.width, img.height);
    match ext {
        "png" => PngEncoder::new_with_quality(out, encoding.png.image_type(), encoding.png.colour_filter())
            .write_image(&img.data, w, h, ExtendedColorType::Rgb8)
            .map_err(|e| Error::encode(path, e.to_string())),
        "jpg" | "jpeg" => JpegEncoder::new_with_quality(out, JPEG_QUALITY)
            .write_image(&img.data, w, h, ExtendedColorType::Rgb8)
            .map_err(|e| Error::encode(path, e.to_string())),
        "exr" => {
            let plane = |c: usize| -> Vec<f32> {
                img.data
                    .iter()
                    .skip(c)
                    .step_by(3)
                    .map(|&v| f32::from(v) / 255.0)
                    .collect()
            };
            let channels = vec![("R", plane(0)), ("G", plane(1)), ("B", plane(2))];
            write_f32_channels(path, out, w, h, channels, encoding.exr)
        }
        _ => Err(Error::encode(
            path,
            "unknown RGB output format: expected .png .jpg .jpeg .exr",
        )),
    }
}

pub(crate) fn lowercase_extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Gray (+alpha) is replicated, RGB(A) keeps its first three samples.
fn to_rgb8<T: Copy>(samples: &[T], channels: usize, conv: impl Fn(T) -> u8) -> Vec<u8> {
    let mut out = Vec::with_capacity(samples.len() / channels.max(1) * 3);
    for px in samples.chunks_exact(channels.max(1)) {
        match *px {
            [g] | [g, _] => out.extend([conv(g); 3]),
            [r, g, b] | [r, g, b, _] => out.extend([conv(r), conv(g), conv(b)]),
            _ => {}
        }
    }
    out
}

fn unit_to_u8(v: f32) -> u8 {
    if v.is_nan() {
        0
    } else {
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::{list_dir, scratch_dir};

    fn gradient(w: u32, h: u32) -> RgbImage {
        let mut data = Vec::new();
        for y in 0..h {
            for x in 0..w {
                data.extend([(x * 17 % 256) as u8, (y * 29 % 256) as u8, ((x + y) * 5) as u8]);
            }
        }
        RgbImage::new(w, h, data).unwrap()
    }

    #[test]
    fn png_round_trip_exact() {
        let dir = scratch_dir("rgb-png");
        let img = gradient(13, 7);
        let path = dir.join("a.PNG");
        save_rgb(&path, &img).unwrap();
        assert_eq!(load_rgb(&path).unwrap(), img);
    }

    #[test]
    fn exr_round_trip_exact() {
        let dir = scratch_dir("rgb-exr");
        let img = gradient(9, 5);
        let path = dir.join("a.exr");
        save_rgb(&path, &img).unwrap();
        assert_eq!(load_rgb(&path).unwrap(), img);
    }

    #[test]
    fn jpeg_round_trip_approximate() {
        let dir = scratch_dir("rgb-jpg");
        let img = gradient(32, 24);
        let path = dir.join("a.jpg");
        save_rgb(&path, &img).unwrap();
        let back = load_rgb(&path).unwrap();
        assert_eq!((back.width, back.height), (32, 24));
        let mean_err: f64 = img
            .data
            .iter()
            .zip(&back.data)
            .map(|(a, b)| (f64::from(*a) - f64::from(*b)).abs())
            .sum::<f64>()
            / img.data.len() as f64;
        assert!(mean_err < 6.0, "mean abs error {mean_err}");
    }

    #[test]
    fn gray_alpha_and_16_bit_inputs_convert() {
        let dir = scratch_dir("rgb-conv");
        let path = dir.join("g16.png");
        let gray16 = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(2, 1, vec![0x1234, 0xFF00]).unwrap();
        gray16.save(&path).unwrap();
        let img = load_rgb(&path).unwrap();
        assert_eq!(img.data, vec![0x12, 0x12, 0x12, 0xFF, 0xFF, 0xFF]);

        let path = dir.join("rgba.png");
        let rgba = image::RgbaImage::from_raw(1, 1, vec![10, 20, 30, 0]).unwrap();
        rgba.save(&path).unwrap();
        assert_eq!(load_rgb(&path).unwrap().data, vec![10, 20, 30]);
    }

    #[test]
    fn float_clamps_without_tone_mapping() {
        assert_eq!(unit_to_u8(-1.0), 0);
        assert_eq!(unit_to_u8(0.5), 128);
        assert_eq!(unit_to_u8(7.0), 255);
        assert_eq!(unit_to_u8(f32::NAN), 0);
        assert_eq!(unit_to_u8(f32::INFINITY), 255);
    }

    #[test]
    fn missing_file_names_path() {
        let path = scratch_dir("rgb-missing").join("nope.png");
        let err = load_rgb(&path).unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert!(err.to_string().contains("nope.png"), "{err}");
    }

    #[test]
    fn corrupt_png_is_decode_error() {
        let dir = scratch_dir("rgb-corrupt");
        let path = dir.join("bad.png");
        save_rgb(&path, &gradient(20, 20)).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        bytes.truncate(bytes.len() / 2);
        for b in bytes.iter_mut().skip(40) {
            *b ^= 0x5A;
        }
        std::fs::write(&path, bytes).unwrap();
        let err = load_rgb(&path).unwrap_err();
        assert!(matches!(err, Error::Decode { .. }), "{err}");
        assert!(err.to_string().contains("bad.png"));

        std::fs::write(&path, b"not an image at all").unwrap();
        assert!(matches!(load_rgb(&path), Err(Error::Decode { .. })));
    }

    #[test]
    fn save_rejects_bad_input_without_files() {
        let dir = scratch_dir("rgb-save-bad");
        let bad = RgbImage {
            width: 4,
            height: 4,
            data: vec![0; 5],
        };
        assert!(save_rgb(&dir.join("a.png"), &bad).is_err());
        assert!(save_rgb(&dir.join("a.bmp"), &gradient(2, 2)).is_err());
        let empty = RgbImage {
            width: 0,
            height: 0,
            data: vec![],
        };
        assert!(save_rgb(&dir.join("a.png"), &empty).is_err());
        assert!(list_dir(&dir).is_empty());
    }
}
