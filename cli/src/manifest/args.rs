//! `viewsynth manifest` options.

use crate::options::IntrinsicsArgs;
use clap::Args;
use std::path::PathBuf;
use viewsynth::job::manifest::TumManifestJob;
use viewsynth::job::{finite_value, ArgError, SourceIntrinsics};
use viewsynth::refocus::batch::{TUM_DEPTH_SCALE, TUM_MAX_DIFFERENCE};

/// The examples under `viewsynth manifest --help`.
pub(crate) const EXAMPLES: &str = "\
Examples:
  # a TUM RGB-D sequence (rgb.txt, depth.txt) into a manifest, then every frame at two scales
  viewsynth manifest tum_seq --fx 525 --fy 525 --cx 319.5 --cy 239.5 --out tum_seq/frames.csv
  viewsynth refocus --batch tum_seq/frames.csv --zoom-range 0.5,2 --out-dir out/tum_frames";

#[derive(Args)]
pub(crate) struct ManifestArgs {
    /// A TUM-style sequence folder: rgb.txt and depth.txt list `timestamp path` lines (`#`
    /// comments), the paths relative to it.
    #[arg(value_name = "SEQUENCE", help_heading = crate::options::INPUTS)]
    pub(crate) sequence: PathBuf,
    /// The colour listing, if not SEQUENCE/rgb.txt.
    #[arg(long, value_name = "FILE", help_heading = crate::options::INPUTS)]
    pub(crate) rgb_list: Option<PathBuf>,
    /// The depth listing, if not SEQUENCE/depth.txt.
    #[arg(long, value_name = "FILE", help_heading = crate::options::INPUTS)]
    pub(crate) depth_list: Option<PathBuf>,
    /// Stored depth units per metre, written on every row (TUM's 16-bit PNGs: 5000).
    #[arg(long, default_value_t = TUM_DEPTH_SCALE, value_parser = finite_value, help_heading = crate::options::INPUTS)]
    pub(crate) depth_scale: f64,
    /// Largest time between a paired colour and depth frame, seconds; each colour frame takes
    /// the nearest depth frame, each frame used once, as TUM's associate.py pairs them.
    #[arg(long, default_value_t = TUM_MAX_DIFFERENCE, value_parser = finite_value, value_name = "SECONDS",
          help_heading = crate::options::INPUTS)]
    pub(crate) max_difference: f64,
    #[command(flatten)]
    pub(crate) intrinsics: IntrinsicsArgs,
    /// The CSV manifest to write (replaced whole, or left as it was on failure). Paths under
    /// its folder are written relative to it, others absolute.
    #[arg(long, value_name = "FILE", help_heading = crate::options::OUTPUTS)]
    pub(crate) out: PathBuf,
}

impl TryFrom<ManifestArgs> for TumManifestJob {
    type Error = ArgError;
    fn try_from(a: ManifestArgs) -> Result<Self, ArgError> {
        let k = SourceIntrinsics::resolve(a.intrinsics.intrinsics.as_deref(), a.intrinsics.values())?;
        TumManifestJob::new(
            a.sequence,
            (a.rgb_list, a.depth_list),
            k,
            a.depth_scale,
            a.max_difference,
            a.out,
        )
    }
}
