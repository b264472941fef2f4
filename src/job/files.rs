//! Output files of refocus, batch and reproject (written by the output layer,
//! [`crate::output::write_view`]): which outputs, which formats, how encoded,
//! from the options' text (`--outputs rgb,depth`, `--depth-format exr,png16`, ...).

use super::ArgError;
use crate::io;
use crate::output::{DepthFormats, FileFormats, OutputSet, RgbFormat};

/// The file options as given.
#[derive(Debug, Clone, Copy)]
pub struct FileOptions<'a> {
    /// `--outputs`, parsed once by the front end.
    pub outputs: OutputSet,
    /// `--rgb-format`.
    pub rgb: RgbFormat,
    /// `--depth-format`: any of exr, npy, png16.
    pub depth: &'a str,
    /// `--depth-png-scale`: raw units per metre of png16 depth (none: 1000, millimetres).
    pub depth_png_scale: Option<f64>,
    /// `--depth-preview`.
    pub depth_preview: bool,
    /// `--png-compression`: fast, default or best.
    pub png_compression: &'a str,
    /// `--exr-compression`: none, rle, zip or piz.
    pub exr_compression: &'a str,
}

/// The validated file formats of refocus and reproject (a preview needs the depth output it
/// colours); the output layer ([`crate::output::write_view`]) writes every one of them.
pub fn file_formats(o: &FileOptions<'_>) -> Result<FileFormats, ArgError> {
    let mut depth = depth_formats(o.depth)?;
    if let Some(units) = o.depth_png_scale {
        // A unit that changes nothing would be silently ignored: name it instead.
        if !depth.png16 {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::DepthPngScale,
                crate::msg![
                    "sets the units of png16 depth: add png16 to ",
                    crate::Field::DepthFormat
                ],
            )));
        }
        depth.png16_units = io::Png16Units::new(units).map_err(|e| e.renamed(crate::Field::DepthPngScale))?;
    }
    let formats = FileFormats {
        outputs: o.outputs,
        rgb: o.rgb,
        depth,
        encoding: io::Encoding {
            png: png_compression(o.png_compression)?,
            exr: o
                .exr_compression
                .parse()
                .map_err(|e: crate::Error| e.renamed(crate::Field::ExrCompression))?,
        },
        depth_preview: o.depth_preview,
    };
    if formats.depth_preview && !formats.outputs.depth {
        return Err(ArgError::PreviewWithoutDepth);
    }
    formats.validate()?;
    Ok(formats)
}

/// `--png-compression`: fast, default or best (refocus, reproject and bench read it alike).
pub fn png_compression(text: &str) -> Result<io::PngCompression, ArgError> {
    Ok(text
        .parse()
        .map_err(|e: crate::Error| e.renamed(crate::Field::PngCompression))?)
}

/// `--depth-format`: a comma-separated list of exr, npy, png16.
pub fn depth_formats(list: &str) -> Result<DepthFormats, ArgError> {
    DepthFormats::parse(list.split(',')).map_err(ArgError::DepthFormat)
}

#[cfg(test)]
mod tests {
    use super::{depth_formats, file_formats, ArgError, FileOptions, OutputSet, RgbFormat};

    fn options<'a>(outputs: &str, depth: &'a str, preview: bool) -> FileOptions<'a> {
        FileOptions {
            outputs: OutputSet::parse(outputs).unwrap(),
            rgb: RgbFormat::Png,
            depth,
            depth_png_scale: None,
            depth_preview: preview,
            png_compression: "fast",
            exr_compression: "zip",
        }
    }

    #[test]
    fn depth_formats_combine_and_name_the_bad_entry() {
        let f = depth_formats("exr, png16").unwrap();
        assert!(f.exr && f.png16 && !f.npy);
        let e = depth_formats("exr,tiff").unwrap_err().to_string();
        assert!(e.contains("'tiff'") && e.contains("exr, npy, png16"), "{e}");
    }

    #[test]
    fn png16_units_are_checked_and_need_png16() {
        let mut o = options("rgb,depth", "exr,png16", false);
        assert_eq!(file_formats(&o).unwrap().depth.png16_units.get(), 1000.0);
        o.depth_png_scale = Some(5000.0);
        assert_eq!(file_formats(&o).unwrap().depth.png16_units.get(), 5000.0);
        for bad in [0.0, -5000.0, f64::NAN, f64::INFINITY] {
            o.depth_png_scale = Some(bad);
            let e = file_formats(&o).unwrap_err().to_string();
            assert!(e.starts_with("invalid --depth-png-scale"), "{e}");
        }
        let mut exr_only = options("rgb,depth", "exr", false);
        exr_only.depth_png_scale = Some(5000.0);
        let e = file_formats(&exr_only).unwrap_err().to_string();
        assert!(e.contains("--depth-png-scale") && e.contains("png16"), "{e}");
    }

    #[test]
    fn a_preview_needs_the_depth_output() {
        assert!(file_formats(&options("rgb,depth", "exr", true)).unwrap().depth_preview);
        let e = file_formats(&options("rgb,mask", "exr", true)).unwrap_err();
        assert!(matches!(e, ArgError::PreviewWithoutDepth), "{e}");
    }

    #[test]
    fn an_encoding_refusal_names_the_option() {
        for (png, exr, want) in [
            ("max", "zip", "invalid --png-compression: 'max'"),
            ("fast", "lzw", "invalid --exr-compression: 'lzw'"),
        ] {
            let mut o = options("rgb", "exr", false);
            o.png_compression = png;
            o.exr_compression = exr;
            let e = file_formats(&o).unwrap_err().to_string();
            assert!(e.starts_with(want), "{e}");
        }
    }
}
