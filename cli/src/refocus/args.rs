//! `viewsynth refocus` options and their conversion into a checked library job.

use crate::options::{BackendArg, ConventionArgs, FileOutputArgs, GpuArgs, IntrinsicsArgs};
use crate::options::{BATCH, GPU, INPUTS, METHOD, OUTPUTS, TARGETS};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use viewsynth::io::{self, DepthDecode};
use viewsynth::job::refocus::{RefocusCommand, RefocusOptions, RefocusRequest};
use viewsynth::job::{finite_or_inf, finite_value, shard_value, ArgError};
use viewsynth::refocus::{BreakRule, Method};

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum MethodArg {
    Mesh,
    Fullscreen,
}

/// The example under `viewsynth refocus --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  # TUM RGB-D frame at five focal scales (s0.5_rgb.png ... s2_mask.png, manifest.json)
  viewsynth refocus --rgb ../shared/data/rgbd_open3d_testdata/TUM_color.png \\
      --depth ../shared/data/rgbd_open3d_testdata/TUM_depth.png --depth-scale 5000 \\
      --fx 525 --fy 525 --cx 319.5 --cy 239.5 --zoom-range 0.5,0.75,1,1.5,2 --out-dir out/tum
  # every frame of a manifest (CSV: rgb,depth,fx,fy,cx,cy[,depth_scale,name]), one shard of four;
  # --depth-scale for the rows that give no depth_scale
  viewsynth refocus --batch frames.csv --depth-scale 5000 --zoom-range 0.5,2 --shard 0/4 --out-dir out/batch";

#[derive(Args)]
pub(crate) struct RefocusArgs {
    /// Source colour (PNG, JPEG, PPM, EXR).
    #[arg(help_heading = INPUTS, long, required_unless_present = "batch")]
    rgb: Option<PathBuf>,
    /// Source metric depth, view-space Z (EXR, NPY/NPZ f32/f64/u16, 16-bit PNG/PGM with --depth-scale, PFM).
    #[arg(help_heading = INPUTS, long, required_unless_present = "batch")]
    depth: Option<PathBuf>,
    /// Raw units per metre for integer depth: 5000 for TUM, 1000 for SUN RGB-D (with
    /// --sun-bit-rotate) and millimetre PNGs.
    ///
    /// Divides float depth too when given. (NYU v2 raw PGM holds Kinect disparity, not depth: no
    /// scale fits; convert it first.) With --batch: the scale of every frame whose manifest row
    /// gives no depth_scale.
    #[arg(help_heading = INPUTS, long, value_parser = finite_value)]
    depth_scale: Option<f64>,
    /// Array of an .npz depth file to read (default: the only array, else the first
    /// floating-point one).
    #[arg(help_heading = INPUTS, long, value_name = "NAME")]
    npz_key: Option<String>,
    /// Treat input depth beyond M metres as invalid (as Open3D's depth_trunc), after
    /// --depth-scale.
    #[arg(help_heading = INPUTS, long, value_name = "M", value_parser = finite_value)]
    depth_trunc: Option<f64>,
    /// SUN RGB-D PNG depth: rotate the 16-bit value right by 3 bits before scaling.
    #[arg(help_heading = INPUTS, long)]
    sun_bit_rotate: bool,
    #[command(flatten)]
    intrinsics: IntrinsicsArgs,
    /// Target focal lengths fx' in pixels (fy' keeps the source fy/fx); files are named by
    /// them, e.g. f571.4_rgb.png.
    #[arg(help_heading = TARGETS, long, value_delimiter = ',', conflicts_with = "zoom_range", value_parser = finite_value)]
    focal_list: Option<Vec<f64>>,
    /// Target focal scales s (fx' = s fx) [default: 0.5,0.75,1,1.5,2].
    #[arg(help_heading = TARGETS, long, value_delimiter = ',', value_parser = finite_value)]
    zoom_range: Option<Vec<f64>>,
    /// K random focal scales per frame in [LO, HI] (log-uniform: zooming in and out equally
    /// often), drawn from --seed and, with --batch, the frame's name, so reruns, resumed and
    /// sharded runs draw the same; files z{k}_s{s}_*, scales recorded in each frame's manifest.
    #[arg(help_heading = TARGETS, long, value_name = "LO,HI", value_delimiter = ',', conflicts_with_all = ["zoom_range", "focal_list"], value_parser = finite_value)]
    zoom_random: Option<Vec<f64>>,
    /// With --zoom-random: scales drawn per frame [default: 1]; at most the distinct file tags
    /// (6 decimals) the range holds.
    #[arg(help_heading = TARGETS, long, value_name = "K", requires = "zoom_random", value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=viewsynth::refocus::batch::MAX_SAMPLES as u64))]
    samples: Option<usize>,
    /// With --zoom-random: the seed [default: 0].
    #[arg(help_heading = TARGETS, long, value_name = "S", requires = "zoom_random")]
    seed: Option<u64>,
    /// Output width in pixels (default: the source's; with --height-out).
    #[arg(help_heading = TARGETS, long, requires = "height_out", value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    width_out: Option<u32>,
    /// Output height in pixels (default: the source's; with --width-out).
    #[arg(help_heading = TARGETS, long, requires = "width_out", value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    height_out: Option<u32>,
    /// Output principal point x in pixels (default: the source's offset from the image centre:
    /// cx' = cx + (W' - W) / 2; with --cy-out).
    #[arg(help_heading = TARGETS, long, requires = "cy_out", value_parser = finite_value)]
    cx_out: Option<f64>,
    /// Output principal point y in pixels (default: cy' = cy + (H' - H) / 2; with --cx-out).
    #[arg(help_heading = TARGETS, long, requires = "cx_out", value_parser = finite_value)]
    cy_out: Option<f64>,
    /// Break an edge when |za - zb| > tau_rel * min(za, zb).
    #[arg(help_heading = METHOD, long, default_value_t = BreakRule::default().tau_rel, value_parser = finite_value)]
    tau_rel: f64,
    /// Break an edge when |za - zb| > tau_abs (metres; "inf" disables).
    #[arg(help_heading = METHOD, long, default_value_t = BreakRule::default().tau_abs, value_parser = finite_or_inf)]
    tau_abs: f64,
    /// GPU path: fullscreen (one full-screen pass evaluating the kept triangles analytically; the
    /// default) or mesh (the triangles rasterised); both give the same output.
    #[arg(help_heading = METHOD, long, value_enum, default_value = "fullscreen")]
    method: MethodArg,
    /// Colour every output pixel inside the source frame, bilinear from the source whatever its
    /// depth (same pose: where a pixel lands does not depend on it); depth and mask unchanged,
    /// valid geometry only. For training images without black holes at depth gaps and edges.
    #[arg(help_heading = METHOD, long)]
    rgb_everywhere: bool,
    /// Output folder (created if missing): per zoom scale s, s{s}_rgb.png (s{s}_rgb.jpg, s{s}_rgb.exr
    /// with --rgb-format), s{s}_depth.exr, s{s}_depth.npy, s{s}_depth.png (those in --depth-format),
    /// s{s}_depth_preview.png (--depth-preview), s{s}_mask.png (those in --outputs; f{fx'}_rgb.png
    /// etc. with --focal-list), and manifest.json.
    #[arg(help_heading = OUTPUTS, long)]
    out_dir: PathBuf,
    #[command(flatten)]
    files: FileOutputArgs,
    /// Refocus every frame of a manifest into <out-dir>/<name>/, with one GL context, files encoded
    /// on writer threads, and resume.
    ///
    /// CSV with a header row rgb,depth,fx,fy,cx,cy and optional depth_scale,name columns, or a JSON
    /// array of objects with those keys (and sun_bit_rotate); relative paths are relative to the
    /// manifest. --fx/--fy/--cx/--cy, --intrinsics and --depth-scale give the values of rows that
    /// lack them.
    #[arg(help_heading = BATCH, long, conflicts_with_all = ["rgb", "depth"])]
    batch: Option<PathBuf>,
    /// With --batch: render every frame again, even those finished with the same settings.
    #[arg(help_heading = BATCH, long, alias = "no-resume")]
    force: bool,
    /// With --batch: also check, before skipping a finished frame, the CRC-32 of each of its
    /// files and the content of its inputs. By default a finished frame costs a read of its
    /// manifest.json and a stat of each input and file (the commit journal makes a set
    /// all-or-none); inputs are recognised by size and mtime, or by content when the mtime
    /// differs, whatever the path's spelling.
    #[arg(help_heading = BATCH, long, conflicts_with = "force")]
    verify: bool,
    /// With --batch: threads in each CPU pool (decoding inputs, encoding files) around the GL
    /// thread; 0 runs every stage in turn on one thread.
    ///
    /// Default: the number of cores.
    #[arg(help_heading = BATCH, long, alias = "writer-threads", value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=viewsynth::refocus::batch::MAX_JOBS as u64))]
    jobs: Option<usize>,
    /// With --batch: process only shard K of N (frames whose manifest index i has i % N == K,
    /// K from 0), e.g. one Slurm array task or Kubernetes indexed Job per shard.
    #[arg(help_heading = BATCH, long, value_name = "K/N", value_parser = shard_value)]
    shard: Option<String>,
    #[command(flatten)]
    conv: ConventionArgs,
    #[command(flatten)]
    gpu: GpuArgs,
    /// Rendering API: gl, or vulkan (the same shaders as SPIR-V on a Vulkan device, --device
    /// an index of `viewsynth info --backend vulkan`; single frames and --batch alike).
    #[arg(help_heading = GPU, long, value_enum, default_value = "gl")]
    backend: BackendArg,
}

impl RefocusArgs {
    /// The settings the Python binding gives too, as the library's request.
    pub(crate) fn request(&self) -> Result<RefocusRequest, ArgError> {
        let mut r = RefocusRequest {
            scales: self.zoom_range.clone(),
            focal_list: self.focal_list.clone(),
            size: self.width_out.zip(self.height_out),
            principal: self.cx_out.zip(self.cy_out),
            tau_rel: self.tau_rel,
            tau_abs: self.tau_abs,
            method: match self.method {
                MethodArg::Mesh => Method::Mesh,
                MethodArg::Fullscreen => Method::Fullscreen,
            },
            depth_trunc: self.depth_trunc,
            resume: !self.force,
            verify: self.verify,
            jobs: self.jobs,
            shard: self.shard.clone(),
            rgb_everywhere: self.rgb_everywhere,
            zoom_random: match self.zoom_random.as_deref() {
                None => None,
                Some(&[lo, hi]) => Some((lo, hi)),
                Some(other) => {
                    return Err(ArgError::Invalid(viewsynth::Error::param(
                        "--zoom-random",
                        format!("{} values given: expected LO,HI", other.len()),
                    )))
                }
            },
            samples: self.samples,
            seed: self.seed,
            ..Default::default()
        };
        self.files.fill_refocus(&mut r)?;
        Ok(r)
    }
}

impl TryFrom<RefocusArgs> for RefocusCommand {
    type Error = ArgError;
    fn try_from(a: RefocusArgs) -> Result<Self, ArgError> {
        let request = a.request()?;
        RefocusCommand::new(RefocusOptions {
            rgb: a.rgb,
            depth: a.depth,
            manifest: a.batch,
            decode: DepthDecode {
                scale: a.depth_scale,
                sun_rgbd_bit_rotate: a.sun_bit_rotate,
                ..Default::default()
            },
            npz_key: a.npz_key,
            intrinsics_file: a.intrinsics.intrinsics.clone(),
            intrinsics: a.intrinsics.values(),
            request,
            conventions: a.conv.into(),
            out_dir: a.out_dir,
            gpu: a.gpu.try_into()?,
            backend: a.backend.into(),
        })
    }
}
