//! `viewsynth cyclopean` options and their conversion into a checked library job. Three set-ups:
//! a rectified pair with disparities (`--left-disparity/--right-disparity`), any pair with
//! depth and a camera file (`--left-depth/--right-depth --cameras`), or a rectified pair alone
//! (disparities estimated by the census matcher, `--max-disparity`).

use crate::options::{BackendArg, GpuArgs};
use crate::options::{GPU, INPUTS, INTRINSICS, METHOD, OUTPUTS, TARGETS};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use viewsynth::cyclopean::CyclopeanMethod;
use viewsynth::job::cyclopean::{CyclopeanJob, CyclopeanOptions, CyclopeanRequest, CyclopeanSequenceJob};
use viewsynth::job::{finite_value, ArgError};
use viewsynth::stereo::gather::Blend;
use viewsynth::stereo::matcher::MatcherMethod;

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum BlendArg {
    Hard,
    Soft,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum MatcherArg {
    /// Census costs averaged over a 9 x 9 box, winner takes all: precise where there is
    /// texture, unknown where there is none.
    Census,
    /// Semi-global matching of the census costs along 8 paths (coarse to fine for wide
    /// searches): smooth, so low-texture regions take the surrounding surface's disparity.
    Sgm,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum MethodArg {
    /// Splat each eye's surfaces into the view (nearest first), then refine each pixel sub-pixel
    /// on the surface it sees and merge the eyes (the best on real stereo).
    SplatGather,
    /// One step per eye: the middle ray at the fixation depth is projected into the eye, the
    /// eye's depth read there gives the surface point; the eyes' colours merge by --blend.
    Seed,
    /// The seed's step, --refine-steps refinement steps and a projection check.
    Refine,
    /// Each eye's depth mesh rendered into the view, the nearest surface wins.
    Forward,
}

/// The example under `viewsynth cyclopean --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  # the middle view of Middlebury Cones from both eyes and their disparities (stored x4)
  viewsynth cyclopean --left-rgb ../shared/data/middlebury2003_cones/im2.png \\
      --right-rgb ../shared/data/middlebury2003_cones/im6.png \\
      --left-disparity ../shared/data/middlebury2003_cones/disp2.pgm \\
      --right-disparity ../shared/data/middlebury2003_cones/disp6.pgm --disparity-scale 4 --out-dir out/cones
  # any pair with depth and a camera file (as `viewsynth scene` writes it)
  viewsynth cyclopean --left-rgb out/scene/left_rgb.png --left-depth out/scene/left_device_depth.exr \\
      --right-rgb out/scene/right_rgb.png --right-depth out/scene/right_device_depth.exr \\
      --cameras out/scene/cameras.json --out-dir out/scene_middle";

#[derive(Args)]
pub(crate) struct CyclopeanArgs {
    /// Left eye colour (PNG, JPEG, PPM, EXR), rows top-down.
    #[arg(help_heading = INPUTS, long, required_unless_present = "sequence")]
    left_rgb: Option<PathBuf>,
    /// Right eye colour.
    #[arg(help_heading = INPUTS, long, required_unless_present = "sequence")]
    right_rgb: Option<PathBuf>,
    /// A sequence of frames, rendered in order: JSON `{"frames": [{"left_rgb": ..., "right_rgb":
    /// ..., "left_depth": ..., "right_depth": ..., "cameras": ...}, ...]}` (the keys of these
    /// flags; disparities or neither as for one pair), paths relative to the file.
    ///
    /// Writes middle_00000_rgb.png, ... for frame 0 and so on, all-or-none. With --fill, holes take
    /// what earlier frames saw there (the last view moved into this frame's camera) before the fill
    /// fills the rest.
    #[arg(
        help_heading = INPUTS,
        long,
        value_name = "FILE",
        conflicts_with_all = ["left_rgb", "right_rgb", "left_disparity", "right_disparity", "left_depth", "right_depth", "cameras", "confidence"]
    )]
    sequence: Option<PathBuf>,
    /// Left disparity of a rectified pair, pixels (x_right = x_left - d); 0 or non-finite =
    /// unknown.
    ///
    /// PGM/PNG (8/16-bit), PFM, NPY or EXR.
    #[arg(help_heading = INPUTS, long, conflicts_with_all = ["left_depth", "cameras"])]
    left_disparity: Option<PathBuf>,
    /// Right disparity, pixels (x_left = x_right + d).
    #[arg(help_heading = INPUTS, long, conflicts_with_all = ["right_depth", "cameras"])]
    right_disparity: Option<PathBuf>,
    /// Raw disparity units per pixel (4 for Middlebury 2003 PGMs; default 1). Each map's
    /// summary is printed, with a warning naming the scale the two views agree with when it
    /// fits far better than this one.
    #[arg(help_heading = INPUTS, long)]
    disparity_scale: Option<f64>,
    /// Left depth: device (window) depth or view distance, as `depth_kind` in the camera file.
    #[arg(help_heading = INPUTS, long, requires = "cameras")]
    left_depth: Option<PathBuf>,
    /// Right depth, as --left-depth.
    #[arg(help_heading = INPUTS, long, requires = "cameras")]
    right_depth: Option<PathBuf>,
    /// Camera JSON: per-eye GL view and projection (row-major 4x4), middle projection and size,
    /// gaze rays or fixation distance, conventions, depth kind (device or view-z); `viewsynth
    /// scene` writes one.
    #[arg(help_heading = INPUTS, long, requires_all = ["left_depth", "right_depth"])]
    cameras: Option<PathBuf>,
    /// Raw units per unit of depth for integer depth files.
    #[arg(help_heading = INPUTS, long, value_parser = finite_value)]
    depth_scale: Option<f64>,
    /// Array of an .npz depth or disparity file (both eyes) to read (default: the only array,
    /// else the first floating-point one).
    #[arg(help_heading = INPUTS, long, value_name = "NAME")]
    npz_key: Option<String>,
    /// Right principal point minus left, pixels (Middlebury 2014 `doffs`): depth = f B / (d + doffs).
    #[arg(help_heading = INTRINSICS, long, default_value_t = CyclopeanRequest::default().doffs)]
    doffs: f64,
    /// Focal length, pixels; with --baseline the view's metric depth is written.
    #[arg(help_heading = INTRINSICS, long, requires = "baseline")]
    focal: Option<f64>,
    /// Baseline, metres.
    #[arg(help_heading = INTRINSICS, long, requires = "focal")]
    baseline: Option<f64>,
    /// Where the view sits between the eyes: 0 = left, 0.5 = middle, 1 = right.
    #[arg(help_heading = TARGETS, long)]
    position: Option<f64>,
    /// Method (default splat-gather; a lone --refine-steps selects seed (0) or refine as before).
    #[arg(help_heading = METHOD, long, value_enum)]
    method: Option<MethodArg>,
    /// Refinement steps of the refine method after the seed's step (0 = the seed alone).
    #[arg(help_heading = METHOD, long, value_parser = clap::value_parser!(u32).range(0..=16))]
    refine_steps: Option<u32>,
    /// Seed/refine only.
    #[arg(help_heading = METHOD, long, value_enum)]
    blend: Option<BlendArg>,
    /// Seed/refine only: middle-space depth disagreement (metres) treated as different surfaces
    /// (default: the seed's clamp(0.02 * fixation, 0.02, 0.25)).
    #[arg(help_heading = METHOD, long, value_parser = finite_value)]
    z_threshold: Option<f64>,
    /// Seed/refine only: dominant eye and its blend weight, e.g. `left:0.7`.
    #[arg(help_heading = METHOD, long)]
    dominant: Option<String>,
    /// Outputs to write: any of rgb (or color), depth, mask.
    ///
    /// Default all (disparity input: depth only with --focal and --baseline). Colour and depth not
    /// listed are not read back.
    #[arg(help_heading = OUTPUTS, long)]
    outputs: Option<String>,
    /// Fill the holes (pixels no eye saw) so the frame is complete; filled pixels are 128 in
    /// middle_mask.png.
    ///
    /// Disparities, given or estimated from two images alone, first render on maps made dense
    /// (unknown ones filled from similar-coloured neighbours, leaning to the background), then
    /// every remaining hole takes the background layer around it in 2-D. Filled pixels are 128 in
    /// middle_mask.png (rendered from matched or given disparities: 255). Off: holes stay 0.
    #[arg(help_heading = OUTPUTS, long)]
    fill: bool,
    /// Two images alone (no disparities, no depth): the largest disparity the matcher searches,
    /// pixels.
    ///
    /// Default: estimated from the images by a coarse pass, with a margin; the range used is
    /// printed. The search is bounded: at most 1024 disparities past 0 (max - min when the
    /// minimum is negative).
    #[arg(help_heading = INPUTS, long, value_name = "N", allow_hyphen_values = true, value_parser = clap::value_parser!(i32).range(-i64::from(viewsynth::io::MAX_DIMENSION)..=i64::from(viewsynth::io::MAX_DIMENSION)))]
    max_disparity: Option<i32>,
    /// Two images alone: the smallest disparity searched, pixels; negative for pairs whose
    /// disparities cross zero.
    ///
    /// Negative disparities come from a converged rig or images cropped after rectification.
    /// Default: estimated from the images.
    #[arg(help_heading = INPUTS, long, value_name = "N", allow_hyphen_values = true, value_parser = clap::value_parser!(i32).range(-i64::from(viewsynth::io::MAX_DIMENSION)..=i64::from(viewsynth::io::MAX_DIMENSION)))]
    min_disparity: Option<i32>,
    /// Two images alone: drop estimated disparities whose confidence is below C, in [0, 1]
    /// (the eyes' agreement times 1 / (1 + the local disparity variance)): fewer pixels, more
    /// of them right.
    #[arg(help_heading = INPUTS, long, value_name = "C", value_parser = finite_value)]
    min_confidence: Option<f64>,
    /// Two images alone: also write each eye's matcher confidence, left_confidence.exr and
    /// right_confidence.exr (float32 in [0, 1]; 0 where the disparity is unknown, at most 0.25
    /// where the semi-global matcher inferred it), the values --min-confidence is held against.
    #[arg(help_heading = OUTPUTS, long)]
    confidence: bool,
    /// Two images alone: the stereo matcher [default: sgm].
    ///
    /// sgm is smooth: low-texture regions take the surrounding surface's disparity. Its
    /// disparities the census matcher (run on the same pair) does not support, outside flat
    /// regions, are inferred: rendered with --fill (128 in the mask), not without. census alone
    /// is faster and leaves those pixels unknown; see docs/cyclopean.md.
    #[arg(help_heading = INPUTS, long, value_enum)]
    matcher: Option<MatcherArg>,
    /// Writes middle_rgb.png, middle_depth.exr, middle_mask.png (those in --outputs), and
    /// left_confidence.exr, right_confidence.exr with --confidence; with --sequence,
    /// middle_00000_rgb.png, ... per frame.
    #[arg(help_heading = OUTPUTS, long)]
    out_dir: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
    /// Rendering API: gl, or vulkan (the same gather shader as SPIR-V on a Vulkan device,
    /// --device an index of `viewsynth info --backend vulkan`).
    #[arg(help_heading = GPU, long, value_enum, default_value = "gl")]
    backend: BackendArg,
}

impl CyclopeanArgs {
    /// The settings the Python binding gives too, as the library's request.
    pub(crate) fn request(&self) -> Result<CyclopeanRequest, ArgError> {
        Ok(CyclopeanRequest {
            method: self.method.map(|m| match m {
                MethodArg::SplatGather => CyclopeanMethod::SplatGather,
                MethodArg::Seed => CyclopeanMethod::Seed,
                MethodArg::Refine => CyclopeanMethod::Refine,
                MethodArg::Forward => CyclopeanMethod::Forward,
            }),
            refine_steps: self.refine_steps,
            blend: self.blend.map(|b| match b {
                BlendArg::Hard => Blend::Hard,
                BlendArg::Soft => Blend::Soft,
            }),
            z_threshold: self.z_threshold,
            dominant: self.dominant.clone(),
            position: self.position,
            focal: self.focal,
            baseline: self.baseline,
            doffs: self.doffs,
            outputs: crate::options::parse_outputs(self.outputs.as_deref())?,
            fill: self.fill,
            max_disparity: self.max_disparity,
            min_disparity: self.min_disparity,
            min_confidence: self.min_confidence,
            confidence: self.confidence,
            matcher: self.matcher.map(|m| match m {
                MatcherArg::Census => MatcherMethod::Census,
                MatcherArg::Sgm => MatcherMethod::Sgm,
            }),
        })
    }
}

/// One pair, or a sequence of frames (`--sequence`).
pub(crate) enum CyclopeanRun {
    Pair(CyclopeanJob),
    Sequence(CyclopeanSequenceJob),
}

impl TryFrom<CyclopeanArgs> for CyclopeanRun {
    type Error = ArgError;
    fn try_from(a: CyclopeanArgs) -> Result<Self, ArgError> {
        let request = a.request()?;
        let options = CyclopeanOptions {
            left_rgb: a.left_rgb.unwrap_or_default(),
            right_rgb: a.right_rgb.unwrap_or_default(),
            left_disparity: a.left_disparity,
            right_disparity: a.right_disparity,
            disparity_scale: a.disparity_scale,
            left_depth: a.left_depth,
            right_depth: a.right_depth,
            cameras: a.cameras,
            depth_scale: a.depth_scale,
            npz_key: a.npz_key,
            request,
            out_dir: a.out_dir,
            gpu: a.gpu.try_into()?,
            backend: a.backend.into(),
        };
        Ok(match a.sequence {
            Some(file) => CyclopeanRun::Sequence(CyclopeanSequenceJob::new(file, options)?),
            None => CyclopeanRun::Pair(CyclopeanJob::new(options)?),
        })
    }
}
