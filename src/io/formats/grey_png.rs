//! The one grey channel of a depth or disparity PNG. Many dataset copies store grey maps as
//! palette (the decoder expands it to RGB or RGBA), RGB or RGBA PNGs with equal channels:
//! those are read as the grey they hold. Alpha must be opaque at every pixel: a transparent
//! pixel has no agreed meaning in a map (invalid? background?), so it is refused rather than
//! guessed. Colour channels that differ anywhere are refused, naming the first such pixel: a
//! colour-mapped visualisation is no map.

use std::path::Path;

use crate::error::{Error, Result};

/// The grey samples of `samples` (`channels` interleaved per pixel, `width` pixels a row):
/// as stored for 1 channel; the first channel for 2 (grey + alpha), 3 (RGB) or 4 (RGBA) when
/// the colour channels are equal and the alpha (if any) is `opaque` at every pixel.
pub(crate) fn grey_of<T: Copy + PartialEq + std::fmt::Display>(
    path: &Path,
    samples: Vec<T>,
    channels: usize,
    width: u32,
    opaque: T,
) -> Result<Vec<T>> {
    let (colours, alpha) = match channels {
        1 => return Ok(samples),
        2 => (1, true),
        3 => (3, false),
        4 => (3, true),
        n => {
            return Err(Error::decode(
                path,
                format!("a depth or disparity PNG has 1 to 4 channels, found {n}"),
            ))
        }
    };
    let at = |i: usize| {
        let w = width.max(1) as usize;
        (i % w, i / w)
    };
    for (i, px) in samples.chunks_exact(channels).enumerate() {
        if px[1..colours].iter().any(|&c| c != px[0]) {
            let (x, y) = at(i);
            let values: Vec<String> = px[..colours].iter().map(T::to_string).collect();
            return Err(Error::decode(
                path,
                format!(
                    "{channels}-channel PNG whose colour channels differ at pixel ({x}, {y}) ({}): \
                     not a grey map (a colour-mapped picture?); store depth or disparity as one grey channel",
                    values.join(", ")
                ),
            ));
        }
        if alpha && px[channels - 1] != opaque {
            let (x, y) = at(i);
            return Err(Error::decode(
                path,
                format!(
                    "{channels}-channel PNG with alpha {} at pixel ({x}, {y}): a grey map's alpha must be \
                     opaque everywhere (transparency has no meaning as depth or disparity)",
                    px[channels - 1]
                ),
            ));
        }
    }
    Ok(samples.chunks_exact(channels).map(|px| px[0]).collect())
}

#[cfg(test)]
mod tests {
    use super::grey_of;
    use std::path::Path;

    #[test]
    fn equal_channels_read_as_grey_and_others_are_refused_naming_the_pixel() {
        let p = Path::new("d.png");
        // 2 x 2 RGB with equal channels.
        let rgb: Vec<u8> = [7u8, 0, 200, 255].iter().flat_map(|&v| [v, v, v]).collect();
        assert_eq!(grey_of(p, rgb.clone(), 3, 2, 255).unwrap(), [7, 0, 200, 255]);
        let rgba: Vec<u16> = [9u16, 60000].iter().flat_map(|&v| [v, v, v, u16::MAX]).collect();
        assert_eq!(grey_of(p, rgba, 4, 2, u16::MAX).unwrap(), [9, 60000]);
        assert_eq!(grey_of(p, vec![5u8, 255, 6, 255], 2, 2, 255).unwrap(), [5, 6]);
        assert_eq!(grey_of(p, vec![1u8, 2, 3], 1, 3, 255).unwrap(), [1, 2, 3]);
        // Pixel (1, 1) of a 2 x 2 image differs in green.
        let mut bad = rgb;
        bad[3 * 3 + 1] = 254;
        let e = grey_of(p, bad, 3, 2, 255).unwrap_err().to_string();
        assert!(
            e.contains("d.png") && e.contains("differ at pixel (1, 1)") && e.contains("255, 254, 255"),
            "{e}"
        );
        // Transparency is refused, not ignored.
        let e = grey_of(p, vec![4u8, 4, 4, 255, 4, 4, 4, 0], 4, 2, 255)
            .unwrap_err()
            .to_string();
        assert!(e.contains("alpha 0 at pixel (1, 0)"), "{e}");
    }
}
