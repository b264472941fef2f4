//! Colour at its file's own precision, for measures that must not quantise it (`compare`):
//! 8- and 16-bit samples as `v / 255` and `v / 65535`, float EXR samples as stored (linear, no
//! clamping), alpha kept when the file has it.

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::formats::decode::{decode_image, Decoded, Samples};
use crate::io::image::types::RgbImage;

/// RGB (and alpha, when the file has it) as f32, rows top-down, interleaved.
#[derive(Debug, Clone, PartialEq)]
pub struct ColourImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 3` samples, R G B per pixel; [0, 1] for integer files.
    pub rgb: Vec<f32>,
    /// `width * height` alpha samples, when the file has an alpha channel.
    pub alpha: Option<Vec<f32>>,
    /// Bits per sample of the file: 8, 16 or 32 (float).
    pub bits: u8,
}

impl From<&RgbImage> for ColourImage {
    fn from(img: &RgbImage) -> Self {
        ColourImage {
            width: img.width,
            height: img.height,
            rgb: img.data.iter().map(|v| f32::from(*v) / 255.0).collect(),
            alpha: None,
            bits: 8,
        }
    }
}

impl From<RgbImage> for ColourImage {
    fn from(img: RgbImage) -> Self {
        ColourImage::from(&img)
    }
}

/// Loads PNG, JPEG, PPM/PNM or EXR (sniffed from the content) at its own precision: gray is
/// replicated to RGB, alpha kept apart.
pub fn load_colour(path: &Path) -> Result<ColourImage> {
    let Decoded {
        width,
        height,
        channels,
        samples,
    } = decode_image(path, None)?;
    let (values, bits): (Vec<f32>, u8) = match samples {
        Samples::U8(s) => (s.iter().map(|v| f32::from(*v) / 255.0).collect(), 8),
        Samples::U16(s) => (s.iter().map(|v| f32::from(*v) / 65535.0).collect(), 16),
        Samples::F32(s) => (s, 32),
    };
    let has_alpha = channels == 2 || channels == 4;
    let n = width as usize * height as usize;
    let (mut rgb, mut alpha) = (
        Vec::with_capacity(n * 3),
        Vec::with_capacity(n * usize::from(has_alpha)),
    );
    for px in values.chunks_exact(channels.max(1)) {
        match *px {
            [g] => rgb.extend([g; 3]),
            [g, a] => {
                rgb.extend([g; 3]);
                alpha.push(a);
            }
            [r, g, b] => rgb.extend([r, g, b]),
            [r, g, b, a] => {
                rgb.extend([r, g, b]);
                alpha.push(a);
            }
            _ => return Err(Error::decode(path, format!("{channels} channels per pixel"))),
        }
    }
    if rgb.len() != n * 3 {
        return Err(Error::decode(path, "fewer samples than pixels"));
    }
    Ok(ColourImage {
        width,
        height,
        rgb,
        alpha: has_alpha.then_some(alpha),
        bits,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::scratch_dir;

    #[test]
    fn sixteen_bit_png_keeps_its_low_byte_and_alpha() {
        let d = scratch_dir("colour16");
        let p = d.join("c.png");
        // One pixel one 16-bit level apart from the next: 8-bit loading makes them equal.
        let px: Vec<u16> = vec![30000, 30001, 65535, 65535, 30001, 30000, 0, 32768];
        image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(2, 1, px)
            .unwrap()
            .save(&p)
            .unwrap();
        let c = load_colour(&p).unwrap();
        assert_eq!(c.bits, 16);
        assert_eq!(c.rgb[0], 30000.0 / 65535.0);
        assert_eq!(c.rgb[1], 30001.0 / 65535.0);
        assert_eq!(c.alpha, Some(vec![1.0, 32768.0 / 65535.0]));
    }
}
