//! A refocus job: which targets to render (focal list or zoom scales, output size, principal
//! point), where to write what, and the manifest describing it.

use super::{OutputSet, RefocusOutput};
use crate::camera::{Intrinsics, PinholeCamera};
use crate::error::{Error, Result};
use crate::io;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// File format of the colour output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum RgbFormat {
    /// 8-bit PNG (the default).
    #[default]
    Png,
    /// JPEG at quality 95 (lossy).
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
    /// uint16 millimetres in a 16-bit gray PNG (0 = invalid). Left out of the settings JSON
    /// when off, so batches made before it resume.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub png16: bool,
}

impl Default for DepthFormats {
    fn default() -> Self {
        DepthFormats {
            exr: true,
            npy: false,
            png16: false,
        }
    }
}

/// What files a target produces and how they are encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct FileFormats {
    /// Which images are rendered (colour, depth, mask).
    pub outputs: OutputSet,
    /// File format of the colour output.
    pub rgb: RgbFormat,
    /// File formats of the depth output.
    pub depth: DepthFormats,
    /// PNG and EXR compression.
    pub encoding: io::Encoding,
    /// A colour-mapped PNG of the depth output beside it (left out of the settings JSON when
    /// off, so batches made before it resume).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub depth_preview: bool,
}

/// How target cameras are derived from the source.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetSpec {
    /// Focal scales s: fx' = s fx, fy' = s fy.
    pub scales: Vec<f64>,
    /// Output size; None keeps the source size.
    pub size: Option<(u32, u32)>,
    /// Output principal point; None keeps the source's offset from the image centre, i.e.
    /// cx' = cx + (W' - W) / 2 (= cx at the same size).
    pub principal: Option<(f64, f64)>,
}

impl TargetSpec {
    /// Scales from absolute target focal lengths fx' (fy' follows with the source aspect).
    pub fn scales_from_focal_list(source: &Intrinsics, fx_list: &[f64]) -> Vec<f64> {
        fx_list.iter().map(|f| f / source.fx).collect()
    }

    /// File-name tags of a focal list, one per fx' as given (`f571.4`); two fx' that print
    /// alike would overwrite each other's files, so they are refused.
    pub fn focal_tags(fx_list: &[f64]) -> Result<Vec<String>> {
        let mut seen = std::collections::HashMap::new();
        for &f in fx_list {
            if let Some(prev) = seen.insert(focal_tag(f), f) {
                return Err(Error::param(
                    "focal-list",
                    format!(
                        "{prev} and {f} both name their files '{}' (6 decimals); give each focal length once",
                        focal_tag(f)
                    ),
                ));
            }
        }
        Ok(fx_list.iter().map(|&f| focal_tag(f)).collect())
    }

    /// One target camera per scale (the source scaled by it, at the output size and principal point); refuses an empty list, scales <= 0 or not finite, and two scales that print alike in file names.
    pub fn targets(&self, source: &PinholeCamera) -> Result<Vec<PinholeCamera>> {
        if self.scales.is_empty() {
            return Err(Error::param("scales", "no focal scale given"));
        }
        // Each scale names its files: two that print alike would overwrite each other.
        let mut tags = std::collections::HashMap::new();
        for &s in &self.scales {
            if let Some(prev) = tags.insert(scale_tag(s), s) {
                return Err(Error::param(
                    "focal scales",
                    format!(
                        "{prev} and {s} both name their files '{}' (6 decimals); give each scale once",
                        scale_tag(s)
                    ),
                ));
            }
        }
        let (w, h) = self.size.unwrap_or((source.width, source.height));
        let (cx, cy) = self.principal.unwrap_or((
            source.k.cx + (w as f64 - source.width as f64) / 2.0,
            source.k.cy + (h as f64 - source.height as f64) / 2.0,
        ));
        self.scales
            .iter()
            .map(|&s| {
                if !(s.is_finite() && s > 0.0) {
                    return Err(Error::param("focal scale", format!("{s} must be finite and > 0")));
                }
                let cam = PinholeCamera {
                    k: Intrinsics {
                        fx: source.k.fx * s,
                        fy: source.k.fy * s,
                        cx,
                        cy,
                    },
                    width: w,
                    height: h,
                };
                cam.validate("target camera")?;
                Ok(cam)
            })
            .collect()
    }
}

/// One manifest entry: a target and the files written for it.
#[derive(Debug, Clone, Serialize)]
pub struct ManifestEntry {
    /// Focal scale s of the target: fx' = s fx.
    pub scale: f64,
    /// The target's intrinsics K', pixels (OpenCV: pixel (u, v) centred at (u, v)).
    pub intrinsics: Intrinsics,
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Colour file name, relative to the manifest; None when not written.
    pub rgb: Option<String>,
    /// Depth EXR file name; None when not written.
    pub depth_exr: Option<String>,
    /// Depth NPY file name; None when not written.
    pub depth_npy: Option<String>,
    /// Depth 16-bit PNG file name (millimetres); None when not written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_png16: Option<String>,
    /// Valid pixels written as 0 in the PNG because they lie beyond 65.535 m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_png16_clipped: Option<u64>,
    /// Depth preview PNG file name; None when not written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_preview: Option<String>,
    /// Depth in metres at the preview's near (red) and far (blue) colours: the 2nd and 98th
    /// percentile of the valid depth; absent when no pixel is valid (the preview is black).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth_preview_range_m: Option<io::PreviewRange>,
    /// Mask PNG file name; None when not written.
    pub mask: Option<String>,
    /// Fraction of output pixels with mask = 1 (when a mask or depth was produced).
    pub coverage: Option<f64>,
    /// Wall time of the target's render, milliseconds.
    pub render_ms: f64,
    /// Wall time of reading the target's outputs back, milliseconds.
    pub readback_ms: f64,
    /// Wall time of encoding and writing the target's files, milliseconds.
    pub write_ms: f64,
}

/// What the output files hold, repeated in every manifest.
pub const MANIFEST_NOTES: &str = "rgb: 8-bit sRGB as sampled from the source (no hole filling, 0 where invalid); \
depth: view-space Z in metres (distance along the optical axis), float32, 0 where invalid; \
mask: 255 where a kept triangle covers the pixel centre, 0 elsewhere; rows top-down; \
K' follows OpenCV: pixel (u, v) has its centre at (u, v).";

/// The manifest written as `manifest.json` beside the outputs.
#[derive(Debug, Clone, Serialize)]
pub struct Manifest {
    /// Program and version that wrote the files ("viewsynth X.Y.Z").
    pub tool: String,
    /// The source camera: intrinsics and image size.
    pub source: PinholeCamera,
    /// Refocus method (fullscreen or mesh).
    pub method: super::Method,
    /// Depth-break rule that decides which source triangles are kept.
    pub break_rule: super::BreakRule,
    /// NDC depth range, reversed-Z and row order the targets were rendered under.
    pub conventions: crate::convention::Conventions,
    /// GL renderer string of the context that rendered them.
    pub renderer: String,
    /// What the files hold: depth is view-space Z in metres with 0 = invalid; mask 255 = valid.
    pub notes: String,
    /// The settings a batch frame was made with; resume redoes the frame when they differ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub settings: Option<serde_json::Value>,
    /// Every file written, with its size: resume checks they are all still there.
    pub files: Vec<FileRecord>,
    /// One entry per target, in the order rendered.
    pub outputs: Vec<ManifestEntry>,
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

/// The files `entries` name, with their sizes on disk.
pub fn file_records(dir: &Path, entries: &[ManifestEntry]) -> Result<Vec<FileRecord>> {
    let mut out = Vec::new();
    for e in entries {
        for name in [
            &e.rgb,
            &e.depth_exr,
            &e.depth_npy,
            &e.depth_png16,
            &e.depth_preview,
            &e.mask,
        ]
        .into_iter()
        .flatten()
        {
            let path = dir.join(name);
            let bytes = std::fs::metadata(&path).map_err(|e| Error::io(&path, e))?.len();
            out.push(FileRecord {
                name: name.clone(),
                bytes,
                crc32: Some(file_crc32(&path).map_err(|e| Error::io(&path, e))?),
            });
        }
    }
    Ok(out)
}

/// The file-name prefix of a zoom scale: 0.5 -> "s0.5", 1 -> "s1", 1.25 -> "s1.25" (short,
/// sortable enough, unambiguous).
pub fn scale_tag(scale: f64) -> String {
    format!("s{}", trim_decimals(scale))
}

/// The file-name prefix of a target focal length fx' in pixels: 571.4 -> "f571.4".
pub fn focal_tag(fx: f64) -> String {
    format!("f{}", trim_decimals(fx))
}

fn trim_decimals(v: f64) -> String {
    format!("{v:.6}")
        .trim_end_matches('0')
        .trim_end_matches('.')
        .to_string()
}

/// Write the requested files of one output under `dir` (atomic: temporary name, then rename),
/// named by the scale's tag.
pub fn write_output(dir: &Path, scale: f64, out: &RefocusOutput, files: &FileFormats) -> Result<ManifestEntry> {
    write_output_named(dir, &scale_tag(scale), scale, out, files)
}

/// [`write_output`] with the files named `{tag}_rgb.png` etc. (e.g. a [`focal_tag`]).
pub fn write_output_named(
    dir: &Path,
    tag: &str,
    scale: f64,
    out: &RefocusOutput,
    files: &FileFormats,
) -> Result<ManifestEntry> {
    let (outputs, rgb_format, depth_formats, enc) = (&files.outputs, files.rgb, files.depth, files.encoding);
    let t0 = std::time::Instant::now();
    let name = |suffix: &str| -> (PathBuf, String) {
        let file = format!("{tag}_{suffix}");
        (dir.join(&file), file)
    };
    let mut entry = ManifestEntry {
        scale,
        intrinsics: out.camera.k,
        width: out.camera.width,
        height: out.camera.height,
        rgb: None,
        depth_exr: None,
        depth_npy: None,
        depth_png16: None,
        depth_png16_clipped: None,
        depth_preview: None,
        depth_preview_range_m: None,
        mask: None,
        coverage: None,
        render_ms: out.render.wall_ms,
        readback_ms: out.readback_ms,
        write_ms: 0.0,
    };
    if let (true, Some(rgb)) = (outputs.rgb, &out.rgb) {
        let (path, file) = name(&format!("rgb.{}", rgb_format.extension()));
        io::save_rgb_with(&path, rgb, &enc)?;
        entry.rgb = Some(file);
    }
    if let (true, Some(depth)) = (outputs.depth, &out.depth) {
        if depth_formats.exr {
            let (path, file) = name("depth.exr");
            io::save_depth_exr_with(&path, depth, enc.exr)?;
            entry.depth_exr = Some(file);
        }
        if depth_formats.npy {
            let (path, file) = name("depth.npy");
            io::save_depth_npy(&path, depth)?;
            entry.depth_npy = Some(file);
        }
        if depth_formats.png16 {
            let (path, file) = name("depth.png");
            entry.depth_png16_clipped = Some(io::save_depth_png16(&path, depth, enc.png)?);
            entry.depth_png16 = Some(file);
        }
        if files.depth_preview {
            let (path, file) = name("depth_preview.png");
            entry.depth_preview_range_m = io::save_depth_preview(&path, depth, &enc)?;
            entry.depth_preview = Some(file);
        }
        let valid = depth.data.iter().filter(|z| **z > 0.0).count();
        entry.coverage = Some(valid as f64 / depth.data.len() as f64);
    }
    if let (true, Some(mask)) = (outputs.mask, &out.mask) {
        let (path, file) = name("mask.png");
        io::save_mask_png_with(&path, mask, enc.png)?;
        entry.mask = Some(file);
        let valid = mask.data.iter().filter(|m| **m != 0).count();
        entry.coverage = Some(valid as f64 / mask.data.len() as f64);
    }
    entry.write_ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(entry)
}

/// Write `manifest.json` atomically.
pub fn write_manifest(dir: &Path, manifest: &Manifest) -> Result<PathBuf> {
    let path = dir.join("manifest.json");
    let text = serde_json::to_string_pretty(manifest).map_err(|e| Error::encode(&path, e.to_string()))?;
    io::atomic_write(&path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| Error::io(&path, e))
    })?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_keep_the_principal_point_offset_when_the_size_changes() {
        let src = PinholeCamera {
            k: Intrinsics {
                fx: 500.0,
                fy: 480.0,
                cx: 319.5,
                cy: 239.5,
            },
            width: 640,
            height: 480,
        };
        let spec = TargetSpec {
            scales: vec![0.5, 2.0],
            size: Some((1280, 720)),
            principal: None,
        };
        let t = spec.targets(&src).unwrap();
        assert_eq!(
            t[0].k,
            Intrinsics {
                fx: 250.0,
                fy: 240.0,
                cx: 639.5,
                cy: 359.5
            }
        );
        assert_eq!(t[1].k.fx, 1000.0);
        let bad = TargetSpec {
            scales: vec![f64::NAN],
            size: None,
            principal: None,
        };
        assert!(bad.targets(&src).unwrap_err().to_string().contains("focal scale"));
        assert_eq!(scale_tag(0.5), "s0.5");
        let twins = TargetSpec {
            scales: vec![0.5, 0.5000001],
            size: None,
            principal: None,
        };
        let e = twins.targets(&src).unwrap_err().to_string();
        assert!(e.contains("0.5000001") && e.contains("s0.5"), "{e}");
        assert_eq!(scale_tag(1.0), "s1");
        assert_eq!(TargetSpec::scales_from_focal_list(&src.k, &[250.0]), vec![0.5]);
    }

    #[test]
    fn focal_lists_name_files_by_the_focal_given() {
        assert_eq!(focal_tag(571.4), "f571.4");
        assert_eq!(focal_tag(500.0), "f500");
        assert_eq!(TargetSpec::focal_tags(&[571.4, 1000.0]).unwrap(), ["f571.4", "f1000"]);
        let e = TargetSpec::focal_tags(&[600.0, 571.4, 571.4000001])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("focal-list") && e.contains("571.4000001") && e.contains("'f571.4'"),
            "{e}"
        );
        let dir = scratch("viewsynth-job-focal-");
        let out = synthetic_output(vec![1.0, 2.0]);
        let e = write_output_named(dir.path(), "f571.4", 57.14, &out, &FileFormats::default()).unwrap();
        assert_eq!(e.rgb.as_deref(), Some("f571.4_rgb.png"));
        assert_eq!(e.depth_exr.as_deref(), Some("f571.4_depth.exr"));
        assert_eq!(e.scale, 57.14);
        assert!(dir.path().join("f571.4_mask.png").is_file());
    }

    /// A 4x1 target whose depth holds `z`, rgb and mask all valid.
    fn synthetic_output(z: Vec<f32>) -> RefocusOutput {
        let (w, h) = (z.len() as u32, 1);
        RefocusOutput {
            camera: PinholeCamera {
                k: Intrinsics {
                    fx: 10.0,
                    fy: 10.0,
                    cx: 1.5,
                    cy: 0.0,
                },
                width: w,
                height: h,
            },
            rgb: Some(io::RgbImage::new(w, h, vec![128; (w * h * 3) as usize]).unwrap()),
            depth: Some(io::DepthMap::new(w, h, z).unwrap()),
            mask: Some(io::Mask::new(w, h, vec![1; (w * h) as usize]).unwrap()),
            render: Default::default(),
            readback_ms: 0.0,
        }
    }

    fn scratch(tag: &str) -> tempfile::TempDir {
        tempfile::Builder::new().prefix(tag).tempdir().unwrap()
    }

    #[test]
    fn png16_depth_counts_what_lies_beyond_its_range() {
        let dir = scratch("viewsynth-job-png16-");
        let out = synthetic_output(vec![1.5, 0.0, 70.0, 65.6]);
        let files = FileFormats {
            depth: DepthFormats {
                exr: false,
                npy: false,
                png16: true,
            },
            ..Default::default()
        };
        let e = write_output(dir.path(), 1.0, &out, &files).unwrap();
        assert_eq!(e.depth_png16.as_deref(), Some("s1_depth.png"));
        assert_eq!((e.depth_exr.as_deref(), e.depth_png16_clipped), (None, Some(2)));
        let back = io::load_depth(
            &dir.path().join("s1_depth.png"),
            &io::DepthDecode {
                scale: Some(1000.0),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(back.data, vec![1.5, 0.0, 0.0, 0.0]);
        let names: Vec<String> = file_records(dir.path(), std::slice::from_ref(&e))
            .unwrap()
            .into_iter()
            .map(|r| r.name)
            .collect();
        assert!(names.contains(&"s1_depth.png".to_string()), "{names:?}");
        let json = serde_json::to_value(&e).unwrap();
        assert_eq!(json["depth_png16_clipped"], 2);
        // Off by default: neither the file nor the keys appear (older manifests stay as they were).
        let plain = write_output(dir.path(), 2.0, &out, &FileFormats::default()).unwrap();
        let json = serde_json::to_value(&plain).unwrap();
        assert!(json.get("depth_png16").is_none() && json.get("depth_png16_clipped").is_none());
        let settings = serde_json::to_value(FileFormats::default()).unwrap();
        assert!(settings["depth"].get("png16").is_none(), "{settings}");
        assert!(settings.get("depth_preview").is_none(), "{settings}");
    }

    #[test]
    fn the_depth_preview_and_its_range_are_in_the_entry() {
        let dir = scratch("viewsynth-job-preview-");
        let out = synthetic_output(vec![1.0, 0.0, 2.0, 3.0]);
        let files = FileFormats {
            depth_preview: true,
            ..Default::default()
        };
        let e = write_output(dir.path(), 0.5, &out, &files).unwrap();
        assert_eq!(e.depth_preview.as_deref(), Some("s0.5_depth_preview.png"));
        let r = e.depth_preview_range_m.unwrap();
        assert_eq!((r.min_m, r.max_m), (1.0, 3.0));
        let json = serde_json::to_value(&e).unwrap();
        assert_eq!(json["depth_preview_range_m"]["max_m"], 3.0);
        let img = io::load_rgb(&dir.path().join("s0.5_depth_preview.png")).unwrap();
        assert_eq!(img.data[3..6], [0, 0, 0]);
        assert_ne!(img.data[..3], img.data[9..]);
        let names: Vec<String> = file_records(dir.path(), &[e])
            .unwrap()
            .into_iter()
            .map(|r| r.name)
            .collect();
        assert!(names.contains(&"s0.5_depth_preview.png".to_string()), "{names:?}");
    }
}
