//! `refocus`: one RGB-D frame re-rendered at other focal lengths (same pose), or every frame of
//! a manifest (`--batch`). The options become a [`RefocusJob`] or [`RefocusBatchJob`], checked
//! whole before a file is read; running one writes every target and the manifest, or nothing.

use super::error::InContext;
use super::{ArgError, Backend, Event, GpuRequest, Host, JobError, PerFrameOption, SourceIntrinsics};
use crate::convention::Conventions;
use crate::io::FileFormats;
use crate::io::{self, DepthDecode, DepthSummary};
use crate::refocus::batch::{load_manifest, run_batch, BatchOptions, BatchSummary, Shard};
use crate::refocus::manifest::{self as job, Manifest, ManifestEntry, TargetSpec};
use crate::refocus::{BreakRule, Method, RefocusSource, Refocuser};
use std::path::PathBuf;

/// What to check when a refocus input's depth summary looks wrong.
const DEPTH_HINT: &str = "check --depth-scale (raw units per metre: 5000 TUM, 1000 SUN RGB-D with --sun-bit-rotate) \
     and that the file holds metric depth, not disparity";

/// How the target focal lengths are given.
#[derive(Debug, Clone, PartialEq)]
pub enum Focals {
    /// Focal scales s, fx' = s fx (`--zoom-range`); files named `s{s}_...`.
    Scales(Vec<f64>),
    /// Absolute fx' in pixels, fy' keeping fy/fx (`--focal-list`); files named `f{fx'}_...`.
    List(Vec<f64>),
}

/// The refocus options as given (one frame, or a batch with `manifest`).
#[derive(Debug, Clone)]
pub struct RefocusOptions {
    /// Source colour (one frame).
    pub rgb: Option<PathBuf>,
    /// Source view-space depth (one frame).
    pub depth: Option<PathBuf>,
    /// A CSV/JSON manifest of frames instead of one frame.
    pub manifest: Option<PathBuf>,
    /// Batch: render finished frames again.
    pub force: bool,
    /// Batch: threads per CPU pool (None: the number of cores).
    pub jobs: Option<usize>,
    /// Batch: `K/N`.
    pub shard: Option<String>,
    /// How integer (and, when given, float) depth is decoded.
    pub decode: DepthDecode,
    /// The `.npz` array to read.
    pub npz_key: Option<String>,
    /// Depth beyond this many metres is a hole.
    pub depth_trunc: Option<f64>,
    /// `--intrinsics FILE`.
    pub intrinsics_file: Option<PathBuf>,
    /// `--fx --fy --cx --cy`.
    pub intrinsics: [Option<f64>; 4],
    /// Target focal lengths.
    pub focals: Focals,
    /// Output size.
    pub size: Option<(u32, u32)>,
    /// Output principal point.
    pub principal: Option<(f64, f64)>,
    /// Edge breaking.
    pub rule: BreakRule,
    /// GPU path.
    pub method: Method,
    /// NDC range, reversed-Z, row order.
    pub conventions: Conventions,
    /// What to write, how (already checked: [`super::file_formats`]).
    pub files: FileFormats,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The GPU to render on.
    pub gpu: GpuRequest,
    /// GL or Vulkan.
    pub backend: Backend,
}

/// A checked refocus command: one frame or a batch.
#[derive(Debug)]
pub enum RefocusCommand {
    /// One frame.
    Frame(RefocusJob),
    /// Every frame of a manifest.
    Batch(RefocusBatchJob),
}

/// One frame to refocus, every option checked.
#[derive(Debug)]
pub struct RefocusJob {
    rgb: PathBuf,
    depth: PathBuf,
    decode: DepthDecode,
    npz_key: Option<String>,
    depth_trunc: Option<f64>,
    intrinsics: SourceIntrinsics,
    focals: Focals,
    /// File-name tag of each target, in order.
    tags: Vec<String>,
    size: Option<(u32, u32)>,
    principal: Option<(f64, f64)>,
    rule: BreakRule,
    method: Method,
    conventions: Conventions,
    files: FileFormats,
    out_dir: PathBuf,
    gpu: GpuRequest,
    backend: Backend,
}

/// A manifest of frames to refocus, every option checked.
#[derive(Debug)]
pub struct RefocusBatchJob {
    manifest: PathBuf,
    options: BatchOptions,
    out_dir: PathBuf,
    gpu: GpuRequest,
    backend: Backend,
}

impl RefocusCommand {
    /// Checks the options against each other and the library's rules.
    pub fn new(o: RefocusOptions) -> Result<Self, ArgError> {
        super::cyclopean::check_scale("--depth-scale", o.decode.scale)?;
        let (option, values) = match &o.focals {
            Focals::List(list) => ("--focal-list", list),
            Focals::Scales(scales) => ("--zoom-range", scales),
        };
        for &v in values {
            super::cyclopean::check_scale(option, Some(v))?;
        }
        if let Some(manifest) = o.manifest.clone() {
            return RefocusBatchJob::new(manifest, o).map(RefocusCommand::Batch);
        }
        // Batch-only options are refused by name rather than ignored.
        if o.shard.is_some() {
            return Err(ArgError::Invalid(crate::Error::param(
                "--shard",
                "applies with --batch only (it picks the manifest rows a run takes)",
            )));
        }
        // clap requires both without --batch.
        let (Some(rgb), Some(depth)) = (o.rgb.clone(), o.depth.clone()) else {
            return Err(ArgError::PerFrameInput);
        };
        super::check_npz_key(o.npz_key.as_deref(), &[&depth])?;
        let intrinsics = SourceIntrinsics::resolve(o.intrinsics_file.as_deref(), o.intrinsics)?;
        o.rule.validate()?;
        if let Some((w, h)) = o.size {
            io::check_output_pixels("--width-out/--height-out", w, h)?;
        }
        if let Some(m) = o.depth_trunc {
            io::check_depth_trunc(m)?;
        }
        // Files are named by the focal given with --focal-list, else by the zoom scale.
        let tags = match &o.focals {
            Focals::List(list) => TargetSpec::focal_tags(list)?,
            Focals::Scales(scales) => scales.iter().map(|&s| job::scale_tag(s)).collect(),
        };
        Ok(RefocusCommand::Frame(RefocusJob {
            rgb,
            depth,
            decode: o.decode,
            npz_key: o.npz_key,
            depth_trunc: o.depth_trunc,
            intrinsics,
            focals: o.focals,
            tags,
            size: o.size,
            principal: o.principal,
            rule: o.rule,
            method: o.method,
            conventions: o.conventions,
            files: o.files,
            out_dir: o.out_dir,
            gpu: o.gpu,
            backend: o.backend,
        }))
    }
}

/// What a refocused frame wrote.
#[derive(Debug)]
pub struct RefocusReport {
    /// The manifest written (targets in order).
    pub manifest: Manifest,
    /// Where it is.
    pub manifest_path: PathBuf,
}

impl RefocusJob {
    /// Reads and checks the frame, renders every target and writes the files and the manifest
    /// all-or-none (an earlier run's files stay when anything fails).
    pub fn run(&self, host: &dyn Host) -> Result<RefocusReport, JobError> {
        // Sizes and the pixel budget from the headers before either file is decoded.
        io::check_rgbd_sizes(&self.rgb, &self.depth)?;
        let rgb = io::load_rgb(&self.rgb)?;
        let mut depth = io::load_depth_with_key(&self.depth, self.npz_key.as_deref(), &self.decode)?;
        self.intrinsics.check_size(rgb.width, rgb.height)?;
        host.event(Event::InputDepth {
            path: &self.depth,
            summary: &DepthSummary::of(&depth),
            hint: DEPTH_HINT,
        });
        if let Some(limit_m) = self.depth_trunc {
            let pixels = io::truncate_depth(&mut depth, limit_m)?;
            host.event(Event::DepthTruncated { limit_m, pixels });
        }
        let k = self.intrinsics.k;
        let src = RefocusSource::new(rgb, depth, k)
            .within(|| format!("{} and {}", self.rgb.display(), self.depth.display()))?;
        let scales = match &self.focals {
            Focals::List(list) => TargetSpec::scales_from_focal_list(&k, list),
            Focals::Scales(scales) => scales.clone(),
        };
        let spec = TargetSpec {
            scales: scales.clone(),
            size: self.size,
            principal: self.principal,
        };
        let targets = spec.targets(&src.camera())?;
        let out_dir = io::OutDir::prepare(&self.out_dir)?;

        let (files, conv) = (&self.files, self.conventions);
        let device = host.open_device(&self.gpu, self.backend)?;
        let mut refocuser = Refocuser::new(&device, &src, &self.rule, self.method, files.outputs, conv)?;
        host.event(Event::Started {
            what: "refocus targets",
            total: targets.len() as u64,
        });
        let mut entries: Vec<ManifestEntry> = Vec::new();
        // All targets and the manifest, or (on any failure) none: earlier runs' files stay.
        let mut set = out_dir.file_set()?;
        for ((scale, target), tag) in scales.iter().zip(&targets).zip(&self.tags) {
            let out = refocuser.render(target)?;
            entries.push(job::write_target(&mut set, tag, *scale, out, files)?);
            host.event(Event::Advanced);
        }
        host.event(Event::Finished);
        let manifest = Manifest {
            tool: format!("viewsynth {}", env!("CARGO_PKG_VERSION")),
            source: src.camera(),
            method: self.method,
            break_rule: self.rule,
            conventions: conv,
            renderer: refocuser.renderer(),
            notes: job::MANIFEST_NOTES.to_string(),
            settings: None,
            files: job::file_records(set.staging(), &entries).map_err(|e| set.final_error(e))?,
            outputs: entries,
        };
        job::write_manifest(set.staging(), &manifest).map_err(|e| set.final_error(e))?;
        set.commit()?;
        Ok(RefocusReport {
            manifest,
            manifest_path: out_dir.path().join("manifest.json"),
        })
    }
}

/// What a batch did.
#[derive(Debug)]
pub struct RefocusBatchReport {
    /// Frames in the manifest.
    pub frames: usize,
    /// The shard run, if any.
    pub shard: Option<Shard>,
    /// Rendered, skipped and failed frames, timings.
    pub summary: BatchSummary,
}

impl RefocusBatchReport {
    /// An error when any frame failed (the others completed).
    pub fn outcome(&self) -> Result<(), JobError> {
        match self.summary.failed.len() {
            0 => Ok(()),
            failed => Err(JobError::FramesFailed {
                failed,
                total: self.frames,
            }),
        }
    }
}

impl RefocusBatchJob {
    fn new(manifest: PathBuf, o: RefocusOptions) -> Result<Self, ArgError> {
        if o.intrinsics_file.is_some() || o.intrinsics.iter().any(Option::is_some) {
            return Err(ArgError::PerFrameInBatch(PerFrameOption::Intrinsics));
        }
        let Focals::Scales(scales) = o.focals else {
            return Err(ArgError::PerFrameInBatch(PerFrameOption::FocalList));
        };
        let jobs = super::pool_threads(o.jobs)?;
        let shard: Option<Shard> = o.shard.as_deref().map(str::parse).transpose()?;
        o.rule.validate()?;
        Ok(RefocusBatchJob {
            manifest,
            options: BatchOptions {
                scales,
                size: o.size,
                principal: o.principal,
                rule: o.rule,
                method: o.method,
                conv: o.conventions,
                files: o.files,
                depth_trunc: o.depth_trunc,
                resume: !o.force,
                jobs,
                shard,
            },
            out_dir: o.out_dir,
            gpu: o.gpu,
            backend: o.backend,
        })
    }

    /// Refocuses every frame (of this shard) into `<out-dir>/<name>/`, skipping those finished
    /// with the same settings unless forced; a failed frame is reported, the others complete.
    pub fn run(&self, host: &dyn Host) -> Result<RefocusBatchReport, JobError> {
        let frames = load_manifest(&self.manifest)?;
        io::OutDir::prepare(&self.out_dir)?;
        let device = host.open_device(&self.gpu, self.backend)?;
        host.event(Event::Started {
            what: "batch frames",
            total: frames.len() as u64,
        });
        let summary = run_batch(&device, &frames, &self.out_dir, &self.options, || {
            host.event(Event::Advanced)
        })?;
        host.event(Event::Finished);
        Ok(RefocusBatchReport {
            frames: frames.len(),
            shard: self.options.shard,
            summary,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{ArgError, BreakRule, Focals, Method, RefocusCommand, RefocusOptions};
    use crate::job::PerFrameOption;

    fn frame() -> RefocusOptions {
        RefocusOptions {
            rgb: Some("c.png".into()),
            depth: Some("d.exr".into()),
            manifest: None,
            force: false,
            jobs: None,
            shard: None,
            decode: Default::default(),
            npz_key: None,
            depth_trunc: None,
            intrinsics_file: None,
            intrinsics: [Some(525.0), Some(525.0), Some(319.5), Some(239.5)],
            focals: Focals::Scales(vec![0.5, 2.0]),
            size: None,
            principal: None,
            rule: BreakRule::default(),
            method: Method::Fullscreen,
            conventions: Default::default(),
            files: Default::default(),
            out_dir: "out".into(),
            gpu: Default::default(),
            backend: Default::default(),
        }
    }

    #[test]
    fn one_frame_is_checked_whole_before_any_file_is_read() {
        assert!(matches!(RefocusCommand::new(frame()), Ok(RefocusCommand::Frame(_))));
        let e = RefocusCommand::new(RefocusOptions {
            rule: BreakRule {
                tau_rel: -1.0,
                ..BreakRule::default()
            },
            ..frame()
        })
        .unwrap_err();
        assert!(e.to_string().contains("tau"), "{e}");
        let e = RefocusCommand::new(RefocusOptions {
            depth_trunc: Some(0.0),
            ..frame()
        })
        .unwrap_err();
        assert!(e.to_string().contains("depth-trunc"), "{e}");
    }

    #[test]
    fn a_batch_refuses_per_frame_options_and_too_many_threads() {
        let batch = RefocusOptions {
            rgb: None,
            depth: None,
            manifest: Some("frames.csv".into()),
            intrinsics: [None; 4],
            ..frame()
        };
        assert!(matches!(
            RefocusCommand::new(batch.clone()),
            Ok(RefocusCommand::Batch(_))
        ));
        let with_k = RefocusOptions {
            intrinsics: [Some(1.0), None, None, None],
            ..batch.clone()
        };
        assert!(matches!(
            RefocusCommand::new(with_k),
            Err(ArgError::PerFrameInBatch(PerFrameOption::Intrinsics))
        ));
        let focal_list = RefocusOptions {
            focals: Focals::List(vec![500.0]),
            ..batch.clone()
        };
        assert!(matches!(
            RefocusCommand::new(focal_list),
            Err(ArgError::PerFrameInBatch(PerFrameOption::FocalList))
        ));
        let threads = RefocusOptions {
            jobs: Some(crate::refocus::batch::MAX_JOBS + 1),
            ..batch
        };
        assert!(matches!(
            RefocusCommand::new(threads),
            Err(ArgError::TooManyJobs { .. })
        ));
    }
}
