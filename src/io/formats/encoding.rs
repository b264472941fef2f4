//! Compression settings of the encoders: PNG (colour, mask) and EXR (depth, colour). Every
//! setting is lossless (JPEG aside): a PNG decodes to the pixels given and an EXR to the same
//! f32 bits, whatever the setting. The defaults favour encoding time at a small cost in bytes
//! (see BENCHMARKS.md, issue 24); the bytes themselves are not part of any format's contract.

use crate::error::{Error, Result};
use serde::Serialize;

/// PNG deflate effort. `Fast` is the default (fdeflate, the image crate's default, with one
/// fixed row filter); `Default` is deflate's own default level (smaller files, several times
/// the CPU); `Best` the smallest files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PngCompression {
    /// Deflate's fastest level (the default).
    #[default]
    Fast,
    /// Deflate's default level.
    Default,
    /// Deflate's best (slowest) level.
    Best,
}

/// EXR compression of the float outputs (all lossless).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ExrCompression {
    /// Uncompressed.
    None,
    /// Run-length encoding, per scan line.
    Rle,
    /// ZIP over blocks of 16 lines (the default: small files).
    #[default]
    Zip,
    /// PIZ (lossless wavelet + Huffman), over blocks of 32 lines.
    Piz,
}

/// How files are compressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct Encoding {
    /// PNG effort for colour and mask files.
    pub png: PngCompression,
    /// EXR compression for depth and colour files.
    pub exr: ExrCompression,
}

impl std::str::FromStr for PngCompression {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "fast" => Ok(PngCompression::Fast),
            "default" => Ok(PngCompression::Default),
            "best" => Ok(PngCompression::Best),
            _ => Err(Error::param(
                "png-compression",
                format!("'{s}': expected fast, default or best"),
            )),
        }
    }
}

impl std::str::FromStr for ExrCompression {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "none" => Ok(ExrCompression::None),
            "rle" => Ok(ExrCompression::Rle),
            "zip" => Ok(ExrCompression::Zip),
            "piz" => Ok(ExrCompression::Piz),
            _ => Err(Error::param(
                "exr-compression",
                format!("'{s}': expected none, rle, zip or piz"),
            )),
        }
    }
}

impl PngCompression {
    pub(crate) fn image_type(self) -> image::codecs::png::CompressionType {
        use image::codecs::png::CompressionType;
        match self {
            PngCompression::Fast => CompressionType::Fast,
            PngCompression::Default => CompressionType::Default,
            PngCompression::Best => CompressionType::Best,
        }
    }

    /// Row filter of an 8-bit colour image. At `Fast` one fixed filter, Paeth: the adaptive
    /// choice tries all five filters on every row and picks Paeth on nearly all of them for the
    /// renders and photos here, so Paeth alone gives the same bytes (+-0.1 %) in one pass
    /// (TUM VGA colour: 1.3 ms a file against 2.5). The slower levels keep the adaptive choice.
    pub(crate) fn colour_filter(self) -> image::codecs::png::FilterType {
        use image::codecs::png::FilterType;
        match self {
            PngCompression::Fast => FilterType::Paeth,
            PngCompression::Default | PngCompression::Best => FilterType::Adaptive,
        }
    }

    /// Row filter of a mask (0 / 128 / 255). At `Fast`, Up: a mask's rows mostly repeat the row
    /// above, which Up turns into runs of zeros; half the adaptive filter's time for masks about
    /// 10 % larger (masks are ~1 % of a batch's bytes).
    pub(crate) fn mask_filter(self) -> image::codecs::png::FilterType {
        use image::codecs::png::FilterType;
        match self {
            PngCompression::Fast => FilterType::Up,
            PngCompression::Default | PngCompression::Best => FilterType::Adaptive,
        }
    }
}

impl ExrCompression {
    pub(crate) fn exr_encoding(self) -> exr::prelude::Encoding {
        use exr::prelude::{Blocks, Compression, Encoding, LineOrder};
        let compression = match self {
            ExrCompression::None => Compression::Uncompressed,
            ExrCompression::Rle => Compression::RLE,
            ExrCompression::Zip => Compression::ZIP16,
            ExrCompression::Piz => Compression::PIZ,
        };
        Encoding {
            compression,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_and_defaults_are_the_documented_settings() {
        assert_eq!("fast".parse::<PngCompression>().unwrap(), PngCompression::Fast);
        assert_eq!("piz".parse::<ExrCompression>().unwrap(), ExrCompression::Piz);
        assert!("gzip"
            .parse::<ExrCompression>()
            .unwrap_err()
            .to_string()
            .contains("exr-compression"));
        assert!("max"
            .parse::<PngCompression>()
            .unwrap_err()
            .to_string()
            .contains("png-compression"));
        assert_eq!(
            ExrCompression::default().exr_encoding(),
            exr::prelude::Encoding::SMALL_LOSSLESS
        );
        use image::codecs::png::FilterType;
        assert_eq!(PngCompression::default().colour_filter(), FilterType::Paeth);
        assert_eq!(PngCompression::default().mask_filter(), FilterType::Up);
        assert_eq!(PngCompression::Best.colour_filter(), FilterType::Adaptive);
    }
}
