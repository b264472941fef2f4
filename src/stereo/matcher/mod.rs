//! A small dense stereo matcher for rectified pairs: disparities of both eyes from the two
//! images alone, for users without ground-truth disparities (issue 26) and for the report's
//! estimated-disparity rows (issue 13: the default must beat the splat baseline on real pairs
//! without ground truth too).
//!
//! Design: deliberately plain and deterministic (integer costs, fixed tie rule, no tuning per
//! scene), so that what the report measures is the view-synthesis methods, not a clever matcher.
//! - Census transform over a 7 x 5 window of grey = r + g + b (34 bits: neighbour darker than the
//!   centre), borders replicated: robust to the exposure differences between real views.
//! - Cost: Hamming distance of the census codes, left pixel x against right pixel x - d.
//! - Aggregation: mean over a 9 x 9 box clipped to the image and to the pixels where the
//!   disparity can exist (x >= d), kept in fixed point (x 256) so that clipped boxes compare
//!   fairly.
//! - Winner takes all, ties to the smaller disparity, for both eyes from the same costs (the
//!   right eye's cost at (x, d) is the left eye's at (x + d, d)); sub-pixel by the parabola
//!   through the winner's cost and its two neighbours' (offset clamped to half a pixel).
//! - Uniqueness: a winner whose cost is not below every cost two or more disparities away by
//!   more than [`UNIQUENESS_PERCENT`] % is unknown (a repeated texture that matches one period
//!   off as well as at its own disparity; both eyes would agree on the wrong one). The second
//!   best is kept while streaming the disparities: a new winner takes the running minimum of
//!   the costs up to two disparities before it, later costs two or more past it lower it.
//! - Left-right consistency: a disparity is kept only if the other eye's, read at the pixel it
//!   points to, is within 1 px; occlusions and most mismatches become 0 (unknown).
//! - A 3 x 3 median over the known values of each known pixel (unknown pixels stay unknown).
//!
//! Two implementations of that one rule:
//! - [`reference`](mod@reference): the CPU twin, one slice of the cost volume at a time by prefix sums (memory
//!   O(w h); Cones 450 x 375 with 65 disparities in a fraction of a second).
//! - [`Matcher`] ([`gpu`]): the GPU pass on either executor, one compute dispatch per stage
//!   (shaders/cyclopean/matcher_*.comp): grey levels, census codes; per chunk of disparities (so the buffers
//!   stay within every API's storage-buffer limit at any size) the Hamming costs summed along
//!   each row by a sliding window, two disparities a word in 16-bit lanes, then down each
//!   column into the fixed-point means, and the winners of both eyes carried from chunk to
//!   chunk; then the sub-pixel step, the left-right check and the median, stored into the run's
//!   two outputs. At 720p and above the CPU twin dominates a frame's time, hence the pass.
//!
//! Every stage is exact on the GPU: the costs, sums and means are integers (a mean's division
//! is a float quotient corrected by integer tests); the parabola's
//! quotient is rebuilt from integers correctly rounded (GLSL's own division may be 2.5 ulp off);
//! the rest are single f32 additions, subtractions, comparisons and moves, which GLSL rounds as
//! the CPU does. So the GPU's disparities are the twin's bit for bit
//! (viewsynth_tests/tests/library/cyclopean/matcher.rs).
//!
//! [`confidence`]: per pixel, how far to trust each eye's disparity (the eyes' agreement and the
//! local spread), a further stage ([`Matcher::estimate_with_confidence`]) with its twin.
//!
//! Conventions as [`crate::stereo::disparity_frame`]: the left disparity maps x_left to
//! x_right = x_left - d, the right one x_right to x_left = x_right + d; 0 = unknown. Images and
//! disparities have top-down rows.

pub mod confidence;
pub mod gpu;
pub mod params;
pub mod range;
pub mod reference;
pub mod sgm;

pub use confidence::confidence_reference;
pub use gpu::{Checked, EyeEstimate, Matcher};
pub use reference::estimate_disparities;
pub use sgm::estimate_disparities_sgm;

use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};

/// Which matcher estimates the disparities of a pair alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MatcherMethod {
    /// Census costs averaged over a 9 x 9 box, winner takes all (this module's design).
    Census,
    /// Semi-global matching of the census costs ([`sgm`]): smooth where there is no texture.
    /// The default: the two-image frame then leads a learned interpolator (issue 48); its
    /// disparities the census matcher does not support are marked inferred
    /// ([`crate::stereo::trust`]), so the mask's rendered pixels keep the census precision.
    #[default]
    Sgm,
}

impl MatcherMethod {
    /// Both eyes' disparities by this method's CPU twin.
    pub fn estimate_reference(
        self,
        left: &RgbImage,
        right: &RgbImage,
        max_disparity: u32,
    ) -> Result<(DepthMap, DepthMap)> {
        match self {
            MatcherMethod::Census => estimate_disparities(left, right, max_disparity),
            MatcherMethod::Sgm => estimate_disparities_sgm(left, right, max_disparity),
        }
    }
}

/// Census window half-width (7 columns).
pub const CENSUS_HALF_W: usize = 3;
/// Census window half-height (5 rows).
pub const CENSUS_HALF_H: usize = 2;
/// Aggregation box half-size (9 x 9).
pub const BOX_RADIUS: usize = 4;
/// Largest disagreement (px) between the eyes the left-right check accepts.
pub const LR_TOLERANCE_PX: f32 = 1.0;
/// The uniqueness margin: a winner whose cost is not below every cost two or more disparities
/// away by more than this share (in %) is unknown.
pub const UNIQUENESS_PERCENT: u32 = 5;
/// Aggregated costs are means in fixed point with this many fractional bits.
pub const MEAN_SHIFT: u32 = 8;

/// Both images of the pair have one size.
fn check_pair(left: &RgbImage, right: &RgbImage) -> Result<()> {
    if (left.width, left.height) != (right.width, right.height) {
        return Err(Error::SizeMismatch {
            message: format!(
                "stereo matching: left image {}x{} vs right image {}x{}",
                left.width, left.height, right.width, right.height
            ),
        });
    }
    Ok(())
}

/// The search range 0..=`max_disparity` fits the image (at least 1 px, less than its width)
/// and the matcher's bound ([`range::MAX_SEARCH`]).
fn check_range(width: u32, max_disparity: u32) -> Result<()> {
    if max_disparity == 0 || max_disparity >= width || i64::from(max_disparity) > range::MAX_SEARCH {
        return Err(Error::param(
            "max_disparity",
            format!(
                "{max_disparity} px: must be at least 1, less than the image width ({width} px) and at most {}",
                range::MAX_SEARCH
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// The GLSL constants (shaders/cyclopean/matcher_params.glsl) are the Rust ones.
    #[test]
    fn the_shader_constants_are_the_twins() {
        let glsl = include_str!("../../../shaders/cyclopean/matcher_params.glsl");
        for line in [
            format!("const int CENSUS_HALF_W = {};", super::CENSUS_HALF_W),
            format!("const int CENSUS_HALF_H = {};", super::CENSUS_HALF_H),
            format!("const int BOX_RADIUS = {};", super::BOX_RADIUS),
            format!("const uint MEAN_SHIFT = {}u;", super::MEAN_SHIFT),
            format!("const uint UNIQUENESS_PERCENT = {}u;", super::UNIQUENESS_PERCENT),
            format!("const float LR_TOLERANCE_PX = {:?};", super::LR_TOLERANCE_PX),
        ] {
            assert!(glsl.contains(&line), "matcher_params.glsl lacks `{line}`");
        }
    }
}
