//! Which outputs to write and in which file formats (refocus, batch and reproject).

use clap::{Args, ValueEnum};
use viewsynth::job::FileOptions;
use viewsynth::output::RgbFormat;

#[derive(Clone, Copy, ValueEnum)]
enum RgbFormatArg {
    Png,
    Jpeg,
    Exr,
}

#[derive(Args, Clone)]
#[command(next_help_heading = super::OUTPUTS)]
pub(crate) struct FileOutputArgs {
    /// Outputs to produce: any of rgb (or color), depth, mask [default: rgb,depth,mask].
    #[arg(long)]
    outputs: Option<String>,
    /// Colour file format: png (8-bit RGB), jpeg or exr.
    #[arg(long, value_enum, default_value = "png")]
    rgb_format: RgbFormatArg,
    /// Depth file formats, any of: exr (float32 metres), npy (float32 metres), png16 (uint16
    /// metres x --depth-png-scale, 0 = invalid; beyond 65535 units written as 0 and counted in
    /// the manifest) [default: exr].
    #[arg(long)]
    depth_format: Option<String>,
    /// Raw units per metre of png16 depth (recorded in the manifest): 1000 (millimetres: NYU
    /// toolbox, Open3D's default, ScanNet, SUN RGB-D) or 5000 (TUM); holds up to 65535 / this
    /// metres [default: 1000].
    #[arg(long, value_parser = viewsynth::job::finite_value)]
    depth_png_scale: Option<f64>,
    /// Also write a <view>_depth_preview.png beside each depth output (named as the command's
    /// --out-dir lists): the depth colour-mapped (turbo: near red, far blue, invalid black) over
    /// its 2nd-98th percentile (the range is recorded in the manifest where the command writes one).
    #[arg(long)]
    depth_preview: bool,
    /// PNG compression of colour and mask files: fast (the default: the fastest deflate level
    /// and a fixed row filter), default (deflate's default level: smaller files, several times
    /// the CPU) or best.
    #[arg(long, default_value = "fast")]
    png_compression: String,
    /// EXR compression of depth (and EXR colour): none, rle, zip (default) or piz; all lossless.
    #[arg(long, default_value = "zip")]
    exr_compression: String,
}

/// `--outputs` parsed, its errors naming the option as given.
pub(crate) fn parse_outputs(list: Option<&str>) -> Result<Option<viewsynth::output::OutputSet>, viewsynth::Error> {
    list.map(|l| viewsynth::output::OutputSet::parse(l).map_err(|e| e.renamed("--outputs")))
        .transpose()
}

impl FileOutputArgs {
    /// `--outputs` as given (None: the request's default, all three).
    pub(crate) fn outputs_given(&self) -> Result<Option<viewsynth::output::OutputSet>, viewsynth::Error> {
        parse_outputs(self.outputs.as_deref())
    }

    /// Sets the file settings of a refocus request.
    pub(crate) fn fill_refocus(&self, r: &mut viewsynth::job::refocus::RefocusRequest) -> Result<(), viewsynth::Error> {
        r.outputs = self.outputs_given()?;
        r.rgb_format = self.rgb_format();
        r.depth_format = self.depth_format.clone();
        r.depth_png_scale = self.depth_png_scale;
        r.depth_preview = self.depth_preview;
        r.png_compression = self.png_compression.clone();
        r.exr_compression = self.exr_compression.clone();
        Ok(())
    }

    /// `--rgb-format`.
    fn rgb_format(&self) -> RgbFormat {
        match self.rgb_format {
            RgbFormatArg::Png => RgbFormat::Png,
            RgbFormatArg::Jpeg => RgbFormat::Jpeg,
            RgbFormatArg::Exr => RgbFormat::Exr,
        }
    }

    /// The options as the library checks them, with `outputs` parsed once (the request's).
    pub(crate) fn options(&self, outputs: viewsynth::output::OutputSet) -> FileOptions<'_> {
        FileOptions {
            outputs,
            rgb: self.rgb_format(),
            depth: self
                .depth_format
                .as_deref()
                .unwrap_or(viewsynth::job::refocus::DEFAULT_DEPTH_FORMAT),
            depth_png_scale: self.depth_png_scale,
            depth_preview: self.depth_preview,
            png_compression: &self.png_compression,
            exr_compression: &self.exr_compression,
        }
    }
}
