//! Refocus targets and their manifest: which targets to render (focal list or zoom scales,
//! output size, principal point), the file-name tags, and `manifest.json` describing what was
//! written (the files themselves are written by the output layer, [`crate::output::write_view`]).

use super::RefocusOutput;
use crate::camera::{Intrinsics, PinholeCamera};
use crate::error::{Error, Result};
use crate::io::{self, FileSet};
use crate::output::{FileFormats, FileRecord, ViewFiles, ViewNames};
use crate::view::ViewOutput;
use serde::Serialize;
use std::path::Path;

/// The default focal scales of refocus (CLI `--zoom-range`, Python `scales=`, the demo and the
/// benchmarks): the one list every default refers to.
pub const DEFAULT_SCALES: [f64; 5] = [0.5, 0.75, 1.0, 1.5, 2.0];

/// [`DEFAULT_SCALES`] as the CLI's `--zoom-range` default text (a test checks they agree).
pub const DEFAULT_SCALES_TEXT: &str = "0.5,0.75,1,1.5,2";

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
    /// The files written and the coverage (flattened: the manifest's keys are as before).
    #[serde(flatten)]
    pub files: ViewFiles,
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
mask: 255 where a kept triangle covers the pixel centre, 0 elsewhere; every file's rows run top-down \
(conventions.row_order is the GPU framebuffers' order while rendering; the files do not depend on it); \
K' follows OpenCV: pixel (u, v) has its centre at (u, v).";

/// [`MANIFEST_NOTES`], amended under `--rgb-everywhere`.
pub fn manifest_notes(rgb_everywhere: bool) -> String {
    match rgb_everywhere {
        false => MANIFEST_NOTES.to_string(),
        true => format!(
            "{MANIFEST_NOTES} rgb_everywhere: rgb is sampled bilinearly at every pixel inside the source frame, \
             covered or not (0 only outside it); depth and mask still mark valid geometry only."
        ),
    }
}

/// A single frame's sources as given, and the decoding of its depth.
#[derive(Debug, Clone, Serialize)]
pub struct FrameInputs {
    /// The colour file.
    pub rgb: String,
    /// The depth file.
    pub depth: String,
    /// Raw depth units per metre (`--depth-scale`), when given.
    pub depth_scale: Option<f64>,
    /// SUN RGB-D's bit rotation was undone (`--sun-bit-rotate`).
    pub sun_bit_rotate: bool,
}

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
    /// `--rgb-everywhere`: colour at every pixel inside the source frame (absent when off).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub rgb_everywhere: bool,
    /// The settings a batch frame was made with; resume redoes the frame when they differ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub settings: Option<serde_json::Value>,
    /// The source files of a single frame and how its depth was decoded (a batch frame's
    /// `settings` record them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inputs: Option<FrameInputs>,
    /// Every file written, with its size: resume checks they are all still there.
    pub files: Vec<FileRecord>,
    /// One entry per target, in the order rendered.
    pub outputs: Vec<ManifestEntry>,
}

impl Manifest {
    /// The manifest of a frame rendered by `renderer` under `method`, `break_rule` and
    /// `conventions`, before its targets are written (the one place its fields are filled:
    /// [`write_frame`] adds the outputs and the files).
    #[allow(clippy::too_many_arguments)]
    pub fn of_frame(
        source: PinholeCamera,
        method: super::Method,
        break_rule: super::BreakRule,
        conventions: crate::convention::Conventions,
        renderer: String,
        rgb_everywhere: bool,
        settings: Option<serde_json::Value>,
    ) -> Self {
        Manifest {
            tool: format!("viewsynth {}", env!("CARGO_PKG_VERSION")),
            source,
            method,
            break_rule,
            conventions,
            renderer,
            notes: manifest_notes(rgb_everywhere),
            rgb_everywhere,
            settings,
            inputs: None,
            files: Vec::new(),
            outputs: Vec::new(),
        }
    }
}

/// The files `entries` name, with their sizes and CRC-32 on disk (under `dir`).
pub fn file_records(dir: &Path, entries: &[ManifestEntry]) -> Result<Vec<FileRecord>> {
    crate::output::file_records(dir, entries.iter().flat_map(|e| e.files.names()))
}

/// The file-name prefix of a zoom scale: 0.5 -> "s0.5", 1 -> "s1", 1.25 -> "s1.25" (short,
/// sortable enough, unambiguous).
pub fn scale_tag(scale: f64) -> String {
    format!("s{}", trim_decimals(scale))
}

/// A zoom scale as printed for people: at most 3 decimals, trailing zeros dropped (0.5 -> "0.5",
/// 400 / 525 -> "0.762"); the manifest keeps the exact value.
pub fn scale_label(scale: f64) -> String {
    let text = format!("{scale:.3}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    // -0.0004 rounds to "-0": print it as 0.
    if text == "-0" { "0" } else { text }.to_string()
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

/// Write the requested files of one target into `set` through the output layer, named by
/// `tag` (a [`scale_tag`] or [`focal_tag`]): `{tag}_rgb.png`, `{tag}_depth.exr`, ...
pub fn write_target(
    set: &mut FileSet,
    tag: &str,
    scale: f64,
    out: RefocusOutput,
    files: &FileFormats,
) -> Result<ManifestEntry> {
    let t0 = std::time::Instant::now();
    let (camera, render, readback_ms) = (out.camera, out.render, out.readback_ms);
    let view = ViewOutput {
        width: camera.width,
        height: camera.height,
        color: out.rgb,
        depth: out.depth,
        mask: out.mask,
        timing: Some(render),
        exact: None,
    };
    let written = crate::output::write_view(set, &ViewNames::tagged(tag), &view, files)?;
    Ok(ManifestEntry {
        scale,
        intrinsics: camera.k,
        width: camera.width,
        height: camera.height,
        files: written,
        render_ms: render.wall_ms,
        readback_ms,
        write_ms: t0.elapsed().as_secs_f64() * 1e3,
    })
}

/// [`write_target`] of one target straight into `dir` (a file set of its own, committed at
/// once), named by the scale's tag: for tools that write targets one by one (demo, bench).
pub fn write_output(dir: &Path, scale: f64, out: &RefocusOutput, files: &FileFormats) -> Result<ManifestEntry> {
    let mut set = FileSet::new(dir)?;
    let copy = RefocusOutput {
        camera: out.camera,
        rgb: out.rgb.clone(),
        depth: out.depth.clone(),
        mask: out.mask.clone(),
        render: out.render,
        readback_ms: out.readback_ms,
    };
    let entry = write_target(&mut set, &scale_tag(scale), scale, copy, files)?;
    set.commit()?;
    Ok(entry)
}

/// What a frame's set replaces: the files its folder's previous `manifest.json` lists, read by
/// the library's one deletion rule ([`io::Replaces`]: a regular file, never a symlink).
pub fn replaced() -> io::Replaces {
    io::Replaces::Manifest(listed_files)
}

/// The files a manifest's text lists (its `files`): none when it is not JSON with `files`.
fn listed_files(text: &str) -> Vec<String> {
    let Ok(m) = serde_json::from_str::<serde_json::Value>(text) else {
        return Vec::new();
    };
    m.get("files")
        .and_then(|f| f.as_array())
        .into_iter()
        .flatten()
        .filter_map(|f| f.get("name").and_then(|n| n.as_str()).map(str::to_string))
        .collect()
}

/// Writes one frame's set, the one frame path of the single-frame command and of the batch:
/// each target's files through the output layer ([`write_target`], in the order `targets`
/// yields them, so a caller may render each as it is asked for), then their records and
/// `manifest.json` (written last and renamed last: its presence marks the frame finished for
/// resume), and commits the set. `written` hears each target once its files are staged,
/// `before_commit` runs once all are (the batch removes its index then). A failure leaves the
/// previous run's files untouched.
pub fn write_frame(
    mut set: FileSet,
    mut manifest: Manifest,
    targets: impl IntoIterator<Item = Result<(String, f64, RefocusOutput)>>,
    files: &FileFormats,
    mut written: impl FnMut(),
    before_commit: impl FnOnce() -> Result<()>,
) -> Result<Manifest> {
    for target in targets {
        let (tag, scale, out) = target?;
        manifest.outputs.push(write_target(&mut set, &tag, scale, out, files)?);
        written();
    }
    manifest.files = file_records(set.staging(), &manifest.outputs).map_err(|e| set.final_error(e))?;
    let path = set.final_path(io::MANIFEST_NAME);
    let text = serde_json::to_string_pretty(&manifest).map_err(|e| Error::encode(&path, e.to_string()))?;
    set.write(io::MANIFEST_NAME, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| Error::io(&path, e))
    })?;
    before_commit()?;
    set.commit()?;
    Ok(manifest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_labels_are_short() {
        let got: Vec<String> = [0.5, 2.0, 400.0 / 525.0, 1.25, 0.0004, -0.0004, 1.9996]
            .into_iter()
            .map(scale_label)
            .collect();
        assert_eq!(got, ["0.5", "2", "0.762", "1.25", "0", "0", "2"]);
    }

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
    fn the_default_scales_text_is_the_default_scales() {
        let parsed: Vec<f64> = DEFAULT_SCALES_TEXT.split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(parsed, DEFAULT_SCALES);
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
        let e = write(dir.path(), "f571.4", 57.14, out, &FileFormats::default()).unwrap();
        assert_eq!(e.files.rgb.as_deref(), Some("f571.4_rgb.png"));
        assert_eq!(e.files.depth_exr.as_deref(), Some("f571.4_depth.exr"));
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

    /// [`write_target`] into a set committed into `dir`.
    fn write(dir: &Path, tag: &str, scale: f64, out: RefocusOutput, files: &FileFormats) -> Result<ManifestEntry> {
        let mut set = io::OutDir::prepare(dir)?.file_set()?;
        let e = write_target(&mut set, tag, scale, out, files)?;
        set.commit()?;
        Ok(e)
    }

    fn scratch(tag: &str) -> tempfile::TempDir {
        tempfile::Builder::new().prefix(tag).tempdir().unwrap()
    }

    #[test]
    fn png16_depth_counts_what_lies_beyond_its_range() {
        let dir = scratch("viewsynth-job-png16-");
        let out = synthetic_output(vec![1.5, 0.0, 70.0, 65.6]);
        let files = FileFormats {
            depth: crate::output::DepthFormats {
                exr: false,
                npy: false,
                png16: true,
                png16_units: Default::default(),
            },
            ..Default::default()
        };
        let e = write_output(dir.path(), 1.0, &out, &files).unwrap();
        assert_eq!(e.files.depth_png16.as_deref(), Some("s1_depth.png"));
        assert_eq!(
            (e.files.depth_exr.as_deref(), e.files.depth_png16_clipped),
            (None, Some(2))
        );
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
        // The units travel with the file, so no loader has to guess them.
        assert_eq!(json["depth_png16_units_per_metre"], 1000.0);
        // Off by default: neither the file nor the keys appear (older manifests stay as they were).
        let plain = write(dir.path(), "s2", 2.0, out, &FileFormats::default()).unwrap();
        let json = serde_json::to_value(&plain).unwrap();
        assert!(json.get("depth_png16").is_none() && json.get("depth_png16_clipped").is_none());
        let settings = serde_json::to_value(FileFormats::default()).unwrap();
        assert!(settings["depth"].get("png16").is_none(), "{settings}");
        assert!(settings["depth"].get("png16_units").is_none(), "{settings}");
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
        let e = write(dir.path(), "s0.5", 0.5, out, &files).unwrap();
        assert_eq!(e.files.depth_preview.as_deref(), Some("s0.5_depth_preview.png"));
        let r = e.files.depth_preview_range_m.unwrap();
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
