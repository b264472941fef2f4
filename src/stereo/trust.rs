//! Matched or inferred (issue 48): which of the semi-global matcher's disparities the local
//! evidence supports. The semi-global matcher gives a disparity almost everywhere, taking it
//! from the surface around where the costs have no minimum worth trusting; rendered as matched,
//! those would lower the precision the mask promises (255 = rendered from a matched disparity).
//!
//! The rule, per pixel p of one eye with a semi-global disparity s (0 = unknown) and the census
//! matcher's c on the same pair:
//! - c known: p is matched when |s - c| <= [`AGREE_PX`] (the census costs, with their own
//!   uniqueness and left-right checks, found the same surface);
//! - c unknown (or not looked for: a search wider than [`CENSUS_CHECK_SEARCH`]): p is matched
//!   when its census window (7 x 5, borders replicated) is flat, its
//!   grey levels (r + g + b) within [`FLAT_GREY`]: no texture there to render wrongly, the
//!   low-texture regions the semi-global matcher exists for;
//! - otherwise s is inferred: kept for the dense frame (rendered, mask 128), left out of the
//!   matched one.
//!
//! Measured over the 13 issue-48 pairs (`lab/scripts/two_image_pairs.py`, `--fill`): the
//! rendered pixels score above the census matcher's on every pair (mean 35.3 against 33.8 dB)
//! while the share rendered from matched disparities rises (Laundry 57.7 -> 59.7 %, Midd2 51.8 ->
//! 70.4 %). The grey bound was taken low (20 of 765 levels); 40 already let Reindeer's rendered
//! pixels fall below the census matcher's.
//!
//! The GPU side is a stage of the semi-global matcher's own run
//! ([`Matcher::checked`](super::matcher::Matcher::checked)): the census matcher's stages run
//! first on the same grey levels and census codes, then the semi-global ones, then
//! shaders/cyclopean/matcher_trust.comp on both eyes' final disparities and grey levels. So the
//! check costs one pair upload and one readback, not a second matcher's and a pass of its own.
//! Its twin is [`trust_reference`](super::trust_reference::trust_reference): integer grey
//! levels and one f32 subtraction, so the GPU's maps are the twin's bit for bit.

use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};

/// Largest difference (px) at which the census and semi-global disparities agree: the
/// left-right check's tolerance.
pub const AGREE_PX: f32 = 1.0;
/// Largest grey range (r + g + b levels) of a flat census window.
pub const FLAT_GREY: i32 = 20;
/// Widest search (disparities) the census check runs over: its work grows with the search,
/// the semi-global matcher's does not. Past it no census disparity is known, so only the flat
/// windows' disparities count as matched: fewer pixels rendered as 255, none less precise, and
/// the work stays bounded at any width.
pub const CENSUS_CHECK_SEARCH: u32 = 256;

/// Whether the census check runs on a search of 0..=`max_disparity` (stored, offset included).
pub fn census_checked(max_disparity: u32) -> bool {
    max_disparity < CENSUS_CHECK_SEARCH
}

pub(super) fn check(semi_global: &DepthMap, census: &DepthMap, color: &RgbImage) -> Result<()> {
    let size = (color.width, color.height);
    if (semi_global.width, semi_global.height) != size || (census.width, census.height) != size {
        return Err(Error::SizeMismatch {
            message: format!(
                "trust: semi-global disparity {}x{}, census disparity {}x{}, colour {}x{}",
                semi_global.width, semi_global.height, census.width, census.height, color.width, color.height
            ),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stereo::trust_reference::trust_reference;

    /// The GLSL constants are the Rust ones (the census window is the matcher's own).
    #[test]
    fn the_shader_constants_are_the_twins() {
        let glsl = include_str!("../../shaders/cyclopean/matcher_trust.comp");
        for line in [
            format!("const float AGREE_PX = {AGREE_PX:.1};"),
            format!("const int FLAT_GREY = {FLAT_GREY};"),
        ] {
            assert!(glsl.contains(&line), "matcher_trust.comp lacks `{line}`");
        }
    }

    #[test]
    fn the_census_check_is_bounded_work() {
        // The check's census costs are at most CENSUS_CHECK_SEARCH a pixel, whatever the search.
        for max_disparity in [0u32, 63, 255, 256, 1023, 16383] {
            let searched = if census_checked(max_disparity) {
                max_disparity + 1
            } else {
                0
            };
            assert!(searched <= CENSUS_CHECK_SEARCH, "{max_disparity}");
        }
        assert!(census_checked(CENSUS_CHECK_SEARCH - 1) && !census_checked(CENSUS_CHECK_SEARCH));
    }

    fn map(w: u32, h: u32, v: impl Fn(u32, u32) -> f32) -> DepthMap {
        DepthMap::new(
            w,
            h,
            (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| v(x, y))
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn agreement_or_a_flat_window_makes_a_disparity_matched() {
        // 24 x 8: left half flat grey, right half a checkerboard. The semi-global matcher says
        // 10 everywhere; the census matcher says 10.5 in rows 0-1, 12 in rows 2-3, nothing below.
        let (w, h) = (24u32, 8u32);
        let mut rgb = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let v = if x < 12 {
                    100
                } else if (x + y) % 2 == 0 {
                    40
                } else {
                    200
                };
                rgb.extend([v, v, v]);
            }
        }
        let color = RgbImage::new(w, h, rgb).unwrap();
        let semi_global = map(w, h, |_, _| 10.0);
        let census = map(w, h, |_, y| match y {
            0 | 1 => 10.5,
            2 | 3 => 12.0,
            _ => 0.0,
        });
        let out = trust_reference(&semi_global, &census, &color).unwrap();
        let at = |x: u32, y: u32| out.data[(y * w + x) as usize];
        // Agreement within 1 px: matched, flat or not.
        assert_eq!((at(2, 0), at(20, 1)), (10.0, 10.0));
        // Disagreement: inferred, even where flat.
        assert_eq!((at(2, 2), at(20, 3)), (0.0, 0.0));
        // No census disparity: matched where the window is flat (its 7 columns all left of
        // x = 12), inferred where it holds texture.
        assert_eq!(at(2, 6), 10.0);
        assert_eq!(at(8, 6), 10.0);
        assert_eq!(at(9, 6), 0.0, "the window reaches the checkerboard");
        assert_eq!(at(20, 6), 0.0);
        // Unknown stays unknown.
        let none = trust_reference(&map(w, h, |_, _| 0.0), &census, &color).unwrap();
        assert!(none.data.iter().all(|v| *v == 0.0));
    }
}
