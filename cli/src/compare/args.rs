//! `viewsynth compare` options and their conversion into a checked library job.

use crate::options::{conventions, NdcArg, RowsArg};
use crate::options::{CONVENTIONS, INPUTS, OUTPUTS, THRESHOLDS};
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use viewsynth::compare::{Alpha, BadPixel, ChannelOrder, ColourReading, Thresholds, Transfer};
use viewsynth::convention::{DepthPlanes, NdcDepthRange};
use viewsynth::job::compare::{CompareJob, CompareOptions, JsonOutput, SideDepth, SideOptions};
use viewsynth::job::ArgError;

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub(crate) enum DepthKindArg {
    /// Window depth in [0, 1] from a depth buffer (the same under gl and vulkan NDC).
    Device,
    /// NDC z after the divide (clip z / w): gl [-1, 1] or vulkan [0, 1], as --X-ndc says.
    Ndc,
    /// Linear view distance in metres.
    ViewZ,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum ChannelsArg {
    /// Red first.
    Rgb,
    /// Blue first (a BGRA swapchain read back as RGBA).
    Bgr,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum TransferArg {
    /// sRGB-encoded values (image viewers, our PNG outputs).
    Srgb,
    /// Linear values (e.g. a UNORM target read back where an SRGB one was expected).
    Linear,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum AlphaArg {
    /// Colour independent of alpha.
    Straight,
    /// Colour multiplied by alpha (the file must have alpha).
    Premultiplied,
}

/// The example under `viewsynth compare --help` (paths from the repository root, as in the README).
pub(crate) const EXAMPLES: &str = "\
Examples:
  # a cyclopean middle view of Cones against the real middle view, where it is valid
  viewsynth compare --a-rgb out/cones/middle_rgb.png --b-rgb ../shared/data/middlebury2003_cones/im4.png \\
      --mask out/cones/middle_mask.png --min-psnr 25 --flip-map out/cones/flip.png --json out/cones/compare.json
  # a CI gate: GL against a Vulkan reversed-Z rendering of one frame, at most 0.2 % bad pixels
  viewsynth scene --width 320 --height 240 --ndc vulkan --reversed-z --out-dir out/scene_vk
  viewsynth compare --a-rgb out/scene/middle_rgb.png --a-depth out/scene/middle_device_depth.exr --a-depth-kind device \\
      --b-rgb out/scene_vk/middle_rgb.png --b-depth out/scene_vk/middle_device_depth.exr --b-depth-kind device \\
      --b-reversed-z --near 0.05 --far 100 --max-bad-share 0.002 --max-flip 0.01";

#[derive(Args)]
pub(crate) struct CompareArgs {
    /// A's colour (e.g. ours).
    #[arg(help_heading = INPUTS, long)]
    a_rgb: PathBuf,
    /// B's colour (e.g. the other renderer's), the same size.
    #[arg(help_heading = INPUTS, long)]
    b_rgb: PathBuf,
    /// A's depth (EXR, NPY, NPZ, PFM), as --a-depth-kind says.
    #[arg(help_heading = INPUTS, long, requires = "b_depth")]
    a_depth: Option<PathBuf>,
    /// B's depth, as --b-depth-kind says.
    #[arg(help_heading = INPUTS, long, requires = "a_depth")]
    b_depth: Option<PathBuf>,
    /// Array of an .npz depth file (both sides) to read (default: the only array, else the first
    /// floating-point one).
    #[arg(help_heading = INPUTS, long, value_name = "NAME")]
    npz_key: Option<String>,
    /// Compare only where this image (rows top-down, the images' size) is nonzero.
    #[arg(help_heading = INPUTS, long, value_name = "FILE")]
    mask: Option<PathBuf>,
    /// Fail (exit 1) when the colour RMSE exceeds X (8-bit levels).
    #[arg(help_heading = THRESHOLDS, long, visible_alias = "max-color-rmse", value_name = "X")]
    max_colour_rmse: Option<f64>,
    /// Fail (exit 1) when the colour PSNR is below X dB.
    #[arg(help_heading = THRESHOLDS, long, value_name = "X")]
    min_psnr: Option<f64>,
    /// Fail (exit 1) when the largest relative depth error (pixels valid in both) exceeds X.
    ///
    /// One stray pixel decides a maximum: to gate CI, prefer --max-bad-share.
    #[arg(help_heading = THRESHOLDS, long, value_name = "X", requires = "a_depth")]
    max_depth_rel: Option<f64>,
    /// Fail (exit 1) when more than this share of the compared pixels is bad (0.001 = 0.1 %).
    ///
    /// Checked for colour (a pixel is bad when a channel differs by more than --bad-colour
    /// levels) and, with depth, for depth (relative error over --bad-depth-rel, pixels valid in
    /// both; with depth files on both sides and no such pixel, it fails: a gate never passes on
    /// nothing). The share over each threshold is in the JSON either way.
    #[arg(help_heading = THRESHOLDS, long, value_name = "SHARE")]
    max_bad_share: Option<f64>,
    /// Per-pixel colour threshold of --max-bad-share: largest channel difference, 8-bit levels.
    #[arg(help_heading = THRESHOLDS, long, visible_alias = "bad-color", value_name = "LEVELS", default_value_t = BadPixel::default().color_levels)]
    bad_colour: f64,
    /// Per-pixel depth threshold of --max-bad-share: relative view-Z error |A - B| / A.
    #[arg(help_heading = THRESHOLDS, long, value_name = "X", default_value_t = BadPixel::default().depth_rel)]
    bad_depth_rel: f64,
    /// Fail (exit 1) when the FLIP mean (NVIDIA's perceptual error in [0, 1], B the
    /// reference) exceeds X.
    #[arg(help_heading = THRESHOLDS, long, value_name = "X")]
    max_flip: Option<f64>,
    /// Write the colour difference here: |A - B| per channel, scaled so that the largest
    /// difference is white (x 255 / max; the factor is printed and in the JSON).
    #[arg(help_heading = OUTPUTS, long)]
    diff: Option<PathBuf>,
    /// Write FLIP's error map here, in FLIP's magma colours (black: no visible difference,
    /// yellow-white: the largest), B the reference; black outside --mask.
    #[arg(help_heading = OUTPUTS, long, value_name = "FILE")]
    flip_map: Option<PathBuf>,
    /// Write the summary as JSON to FILE (without FILE, or "-": print it instead of text).
    ///
    /// An infinite PSNR is written as the string "inf".
    #[arg(help_heading = OUTPUTS, long, value_name = "FILE", num_args = 0..=1, default_missing_value = "-")]
    json: Option<PathBuf>,
    /// What A's depth holds: view-z (metres), device (window depth in [0, 1], with
    /// --a-near/--a-far) or ndc (NDC z, with --a-ndc and the planes).
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "view-z", requires = "a_depth")]
    a_depth_kind: DepthKindArg,
    /// What B's depth holds (see --a-depth-kind).
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "view-z", requires = "b_depth")]
    b_depth_kind: DepthKindArg,
    /// NDC range of A's stored NDC z (--a-depth-kind ndc only: window depth reads the same
    /// under both): gl [-1, 1] or vulkan [0, 1].
    #[arg(help_heading = CONVENTIONS, long, value_enum)]
    a_ndc: Option<NdcArg>,
    /// NDC range of B's stored NDC z (--b-depth-kind ndc only).
    #[arg(help_heading = CONVENTIONS, long, value_enum)]
    b_ndc: Option<NdcArg>,
    /// A's device depth was written with reversed-Z (near at the top of the range).
    #[arg(help_heading = CONVENTIONS, long)]
    a_reversed_z: bool,
    /// B's device depth was written with reversed-Z.
    #[arg(help_heading = CONVENTIONS, long)]
    b_reversed_z: bool,
    /// Row order each file is stored in (image files are normally top-down).
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "top-down")]
    a_rows: RowsArg,
    /// Row order B's files are stored in (see --a-rows).
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "top-down")]
    b_rows: RowsArg,
    /// Channel order of A's colour file.
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "rgb")]
    a_channels: ChannelsArg,
    /// Channel order of B's colour file.
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "rgb")]
    b_channels: ChannelsArg,
    /// What A's colour values are: srgb (encoded) or linear (encoded to sRGB before comparing).
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "srgb")]
    a_transfer: TransferArg,
    /// What B's colour values are (see --a-transfer).
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "srgb")]
    b_transfer: TransferArg,
    /// A's colour against its alpha: straight or premultiplied (divided out before comparing).
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "straight")]
    a_alpha: AlphaArg,
    /// B's colour against its alpha (see --a-alpha).
    #[arg(help_heading = CONVENTIONS, long, value_enum, default_value = "straight")]
    b_alpha: AlphaArg,
    /// Near plane of both sides' device or NDC depth (metres), with --far.
    #[arg(help_heading = CONVENTIONS, long, requires = "far", conflicts_with_all = ["a_near", "b_near"])]
    near: Option<f64>,
    /// Far plane of both sides' device or NDC depth (metres; may be inf), with --near.
    #[arg(help_heading = CONVENTIONS, long, requires = "near", conflicts_with_all = ["a_far", "b_far"])]
    far: Option<f64>,
    /// Near plane A's device or NDC depth was written with (metres), with --a-far.
    #[arg(help_heading = CONVENTIONS, long, requires = "a_far")]
    a_near: Option<f64>,
    /// Far plane A's depth was written with (metres; inf for an infinite far plane).
    #[arg(help_heading = CONVENTIONS, long, requires = "a_near")]
    a_far: Option<f64>,
    /// Near plane B's device or NDC depth was written with (metres), with --b-far.
    #[arg(help_heading = CONVENTIONS, long, requires = "b_far")]
    b_near: Option<f64>,
    /// Far plane B's depth was written with (metres; inf for an infinite far plane).
    #[arg(help_heading = CONVENTIONS, long, requires = "b_near")]
    b_far: Option<f64>,
}

fn side_depth(kind: DepthKindArg) -> SideDepth {
    match kind {
        DepthKindArg::Device => SideDepth::Device,
        DepthKindArg::Ndc => SideDepth::Ndc,
        DepthKindArg::ViewZ => SideDepth::ViewZ,
    }
}

fn rows(arg: RowsArg) -> viewsynth::convention::RowOrder {
    conventions(NdcArg::Gl, false, arg).row_order
}

fn planes(near: Option<f64>, far: Option<f64>) -> Option<DepthPlanes> {
    Some(DepthPlanes { near: near?, far: far? })
}

fn colour(channels: ChannelsArg, transfer: TransferArg, alpha: AlphaArg) -> ColourReading {
    ColourReading {
        channels: match channels {
            ChannelsArg::Rgb => ChannelOrder::Rgb,
            ChannelsArg::Bgr => ChannelOrder::Bgr,
        },
        transfer: match transfer {
            TransferArg::Srgb => Transfer::Srgb,
            TransferArg::Linear => Transfer::Linear,
        },
        alpha: match alpha {
            AlphaArg::Straight => Alpha::Straight,
            AlphaArg::Premultiplied => Alpha::Premultiplied,
        },
    }
}

fn ndc(arg: Option<NdcArg>) -> Option<NdcDepthRange> {
    arg.map(|n| match n {
        NdcArg::Gl => NdcDepthRange::MinusOneToOne,
        NdcArg::Vulkan => NdcDepthRange::ZeroToOne,
    })
}

impl TryFrom<CompareArgs> for CompareJob {
    type Error = ArgError;
    fn try_from(a: CompareArgs) -> Result<Self, ArgError> {
        CompareJob::new(CompareOptions {
            a: SideOptions {
                rgb: a.a_rgb,
                colour: colour(a.a_channels, a.a_transfer, a.a_alpha),
                depth: a.a_depth,
                depth_kind: side_depth(a.a_depth_kind),
                planes: planes(a.a_near, a.a_far),
                ndc: ndc(a.a_ndc),
                reversed_z: a.a_reversed_z,
                row_order: rows(a.a_rows),
            },
            b: SideOptions {
                rgb: a.b_rgb,
                colour: colour(a.b_channels, a.b_transfer, a.b_alpha),
                depth: a.b_depth,
                depth_kind: side_depth(a.b_depth_kind),
                planes: planes(a.b_near, a.b_far),
                ndc: ndc(a.b_ndc),
                reversed_z: a.b_reversed_z,
                row_order: rows(a.b_rows),
            },
            npz_key: a.npz_key,
            planes: planes(a.near, a.far),
            diff: a.diff,
            flip_map: a.flip_map,
            mask: a.mask,
            thresholds: Thresholds {
                max_color_rmse: a.max_colour_rmse,
                min_psnr_db: a.min_psnr,
                max_depth_rel: a.max_depth_rel,
                max_bad_share: a.max_bad_share,
                bad: BadPixel {
                    color_levels: a.bad_colour,
                    depth_rel: a.bad_depth_rel,
                },
                max_flip_mean: a.max_flip,
            },
            json: a.json.map(|p| match p.as_path() == Path::new("-") {
                true => JsonOutput::Stdout,
                false => JsonOutput::File(p),
            }),
        })
    }
}
