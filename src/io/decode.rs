//! Decoding through the `image` crate into plain sample vectors, with size checks first.

use std::path::Path;

use image::{DynamicImage, ImageDecoder, ImageFormat, ImageReader};

use super::image_types::decode_dims;
use crate::error::{Error, Result};

/// Samples of one decoded image, interleaved, rows top-down.
pub(crate) enum Samples {
    U8(Vec<u8>),
    U16(Vec<u16>),
    F32(Vec<f32>),
}

pub(crate) struct Decoded {
    pub width: u32,
    pub height: u32,
    /// 1 gray, 2 gray+alpha, 3 RGB, 4 RGBA.
    pub channels: usize,
    pub samples: Samples,
}

/// Decodes `path`. The format is `format` if given, else sniffed from the content (falling
/// back on the extension). Width and height are checked before pixel memory is allocated.
pub(crate) fn decode_image(path: &Path, format: Option<ImageFormat>) -> Result<Decoded> {
    let mut reader = ImageReader::open(path).map_err(|e| Error::io(path, e))?;
    match format {
        Some(f) => reader.set_format(f),
        None => reader = reader.with_guessed_format().map_err(|e| Error::io(path, e))?,
    }
    if reader.format().is_none() {
        return Err(Error::decode(path, "unrecognised image format"));
    }
    let decoder = reader.into_decoder().map_err(|e| image_error(path, e))?;
    let (w, h) = decoder.dimensions();
    decode_dims(path, u64::from(w), u64::from(h))?;
    let image = DynamicImage::from_decoder(decoder).map_err(|e| image_error(path, e))?;
    let channels = usize::from(image.color().channel_count());
    let (width, height) = (image.width(), image.height());
    let samples = match image {
        DynamicImage::ImageLuma8(b) => Samples::U8(b.into_raw()),
        DynamicImage::ImageLumaA8(b) => Samples::U8(b.into_raw()),
        DynamicImage::ImageRgb8(b) => Samples::U8(b.into_raw()),
        DynamicImage::ImageRgba8(b) => Samples::U8(b.into_raw()),
        DynamicImage::ImageLuma16(b) => Samples::U16(b.into_raw()),
        DynamicImage::ImageLumaA16(b) => Samples::U16(b.into_raw()),
        DynamicImage::ImageRgb16(b) => Samples::U16(b.into_raw()),
        DynamicImage::ImageRgba16(b) => Samples::U16(b.into_raw()),
        DynamicImage::ImageRgb32F(b) => Samples::F32(b.into_raw()),
        DynamicImage::ImageRgba32F(b) => Samples::F32(b.into_raw()),
        other => {
            return Err(Error::decode(
                path,
                format!("unsupported pixel format {:?}", other.color()),
            ))
        }
    };
    Ok(Decoded {
        width,
        height,
        channels,
        samples,
    })
}

/// Every `image` failure after the file opened is a content problem (truncation included).
fn image_error(path: &Path, e: image::ImageError) -> Error {
    Error::decode(path, e.to_string())
}
