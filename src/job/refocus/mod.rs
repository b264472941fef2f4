//! `refocus`: one RGB-D frame re-rendered at other focal lengths (same pose), or every frame of
//! a manifest (`--batch`). The options become a [`RefocusJob`] or [`RefocusBatchJob`], checked
//! whole before a file is read; running one writes every target and the manifest, or nothing.

mod request;

pub use request::{FramePlan, RefocusRequest, DEFAULT_DEPTH_FORMAT};

use super::error::InContext;
use super::error::OptionsContext;
use super::{ArgError, Backend, Event, GpuRequest, Host, JobError, PerFrameOption, SourceIntrinsics};
use crate::convention::Conventions;
use crate::io::{self, DepthDecode, DepthSummary};
use crate::refocus::batch::{is_index_name, load_manifest_with_defaults, run_batch, BatchOptions, BatchSummary, Shard};
use crate::refocus::manifest::{self as job, Manifest};
use crate::refocus::{RefocusSource, Refocuser};
use std::path::PathBuf;

/// What to check when a refocus input's depth summary looks wrong.
fn depth_hint() -> crate::Message {
    crate::msg![
        "check ",
        crate::Field::DepthScale,
        " (raw units per metre: 5000 TUM, 1000 SUN RGB-D with ",
        crate::Field::SunBitRotate,
        ") and that the file holds metric depth, not disparity"
    ]
}

/// The refocus options as given (one frame, or a batch with `manifest`): the files, how to
/// decode them, the source intrinsics and the request.
#[derive(Debug, Clone)]
pub struct RefocusOptions {
    /// Source colour (one frame).
    pub rgb: Option<PathBuf>,
    /// Source view-space depth (one frame).
    pub depth: Option<PathBuf>,
    /// A CSV/JSON manifest of frames instead of one frame.
    pub manifest: Option<PathBuf>,
    /// How integer (and, when given, float) depth is decoded.
    pub decode: DepthDecode,
    /// The `.npz` array to read.
    pub npz_key: Option<String>,
    /// `--intrinsics FILE`.
    pub intrinsics_file: Option<PathBuf>,
    /// `--fx --fy --cx --cy`.
    pub intrinsics: [Option<f64>; 4],
    /// Every setting the Python binding gives too.
    pub request: RefocusRequest,
    /// NDC range, reversed-Z, row order.
    pub conventions: Conventions,
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
    intrinsics: SourceIntrinsics,
    plan: FramePlan,
    conventions: Conventions,
    out_dir: PathBuf,
    gpu: GpuRequest,
    backend: Backend,
}

/// A manifest of frames to refocus, every option checked.
#[derive(Debug)]
pub struct RefocusBatchJob {
    manifest: PathBuf,
    /// `--fx`, `--fy`, `--cx`, `--cy` (over `--intrinsics`): the values of rows that lack them.
    intrinsics: [Option<f64>; 4],
    /// `--depth-scale`: the scale of frames whose manifest row gives none.
    depth_scale: Option<f64>,
    options: BatchOptions,
    out_dir: PathBuf,
    gpu: GpuRequest,
    backend: Backend,
}

impl RefocusCommand {
    /// Checks the options against each other and the library's rules.
    pub fn new(o: RefocusOptions) -> Result<Self, ArgError> {
        o.gpu.check_backend(o.backend)?;
        super::cyclopean::check_scale(crate::Field::DepthScale, o.decode.scale)?;
        if let Some(manifest) = o.manifest.clone() {
            return RefocusBatchJob::new(manifest, o).map(RefocusCommand::Batch);
        }
        let plan = o.request.frame()?;
        // clap requires both without --batch.
        let (Some(rgb), Some(depth)) = (o.rgb.clone(), o.depth.clone()) else {
            return Err(ArgError::PerFrameInput);
        };
        super::check_npz_key(o.npz_key.as_deref(), &[&depth])?;
        let intrinsics = SourceIntrinsics::resolve(o.intrinsics_file.as_deref(), o.intrinsics)?;
        // Every target's files start with its tag; the manifest goes last.
        let writes =
            |name: &str| name == io::MANIFEST_NAME || plan.tags.iter().any(|t| name.starts_with(&format!("{t}_")));
        let mut inputs = vec![
            (crate::Field::Rgb.into(), rgb.as_path()),
            (crate::Field::Depth.into(), depth.as_path()),
        ];
        inputs.extend(
            o.intrinsics_file
                .as_deref()
                .map(|p| (crate::Field::Intrinsics.into(), p)),
        );
        crate::output::check_out_dir(&o.out_dir, writes, &job::replaced(), &inputs).map_err(ArgError::Invalid)?;
        Ok(RefocusCommand::Frame(RefocusJob {
            rgb,
            depth,
            decode: o.decode,
            npz_key: o.npz_key,
            intrinsics,
            plan,
            conventions: o.conventions,
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
            hint: &depth_hint(),
        });
        if let Some(limit_m) = self.plan.depth_trunc {
            let pixels = io::truncate_depth(&mut depth, limit_m)?;
            host.event(Event::DepthTruncated { limit_m, pixels });
        }
        let k = self.intrinsics.k;
        let src = RefocusSource::new(rgb, depth, k)
            .within(|| format!("{} and {}", self.rgb.display(), self.depth.display()))?;
        let (scales, targets) = self.plan.targets(&src.camera())?;
        let out_dir = io::OutDir::prepare(&self.out_dir)?;

        let (plan, conv) = (&self.plan, self.conventions);
        let files = &plan.files;
        let device = host.open_device(&self.gpu, self.backend)?;
        let mut refocuser = Refocuser::new(&device, &src, &plan.rule, plan.method, files.outputs, conv)?;
        refocuser.set_rgb_everywhere(plan.rgb_everywhere);
        host.event(Event::Started {
            what: "refocus targets",
            total: targets.len() as u64,
        });
        // All targets and the manifest, or (on any failure) none: earlier runs' files stay.
        // The previous run's set, as its manifest lists it, goes where this one does not
        // write the same names (fewer scales, no depth): the folder holds this run's set.
        let set = out_dir.file_set()?.replacing(job::replaced());
        let mut manifest = Manifest::of_frame(
            src.camera(),
            plan.method,
            plan.rule,
            conv,
            refocuser.renderer(),
            plan.rgb_everywhere,
            None,
        );
        manifest.inputs = Some(job::FrameInputs {
            rgb: self.rgb.to_string_lossy().into_owned(),
            depth: self.depth.to_string_lossy().into_owned(),
            depth_scale: self.decode.scale,
            sun_bit_rotate: self.decode.sun_rgbd_bit_rotate,
        });
        let targets = scales
            .iter()
            .zip(&targets)
            .zip(&plan.tags)
            .map(|((scale, target), tag)| {
                let out = refocuser.render(target)?;
                Ok((tag.clone(), *scale, out))
            });
        let manifest = job::write_frame(set, manifest, targets, files, || host.event(Event::Advanced), || Ok(()))?;
        host.event(Event::Finished);
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
        // --intrinsics FILE and --fx/--fy/--cx/--cy (laid over the file) are the defaults of
        // rows that lack them, as --depth-scale is.
        let stored = match o.intrinsics_file.as_deref() {
            Some(p) => Some(
                crate::camera::IntrinsicsFile::load(p)
                    .for_options(crate::Field::Intrinsics)?
                    .k,
            ),
            None => None,
        };
        let [fx, fy, cx, cy] = o.intrinsics;
        let intrinsics = [
            fx.or(stored.map(|k| k.fx)),
            fy.or(stored.map(|k| k.fy)),
            cx.or(stored.map(|k| k.cx)),
            cy.or(stored.map(|k| k.cy)),
        ];
        // A flag the batch cannot apply is refused, never ignored.
        if o.decode.sun_rgbd_bit_rotate {
            return Err(ArgError::PerFrameInBatch(PerFrameOption::SunBitRotate));
        }
        if o.npz_key.is_some() {
            return Err(ArgError::PerFrameInBatch(PerFrameOption::NpzKey));
        }
        Ok(RefocusBatchJob {
            manifest,
            intrinsics,
            depth_scale: o.decode.scale,
            options: o.request.batch(o.conventions)?,
            out_dir: o.out_dir,
            gpu: o.gpu,
            backend: o.backend,
        })
    }

    /// Refuses, before any frame is rendered, a batch whose files would replace one of its
    /// inputs: the manifest under an index name in --out-dir, or a frame's colour or depth
    /// under a name its folder `<out-dir>/<name>/` gets (by identity, as for one frame).
    fn check_outputs(&self, frames: &[crate::refocus::batch::BatchFrame]) -> Result<(), JobError> {
        // The index's own names are written and (those of other runs) removed at the root.
        let index = is_index_name;
        crate::output::check_out_dir(
            &self.out_dir,
            index,
            &io::Replaces::Owned(index),
            &[(crate::Field::Batch.into(), self.manifest.as_path())],
        )
        .map_err(ArgError::Invalid)?;
        for frame in frames {
            let name = frame.name.as_deref().unwrap_or_default();
            let (_, tags) = self.options.frame_targets(name);
            let writes = |n: &str| n == io::MANIFEST_NAME || tags.iter().any(|t| n.starts_with(&format!("{t}_")));
            let inputs = [
                (crate::msg![crate::Field::Batch, " rgb"], frame.rgb.as_path()),
                (crate::msg![crate::Field::Batch, " depth"], frame.depth.as_path()),
            ];
            crate::output::check_out_dir(&self.out_dir.join(name), writes, &job::replaced(), &inputs)
                .map_err(ArgError::Invalid)?;
        }
        Ok(())
    }

    /// Refocuses every frame (of this shard) into `<out-dir>/<name>/`, skipping those finished
    /// with the same settings unless forced; a failed frame is reported, the others complete.
    pub fn run(&self, host: &dyn Host) -> Result<RefocusBatchReport, JobError> {
        let mut frames = load_manifest_with_defaults(&self.manifest, self.intrinsics)?;
        // --depth-scale is the scale of every frame whose row gives none (a row's own wins).
        if let Some(scale) = self.depth_scale {
            for f in frames.iter_mut().filter(|f| f.depth_scale.is_none()) {
                f.depth_scale = Some(scale);
            }
        }
        self.check_outputs(&frames)?;
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
    use super::{ArgError, RefocusCommand, RefocusOptions, RefocusRequest};
    use crate::job::PerFrameOption;

    fn frame() -> RefocusOptions {
        RefocusOptions {
            rgb: Some("c.png".into()),
            depth: Some("d.exr".into()),
            manifest: None,
            decode: Default::default(),
            npz_key: None,
            intrinsics_file: None,
            intrinsics: [Some(525.0), Some(525.0), Some(319.5), Some(239.5)],
            request: RefocusRequest {
                scales: Some(vec![0.5, 2.0]),
                ..Default::default()
            },
            conventions: Default::default(),
            out_dir: "out".into(),
            gpu: Default::default(),
            backend: Default::default(),
        }
    }

    /// `base` with its request changed by `change`.
    fn with(base: RefocusOptions, change: impl FnOnce(&mut RefocusRequest)) -> RefocusOptions {
        let mut o = base;
        change(&mut o.request);
        o
    }

    #[test]
    fn one_frame_is_checked_whole_before_any_file_is_read() {
        assert!(matches!(RefocusCommand::new(frame()), Ok(RefocusCommand::Frame(_))));
        let e = RefocusCommand::new(with(frame(), |r| r.tau_rel = -1.0)).unwrap_err();
        assert!(e.to_string().contains("tau"), "{e}");
        let e = RefocusCommand::new(with(frame(), |r| r.depth_trunc = Some(0.0))).unwrap_err();
        assert!(e.to_string().contains("depth-trunc"), "{e}");
        let e = RefocusCommand::new(with(frame(), |r| r.shard = Some("1/2".into()))).unwrap_err();
        assert!(e.to_string().contains("--shard"), "{e}");
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
        // --fx and the others are the defaults of rows lacking them (issue 44), not refused.
        let with_k = RefocusOptions {
            intrinsics: [Some(1.0), None, None, None],
            ..batch.clone()
        };
        assert!(matches!(
            RefocusCommand::new(with_k),
            Ok(RefocusCommand::Batch(b)) if b.intrinsics == [Some(1.0), None, None, None]
        ));
        let focal_list = with(batch.clone(), |r| (r.scales, r.focal_list) = (None, Some(vec![500.0])));
        assert!(matches!(
            RefocusCommand::new(focal_list),
            Err(ArgError::PerFrameInBatch(PerFrameOption::FocalList))
        ));
        let threads = with(batch, |r| r.jobs = Some(crate::refocus::batch::MAX_JOBS + 1));
        assert!(matches!(
            RefocusCommand::new(threads),
            Err(ArgError::TooManyJobs { .. })
        ));
    }
}
