//! What a command writes, as data: which outputs ([`OutputSet`]), their formats
//! ([`FileFormats`]), the names of a view's files ([`ViewNames`]) and the manifest entry listing
//! them ([`ViewFiles`], [`FileRecord`]). The output layer that turns a view into these files,
//! `output::write_view`, sits above the view type and takes its vocabulary from here.
//!
//! Names: `{stem}_rgb.{png,jpg,exr}`, `{stem}_depth.exr`, `{stem}_depth.npy`,
//! `{stem}_depth.png` (uint16 millimetres), `{stem}_depth_preview.png`, `{stem}_mask.png`;
//! [`ViewNames`] lets a command keep other names it has always written (stitch's
//! `ods_left.png`, scene's `left_view_z.exr`).

use crate::error::{Error, Result};
use crate::io::{Encoding, FileSet, FileWriter, Png16Units, PreviewRange};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Which outputs to produce; nothing is allocated, read back or written for the others.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct OutputSet {
    /// Produce the colour image.
    pub rgb: bool,
    /// Produce the view-Z depth.
    pub depth: bool,
    /// Produce the validity mask.
    pub mask: bool,
}

impl Default for OutputSet {
    fn default() -> Self {
        OutputSet {
            rgb: true,
            depth: true,
            mask: true,
        }
    }
}

impl OutputSet {
    /// The set as `--outputs` names it, e.g. "rgb,mask".
    pub fn names(&self) -> String {
        [(self.rgb, "rgb"), (self.depth, "depth"), (self.mask, "mask")]
            .iter()
            .filter(|(on, _)| *on)
            .map(|(_, name)| *name)
            .collect::<Vec<_>>()
            .join(",")
    }

    /// Parse "rgb,depth,mask" (any subset, at least one; "color"/"colour" name rgb).
    pub fn parse(list: &str) -> Result<Self> {
        let mut out = OutputSet {
            rgb: false,
            depth: false,
            mask: false,
        };
        for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            match item {
                "rgb" | "color" | "colour" => out.rgb = true,
                "depth" => out.depth = true,
                "mask" => out.mask = true,
                _ => {
                    return Err(Error::param(
                        "outputs",
                        format!("'{item}': expected rgb, depth or mask"),
                    ))
                }
            }
        }
        if !(out.rgb || out.depth || out.mask) {
            return Err(Error::param("outputs", "at least one of rgb, depth, mask"));
        }
        Ok(out)
    }
}

/// File format of the colour output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum RgbFormat {
    /// 8-bit PNG (the default).
    #[default]
    Png,
    /// JPEG at quality 95 (lossy).
    #[serde(alias = "jpg")]
    Jpeg,
    /// OpenEXR, float32 R, G, B in [0, 1] (level / 255).
    Exr,
}

impl RgbFormat {
    /// File extension without the dot: "png", "jpg" or "exr".
    pub fn extension(self) -> &'static str {
        match self {
            RgbFormat::Png => "png",
            RgbFormat::Jpeg => "jpg",
            RgbFormat::Exr => "exr",
        }
    }
}

/// File formats of the metric depth output (any combination).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct DepthFormats {
    /// float32 metres in an OpenEXR file (the default).
    pub exr: bool,
    /// float32 metres in a NumPy `.npy` file.
    pub npy: bool,
    /// uint16 `metres * png16_units` in a 16-bit gray PNG (0 = invalid). Left out of the
    /// settings JSON when off, so batches made before it resume.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub png16: bool,
    /// Raw units per metre of the png16 file (default 1000, millimetres; left out of the
    /// settings JSON at the default, so batches made before it resume).
    #[serde(skip_serializing_if = "Png16Units::is_default")]
    pub png16_units: Png16Units,
}

impl DepthFormats {
    /// The formats named (any of exr, npy, png16; at least one): the one parser of the CLI's
    /// `--depth-format` and Python's `depth_format=`. Err holds the first entry that is not a
    /// format ("" when none is given).
    pub fn parse<'a>(names: impl IntoIterator<Item = &'a str>) -> std::result::Result<Self, String> {
        let mut f = DepthFormats {
            exr: false,
            npy: false,
            png16: false,
            png16_units: Png16Units::default(),
        };
        for name in names {
            match name.trim() {
                "exr" => f.exr = true,
                "npy" => f.npy = true,
                "png16" => f.png16 = true,
                other => return Err(other.to_string()),
            }
        }
        if !(f.exr || f.npy || f.png16) {
            return Err(String::new());
        }
        Ok(f)
    }
}

impl Default for DepthFormats {
    fn default() -> Self {
        DepthFormats {
            exr: true,
            npy: false,
            png16: false,
            png16_units: Png16Units::default(),
        }
    }
}

/// What files a view produces and how they are encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct FileFormats {
    /// Which images are rendered (colour, depth, mask).
    pub outputs: OutputSet,
    /// File format of the colour output.
    pub rgb: RgbFormat,
    /// File formats of the depth output.
    pub depth: DepthFormats,
    /// PNG and EXR compression.
    pub encoding: Encoding,
    /// A colour-mapped PNG of the depth output beside it (left out of the settings JSON when
    /// off, so batches made before it resume).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub depth_preview: bool,
}

impl FileFormats {
    /// Checks that the choice can be honoured: at least one output, at least one depth format
    /// when depth is asked for, and a preview only with the depth it colours.
    pub fn validate(&self) -> Result<()> {
        let o = self.outputs;
        if !(o.rgb || o.depth || o.mask) {
            return Err(Error::param("outputs", "at least one of rgb, depth, mask"));
        }
        let d = self.depth;
        if o.depth && !(d.exr || d.npy || d.png16) {
            return Err(Error::param("depth-format", "at least one of exr, npy, png16"));
        }
        if self.depth_preview && !o.depth {
            return Err(Error::param(
                "depth-preview",
                crate::msg!["colours the depth output: add depth to ", crate::Field::Outputs],
            ));
        }
        Ok(())
    }
}

/// The file-name stems of a view's outputs (without extension).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ViewNames {
    /// Colour: `{rgb}.{png,jpg,exr}`.
    pub rgb: String,
    /// Depth: `{depth}.exr`, `{depth}.npy`, `{depth}.png`, `{depth}_preview.png`.
    pub depth: String,
    /// Mask: `{mask}.png`.
    pub mask: String,
}

impl ViewNames {
    /// `{tag}_rgb`, `{tag}_depth`, `{tag}_mask`: the names of every view but stitch's and
    /// scene's special files.
    pub fn tagged(tag: &str) -> Self {
        ViewNames {
            rgb: format!("{tag}_rgb"),
            depth: format!("{tag}_depth"),
            mask: format!("{tag}_mask"),
        }
    }
}

impl ViewNames {
    /// Whether `name` is one of the files this view may write (under any formats): its colour,
    /// depth, depth preview or mask, for the output-path checks made before any work.
    pub fn may_write(&self, name: &str) -> bool {
        let Some((stem, _ext)) = name.rsplit_once('.') else {
            return false;
        };
        let stems = [self.rgb.as_str(), self.depth.as_str(), self.mask.as_str()];
        let preview = stem
            .strip_suffix("_preview")
            .is_some_and(|d| !d.is_empty() && d == self.depth);
        preview || stems.iter().any(|s| !s.is_empty() && stem == *s)
    }
}

impl ViewNames {
    /// A colour file `{rgb}.png` (stitch's `ods_top_bottom`), with the depth file beside it
    /// named `{depth}.exr` where a view has one (scene's `left_view_z`).
    pub fn named(rgb: &str, depth: &str) -> Self {
        ViewNames {
            rgb: rgb.to_string(),
            depth: depth.to_string(),
            mask: format!("{rgb}_mask"),
        }
    }
}

impl OutputSet {
    /// Colour only.
    pub const RGB: OutputSet = OutputSet {
        rgb: true,
        depth: false,
        mask: false,
    };
    /// Colour and depth.
    pub const RGB_DEPTH: OutputSet = OutputSet {
        rgb: true,
        depth: true,
        mask: false,
    };
    /// Depth only.
    pub const DEPTH: OutputSet = OutputSet {
        rgb: false,
        depth: true,
        mask: false,
    };
}

impl FileFormats {
    /// The default formats (PNG colour, EXR depth, default compression) of `outputs`.
    pub fn of(outputs: OutputSet) -> Self {
        FileFormats {
            outputs,
            ..Default::default()
        }
    }
}

/// The files written for one view, as its manifest entry lists them (the fields, in this
/// order, of refocus's manifest entries).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ViewFiles {
    /// Colour file name, relative to the manifest; None when not written.
    pub rgb: Option<String>,
    /// Depth EXR file name; None when not written.
    pub depth_exr: Option<String>,
    /// Depth NPY file name; None when not written.
    pub depth_npy: Option<String>,
    /// Depth 16-bit PNG file name; None when not written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_png16: Option<String>,
    /// Raw units per metre of the 16-bit PNG (metres = raw / this), when written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_png16_units_per_metre: Option<f64>,
    /// Valid pixels written as 0 in the PNG because they lie beyond 65535 units
    /// (65.535 m in millimetres).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_png16_clipped: Option<u64>,
    /// Depth preview PNG file name; None when not written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_preview: Option<String>,
    /// Depth in metres at the preview's near (red) and far (blue) colours: the 2nd and 98th
    /// percentile of the valid depth; absent when no pixel is valid (the preview is black).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_preview_range_m: Option<PreviewRange>,
    /// Mask PNG file name; None when not written.
    pub mask: Option<String>,
    /// Fraction of output pixels with mask = 1 (when a mask or depth was produced).
    pub coverage: Option<f64>,
}

impl ViewFiles {
    /// The names written, in the order written.
    pub fn names(&self) -> impl Iterator<Item = &String> {
        [
            &self.rgb,
            &self.depth_exr,
            &self.depth_npy,
            &self.depth_png16,
            &self.depth_preview,
            &self.mask,
        ]
        .into_iter()
        .flatten()
    }
}

/// A written file (name relative to the manifest's folder) and its size in bytes.
#[derive(Debug, Clone, Serialize)]
pub struct FileRecord {
    /// File name, relative to the manifest's folder.
    pub name: String,
    /// Size in bytes.
    pub bytes: u64,
    /// CRC-32 of the contents: the file's identity, so that resume tells this set's files from
    /// another run's of the same names and sizes (a set mixed by a kill is redone).
    #[serde(default)]
    pub crc32: Option<u32>,
}

/// CRC-32 of the file at `path`, read in chunks.
pub fn file_crc32(path: &Path) -> std::io::Result<u32> {
    use std::io::Read;
    let mut f = std::fs::File::open(path)?;
    let mut crc = flate2::Crc::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            return Ok(crc.sum());
        }
        crc.update(&buf[..n]);
    }
}

/// The records (size, CRC-32) of files named relative to `dir`.
pub fn file_records<'a>(dir: &Path, names: impl IntoIterator<Item = &'a String>) -> Result<Vec<FileRecord>> {
    names
        .into_iter()
        .map(|name| {
            let path = dir.join(name);
            let bytes = std::fs::metadata(&path).map_err(|e| Error::io(&path, e))?.len();
            Ok(FileRecord {
                name: name.clone(),
                bytes,
                crc32: Some(file_crc32(&path).map_err(|e| Error::io(&path, e))?),
            })
        })
        .collect()
}

/// Per-pixel float maps that are not depths (the matcher's confidence, say), each `(name, map)`
/// as one file of `set`: one channel "Y" (OpenEXR's name for a single grey channel), f32, ZIP,
/// rows top-down. Encoded side by side, as a view's files are ([`FileSet::write_all`]).
pub fn write_float_exrs(set: &mut FileSet, maps: &[(&str, &crate::io::DepthMap)]) -> Result<Vec<std::path::PathBuf>> {
    let jobs = maps
        .iter()
        .map(|&(name, map)| {
            let shown = set.final_path(name);
            let write: FileWriter =
                Box::new(move |out| crate::io::encode_map_exr(&shown, out, map, "Y", crate::io::ExrCompression::Zip));
            (name.to_string(), write)
        })
        .collect();
    set.write_all(jobs)
}
