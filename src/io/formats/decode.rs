//! Decoding through the `image` crate into plain sample vectors, with size checks first.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use image::{DynamicImage, ImageDecoder, ImageFormat, ImageReader, Limits};

use crate::error::{Error, Result};
use crate::io::files::input::{max_pixels, open_regular};
use crate::io::image::types::{decode_dims, MAX_DIMENSION};

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

/// A reader positioned on `path`'s header, with the decoder's allocations capped by the pixel
/// budget (16 bytes a pixel: RGBA f32, the widest layout decoded).
fn reader(path: &Path, format: Option<ImageFormat>) -> Result<ImageReader<BufReader<File>>> {
    let (file, _) = open_regular(path)?;
    let mut reader = ImageReader::new(BufReader::new(file));
    match format {
        Some(f) => reader.set_format(f),
        None => reader = reader.with_guessed_format().map_err(|e| Error::io(path, e))?,
    }
    if reader.format().is_none() {
        return Err(Error::decode(path, "unrecognised image format"));
    }
    if reader.format() == Some(ImageFormat::OpenExr) {
        crate::io::formats::exr::check_exr_sampling(path)?;
    }
    let mut limits = Limits::default();
    limits.max_image_width = Some(MAX_DIMENSION);
    limits.max_image_height = Some(MAX_DIMENSION);
    limits.max_alloc = Some(max_pixels().saturating_mul(16).saturating_add(64 << 20));
    reader.limits(limits);
    Ok(reader)
}

/// Width and height from the header alone, checked against the limits and the pixel budget.
pub(crate) fn image_dimensions(path: &Path, format: Option<ImageFormat>) -> Result<(u32, u32)> {
    let decoder = reader(path, format)?.into_decoder().map_err(|e| image_error(path, e))?;
    let (w, h) = decoder.dimensions();
    decode_dims(path, u64::from(w), u64::from(h))
}

/// Decodes `path`. The format is `format` if given, else sniffed from the content. Width and
/// height are checked against the pixel budget before pixel memory is allocated; a JPEG
/// without its end-of-image marker (truncated) is refused.
pub(crate) fn decode_image(path: &Path, format: Option<ImageFormat>) -> Result<Decoded> {
    let reader = reader(path, format)?;
    let is_jpeg = reader.format() == Some(ImageFormat::Jpeg);
    let decoder = reader.into_decoder().map_err(|e| image_error(path, e))?;
    let (w, h) = decoder.dimensions();
    decode_dims(path, u64::from(w), u64::from(h))?;
    if is_jpeg {
        check_jpeg_complete(path)?;
    }
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

/// The JPEG decoder fills a truncated scan with grey and succeeds; a complete file has an
/// end-of-image marker (FF D9) after its first start-of-scan. The marker segments before the
/// scan are skipped by their lengths (an embedded thumbnail's FF D9 does not count); data after
/// the end-of-image marker (some cameras append a trailer) is allowed.
fn check_jpeg_complete(path: &Path) -> Result<()> {
    let truncated = |what: &str| Error::decode(path, format!("truncated JPEG: {what}"));
    let (file, len) = open_regular(path)?;
    let mut r = BufReader::new(file);
    let byte = |r: &mut BufReader<File>| -> Result<Option<u8>> {
        let mut b = [0u8; 1];
        match r.read(&mut b).map_err(|e| Error::io(path, e))? {
            0 => Ok(None),
            _ => Ok(Some(b[0])),
        }
    };
    if (byte(&mut r)?, byte(&mut r)?) != (Some(0xFF), Some(0xD8)) {
        return Err(truncated("no start-of-image marker"));
    }
    // Marker segments up to the first scan.
    loop {
        let mut marker = byte(&mut r)?.ok_or_else(|| truncated("ends before the scan"))?;
        if marker != 0xFF {
            return Err(Error::decode(path, "corrupt JPEG: marker expected"));
        }
        while marker == 0xFF {
            marker = byte(&mut r)?.ok_or_else(|| truncated("ends before the scan"))?;
        }
        let hi = byte(&mut r)?.ok_or_else(|| truncated("ends inside a segment"))?;
        let lo = byte(&mut r)?.ok_or_else(|| truncated("ends inside a segment"))?;
        let seg = u16::from_be_bytes([hi, lo]);
        if seg < 2 {
            return Err(Error::decode(path, "corrupt JPEG: segment length below 2"));
        }
        let pos = r.stream_position().map_err(|e| Error::io(path, e))?;
        let next = pos + u64::from(seg) - 2;
        if next > len {
            return Err(truncated("ends inside a segment"));
        }
        r.seek(SeekFrom::Start(next)).map_err(|e| Error::io(path, e))?;
        if marker == 0xDA {
            break;
        }
    }
    let mut prev_ff = false;
    while let Some(b) = byte(&mut r)? {
        if prev_ff && b == 0xD9 {
            return Ok(());
        }
        prev_ff = b == 0xFF;
    }
    Err(truncated("no end-of-image marker (FF D9) after the scan"))
}

/// Every `image` failure after the file opened is a content problem (truncation included).
fn image_error(path: &Path, e: image::ImageError) -> Error {
    match e {
        image::ImageError::Limits(l) => Error::decode(
            path,
            format!("{l} (pixel budget {} pixels, --max-pixels)", max_pixels()),
        ),
        e => Error::decode(path, e.to_string()),
    }
}
