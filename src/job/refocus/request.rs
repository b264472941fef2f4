//! The refocus request: every refocus setting both front ends give (the CLI's flags; Python's
//! keyword arguments of `refocus` and `refocus_batch`), with one default and one set of checks.
//!
//! Why here: the Python binding used to parse the file formats, default the thread count and
//! check the break rule and the targets on its own (and had drifted: no thread limit); now
//! both fill a [`RefocusRequest`] and [`RefocusRequest::frame`] / [`RefocusRequest::batch`]
//! decide once.

use crate::camera::PinholeCamera;
use crate::convention::Conventions;
use crate::io::{self};
use crate::job::{ArgError, FileOptions, PerFrameOption};
use crate::output::{FileFormats, OutputSet, RgbFormat};
use crate::refocus::batch::{BatchOptions, Shard, ZoomRandom};
use crate::refocus::manifest::{self, TargetSpec, DEFAULT_SCALES};
use crate::refocus::{BreakRule, Method};
use serde::Serialize;

/// The depth file format when none is asked for.
pub const DEFAULT_DEPTH_FORMAT: &str = "exr";

/// Every refocus setting a front end gives; [`Default`] holds the defaults of both.
#[derive(Debug, Clone, Serialize)]
pub struct RefocusRequest {
    /// Focal scales s, fx' = s fx (none: the default list, unless `focal_list`).
    pub scales: Option<Vec<f64>>,
    /// Absolute target fx' in pixels, fy' keeping fy/fx (one frame only).
    pub focal_list: Option<Vec<f64>>,
    /// Output (width, height); none: the source's.
    pub size: Option<(u32, u32)>,
    /// Output principal point; none: the source's offset from the image centre.
    pub principal: Option<(f64, f64)>,
    /// Relative depth-edge break threshold.
    pub tau_rel: f64,
    /// Absolute depth-edge break threshold, metres (inf disables).
    pub tau_abs: f64,
    /// GPU path.
    pub method: Method,
    /// The outputs; none: all three.
    #[serde(serialize_with = "crate::job::outputs_text")]
    pub outputs: Option<OutputSet>,
    /// Colour file format.
    pub rgb_format: RgbFormat,
    /// Depth file formats, comma-separated; none: [`DEFAULT_DEPTH_FORMAT`].
    pub depth_format: Option<String>,
    /// Raw units per metre of png16 depth; none: 1000 (millimetres).
    pub depth_png_scale: Option<f64>,
    /// Also write the depth preview.
    pub depth_preview: bool,
    /// PNG compression.
    pub png_compression: String,
    /// EXR compression.
    pub exr_compression: String,
    /// Depth beyond this many metres is a hole.
    pub depth_trunc: Option<f64>,
    /// Batch: skip frames finished with the same settings.
    pub resume: bool,
    /// Batch: with `resume`, also check the CRC-32 of every finished file and the content of
    /// every input.
    pub verify: bool,
    /// Batch: threads per CPU pool (none: the number of cores).
    pub jobs: Option<usize>,
    /// Batch: `K/N`.
    pub shard: Option<String>,
    /// Colour every pixel inside the source frame, covered or not.
    pub rgb_everywhere: bool,
    /// Batch: random scales per frame in [LO, HI] instead of `scales`.
    pub zoom_random: Option<(f64, f64)>,
    /// Batch: scales drawn per frame with `zoom_random` (none: 1).
    pub samples: Option<usize>,
    /// Batch: the seed of `zoom_random` (none: 0).
    pub seed: Option<u64>,
}

impl Default for RefocusRequest {
    fn default() -> Self {
        RefocusRequest {
            scales: None,
            focal_list: None,
            size: None,
            principal: None,
            tau_rel: BreakRule::default().tau_rel,
            tau_abs: BreakRule::default().tau_abs,
            method: Method::Fullscreen,
            outputs: None,
            rgb_format: RgbFormat::Png,
            depth_format: None,
            depth_png_scale: None,
            depth_preview: false,
            png_compression: "fast".into(),
            exr_compression: "zip".into(),
            depth_trunc: None,
            resume: true,
            verify: false,
            jobs: None,
            shard: None,
            rgb_everywhere: false,
            zoom_random: None,
            samples: None,
            seed: None,
        }
    }
}

/// One frame's checked settings: its targets wait for the source camera.
#[derive(Debug, Clone)]
pub struct FramePlan {
    /// Focal scales, or the absolute focal list.
    focals: Focals,
    /// File-name tag of each target, in order.
    pub tags: Vec<String>,
    size: Option<(u32, u32)>,
    principal: Option<(f64, f64)>,
    /// The edge-break rule.
    pub rule: BreakRule,
    /// The GPU path.
    pub method: Method,
    /// Outputs and file formats.
    pub files: FileFormats,
    /// Depth truncation, metres.
    pub depth_trunc: Option<f64>,
    /// Colour every pixel inside the source frame.
    pub rgb_everywhere: bool,
}

/// How the target focal lengths are given.
#[derive(Debug, Clone, PartialEq)]
enum Focals {
    /// Focal scales s, fx' = s fx; files named `s{s}_...`.
    Scales(Vec<f64>),
    /// Absolute fx' in pixels, fy' keeping fy/fx; files named `f{fx'}_...`.
    List(Vec<f64>),
}

impl RefocusRequest {
    /// The scales or the focal list, each value finite and > 0.
    fn focals(&self) -> Result<Focals, ArgError> {
        let focals = match (&self.focal_list, &self.scales) {
            (Some(_), Some(_)) => {
                return Err(ArgError::Invalid(crate::Error::param(
                    crate::Field::FocalList,
                    crate::msg![
                        "give target focal lengths or scales (",
                        crate::Field::ZoomRange,
                        "), not both"
                    ],
                )))
            }
            (Some(list), None) => Focals::List(list.clone()),
            (None, scales) => Focals::Scales(scales.clone().unwrap_or_else(|| DEFAULT_SCALES.to_vec())),
        };
        let (option, values) = match &focals {
            Focals::List(list) => (crate::Field::FocalList, list),
            Focals::Scales(scales) => (crate::Field::ZoomRange, scales),
        };
        if values.is_empty() {
            return Err(ArgError::Invalid(crate::Error::param(option, "no target given")));
        }
        for &v in values {
            crate::job::cyclopean::check_scale(option, Some(v))?;
        }
        Ok(focals)
    }

    /// The break rule, checked.
    fn rule(&self) -> Result<BreakRule, ArgError> {
        let rule = BreakRule {
            tau_rel: self.tau_rel,
            tau_abs: self.tau_abs,
        };
        rule.validate()?;
        Ok(rule)
    }

    /// Outputs and file formats, checked.
    pub fn files(&self) -> Result<FileFormats, ArgError> {
        crate::job::file_formats(&FileOptions {
            outputs: self.outputs.unwrap_or_default(),
            rgb: self.rgb_format,
            depth: self.depth_format.as_deref().unwrap_or(DEFAULT_DEPTH_FORMAT),
            depth_png_scale: self.depth_png_scale,
            depth_preview: self.depth_preview,
            png_compression: &self.png_compression,
            exr_compression: &self.exr_compression,
        })
    }

    /// The settings of one frame, checked; batch-only settings given are refused by name.
    pub fn frame(&self) -> Result<FramePlan, ArgError> {
        let focals = self.focals()?;
        if self.shard.is_some() {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::Shard,
                crate::msg![
                    "applies with ",
                    crate::Field::Batch,
                    " only (it picks the manifest rows a run takes)"
                ],
            )));
        }
        if self.verify {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::Verify,
                crate::msg![
                    "applies with ",
                    crate::Field::Batch,
                    " only (it checks finished frames before a resume skips them)"
                ],
            )));
        }
        // One frame draws its random scales from the seed alone (a batch adds each frame's name).
        if let Some(z) = self.zoom_random()? {
            if self.focal_list.is_some() {
                return Err(ArgError::Invalid(crate::Error::param(
                    crate::Field::ZoomRandom,
                    crate::msg![
                        "give target focal lengths (",
                        crate::Field::FocalList,
                        ") or a random range, not both"
                    ],
                )));
            }
            let scales = z.scales("");
            let plan = RefocusRequest {
                scales: Some(scales.clone()),
                zoom_random: None,
                samples: None,
                seed: None,
                ..self.clone()
            }
            .frame()?;
            return Ok(FramePlan {
                tags: ZoomRandom::tags(&scales),
                ..plan
            });
        }
        let rule = self.rule()?;
        if let Some((w, h)) = self.size {
            io::check_output_pixels(crate::msg![crate::Field::WidthOut, "/", crate::Field::HeightOut], w, h)?;
        }
        if let Some(m) = self.depth_trunc {
            io::check_depth_trunc(m)?;
        }
        // Files are named by the focal given with --focal-list, else by the zoom scale.
        let tags = match &focals {
            Focals::List(list) => TargetSpec::focal_tags(list)?,
            Focals::Scales(scales) => scales.iter().map(|&s| manifest::scale_tag(s)).collect(),
        };
        Ok(FramePlan {
            focals,
            tags,
            size: self.size,
            principal: self.principal,
            rule,
            method: self.method,
            files: self.files()?,
            depth_trunc: self.depth_trunc,
            rgb_everywhere: self.rgb_everywhere,
        })
    }

    /// `zoom_random`, `samples` and `seed`, checked together.
    fn zoom_random(&self) -> Result<Option<ZoomRandom>, ArgError> {
        let Some((lo, hi)) = self.zoom_random else {
            if self.samples.is_some() || self.seed.is_some() {
                return Err(ArgError::Invalid(crate::Error::param(
                    crate::msg![crate::Field::Samples, "/", crate::Field::Seed],
                    crate::msg!["apply with ", crate::Field::ZoomRandom, " LO,HI only"],
                )));
            }
            return Ok(None);
        };
        if self.scales.is_some() {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::ZoomRandom,
                crate::msg![
                    "give fixed scales (",
                    crate::Field::ZoomRange,
                    ") or a random range, not both"
                ],
            )));
        }
        Ok(Some(ZoomRandom::new(
            lo,
            hi,
            self.samples.unwrap_or(1),
            self.seed.unwrap_or(0),
        )?))
    }

    /// The settings of a batch, checked: per-frame settings given are refused by name.
    pub fn batch(&self, conv: Conventions) -> Result<BatchOptions, ArgError> {
        let zoom_random = self.zoom_random()?;
        let Focals::Scales(scales) = self.focals()? else {
            return Err(ArgError::PerFrameInBatch(PerFrameOption::FocalList));
        };
        let jobs = crate::job::pool_threads(self.jobs)?;
        let shard: Option<Shard> = self.shard.as_deref().map(str::parse).transpose()?;
        Ok(BatchOptions {
            scales,
            zoom_random,
            rgb_everywhere: self.rgb_everywhere,
            size: self.size,
            principal: self.principal,
            rule: self.rule()?,
            method: self.method,
            conv,
            files: self.files()?,
            depth_trunc: self.depth_trunc,
            resume: self.resume,
            verify: self.verify,
            jobs,
            shard,
            index: true,
        })
    }
}

impl FramePlan {
    /// Each target's focal scale and camera, for a source seen by `camera`.
    pub fn targets(&self, camera: &PinholeCamera) -> crate::Result<(Vec<f64>, Vec<PinholeCamera>)> {
        let scales = match &self.focals {
            Focals::List(list) => TargetSpec::scales_from_focal_list(&camera.k, list),
            Focals::Scales(scales) => scales.clone(),
        };
        let spec = TargetSpec {
            scales: scales.clone(),
            size: self.size,
            principal: self.principal,
        };
        Ok((scales, spec.targets(camera)?))
    }
}
