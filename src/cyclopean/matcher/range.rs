//! Signed disparity ranges (issue 38): a pair whose disparities cross zero (a converged rig, or
//! images cropped or shifted after rectification) is matched over its own range, negative values
//! included, by the same census matcher.
//!
//! - [`estimate_range`]: the pair's range from the images alone. A coarse pass (both images box-
//!   averaged to at most [`COARSE_WIDTH`] columns, searched over a third of that width either
//!   way), whose left-right-checked disparities give the 1st and 99th percentiles, scaled back
//!   and widened by a margin for the coarse pass's error; from 0 where the coarse pass saw no
//!   negative disparity.
//! - [`SignedSearch`]: how a signed range runs on the unsigned matcher. The matcher searches
//!   0..=max with 0 meaning unknown; a range whose minimum is negative is moved up by an offset
//!   `o = -min` by widening both images by `o` columns (the left one replicated on its left,
//!   the right one on its right), so that the left pixel x still meets the right pixel x - d
//!   at the stored disparity d + o >= 0 (the range's lowest end, like 0 before, reads as
//!   unknown). The maps are cropped back to the input's columns, their
//!   values kept as d + o (0 still unknown), and [`SignedSearch::offset`] goes into the rig's
//!   `offset` (see [`crate::cyclopean::disparity_frame::DisparityRig`]). Nothing is lost at the
//!   borders: every column of both images is matched as in an unshifted pair.
//!   A range whose minimum is at least 0 runs as before, 0..=max, bit for bit the unsigned
//!   matcher's maps.
//!
//! Both the GPU matcher and its twin run on the widened images, so the GPU's maps stay the
//! twin's bit for bit; the coarse pass is small (at most 128 columns) and runs on the CPU twin.

use super::reference::estimate_disparities;
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use serde::Serialize;

/// Columns of the coarse pass at most: large enough to see objects a few percent of the width,
/// small enough that the twin takes a few milliseconds at any size.
pub const COARSE_WIDTH: u32 = 128;

/// Share of the coarse pass's pixels below the 1st and above the 99th percentile left out of
/// the range (mismatches the left-right check let through).
const TAIL: f64 = 0.01;

/// Most disparities the matcher searches past 0 (its `max_disparity`, the signed range moved
/// up by its offset): its work grows with each one (a 16384-wide pair searched to its width
/// did not finish in 45 s), so the search is bounded by this, not by the image width. Four
/// times the largest default search (256).
pub const MAX_SEARCH: i64 = 1024;

/// A disparity search range, pixels (left: x_right = x_left - d), both ends included.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct DisparityRange {
    /// Smallest disparity searched; may be negative.
    pub min: i32,
    /// Largest disparity searched.
    pub max: i32,
}

impl DisparityRange {
    /// How far the matcher searches for this range: 0..=max - min(min, 0) ([`SignedSearch`]).
    pub fn searched(&self) -> i64 {
        self.max as i64 - (self.min as i64).min(0)
    }

    /// Refuses a range whose search passes [`MAX_SEARCH`] disparities, naming the option that
    /// sets it (both when the range reaches below 0).
    pub fn check_search(&self) -> Result<()> {
        if self.searched() > MAX_SEARCH {
            return Err(Error::param(
                if self.min < 0 {
                    "--min-disparity/--max-disparity"
                } else {
                    "--max-disparity"
                },
                format!(
                    "{}..{} px: the matcher would search {} disparities, more than its {MAX_SEARCH} \
                     (its work grows with each); give a narrower range",
                    self.min,
                    self.max,
                    self.searched() + 1
                ),
            ));
        }
        Ok(())
    }

    /// Refuses an empty range, one at least as wide as the image and one searched past
    /// [`MAX_SEARCH`].
    pub fn validate(&self, width: u32) -> Result<()> {
        let span = self.max as i64 - self.min as i64;
        if span < 1 || self.max as i64 >= width as i64 || -(self.min as i64) >= width as i64 {
            return Err(Error::param(
                "--min-disparity/--max-disparity",
                format!(
                    "{}..{} px: needs min < max and both within +-{} px (less than the width)",
                    self.min,
                    self.max,
                    width.saturating_sub(1)
                ),
            ));
        }
        self.check_search()
    }
}

/// A signed range as the unsigned matcher runs it (see the module notes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SignedSearch {
    /// Columns added to both images, and added to every stored disparity.
    pub offset: u32,
    /// The matcher's search 0..=max_disparity on the widened pair.
    pub max_disparity: u32,
}

impl SignedSearch {
    /// How `range` runs on the matcher.
    pub fn new(range: DisparityRange) -> Self {
        let offset = (-(range.min as i64)).max(0) as u32;
        SignedSearch {
            offset,
            max_disparity: (range.max as i64 + offset as i64).max(1) as u32,
        }
    }

    /// The widened pair's width.
    pub fn width(&self, width: u32) -> u32 {
        width + self.offset
    }

    /// Both images widened by the offset (borrowed as they are without one).
    pub fn widen(&self, left: &RgbImage, right: &RgbImage) -> Result<(RgbImage, RgbImage)> {
        let o = self.offset as usize;
        let (w, h) = (left.width as usize, left.height as usize);
        let (mut l, mut r) = (Vec::with_capacity((w + o) * h * 3), Vec::with_capacity((w + o) * h * 3));
        for y in 0..h {
            let (lr, rr) = (
                &left.data[y * w * 3..(y + 1) * w * 3],
                &right.data[y * w * 3..(y + 1) * w * 3],
            );
            for _ in 0..o {
                l.extend_from_slice(&lr[..3]);
            }
            l.extend_from_slice(lr);
            r.extend_from_slice(rr);
            for _ in 0..o {
                r.extend_from_slice(&rr[3 * (w - 1)..]);
            }
        }
        Ok((
            RgbImage::new(left.width + self.offset, left.height, l)?,
            RgbImage::new(right.width + self.offset, right.height, r)?,
        ))
    }

    /// The widened pair's maps cropped back to `width` columns: the left one drops its first
    /// `offset` columns, the right one its last. Values stay d + offset (0 = unknown).
    pub fn crop(&self, left: DepthMap, right: DepthMap, width: u32) -> Result<(DepthMap, DepthMap)> {
        if self.offset == 0 {
            return Ok((left, right));
        }
        let (o, w, ww) = (self.offset as usize, width as usize, left.width as usize);
        let keep = |map: &DepthMap, from: usize| -> Vec<f32> {
            map.data
                .chunks_exact(ww)
                .flat_map(|row| row[from..from + w].iter().copied())
                .collect()
        };
        Ok((
            DepthMap::new(width, left.height, keep(&left, o))?,
            DepthMap::new(width, right.height, keep(&right, 0))?,
        ))
    }
}

/// The twin of the signed search: both eyes' disparities over `range` (stored as d + offset,
/// 0 unknown) and the offset.
pub fn estimate_signed(left: &RgbImage, right: &RgbImage, range: DisparityRange) -> Result<(DepthMap, DepthMap, u32)> {
    super::check_pair(left, right)?;
    range.validate(left.width)?;
    let search = SignedSearch::new(range);
    let (wl, wr) = search.widen(left, right)?;
    let (dl, dr) = estimate_disparities(&wl, &wr, search.max_disparity)?;
    let (dl, dr) = search.crop(dl, dr, left.width)?;
    Ok((dl, dr, search.offset))
}

/// `img` box-averaged by `f` (integer means, rounded), the partial last row and column dropped.
fn downsample(img: &RgbImage, f: u32) -> Result<RgbImage> {
    let (w, h) = (img.width / f, img.height / f);
    let mut out = Vec::with_capacity((w * h * 3) as usize);
    let n = f * f;
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..f {
                    let row = ((y * f + dy) * img.width) as usize;
                    for dx in 0..f {
                        sum += img.data[(row + (x * f + dx) as usize) * 3 + c] as u32;
                    }
                }
                out.push(((sum + n / 2) / n) as u8);
            }
        }
    }
    RgbImage::new(w, h, out)
}

/// The pair's disparity range from the images alone (see the module notes), or None when the
/// coarse pass keeps too few disparities to say (under 1 % of its pixels, or the pair smaller
/// than 16 x 8 after the box average).
pub fn estimate_range(left: &RgbImage, right: &RgbImage) -> Result<Option<DisparityRange>> {
    super::check_pair(left, right)?;
    let f = left.width.div_ceil(COARSE_WIDTH).max(1);
    let (cl, cr) = (downsample(left, f)?, downsample(right, f)?);
    if cl.width < 16 || cl.height < 8 {
        return Ok(None);
    }
    let reach = (cl.width / 3).max(2) as i32;
    let (dl, _, offset) = estimate_signed(
        &cl,
        &cr,
        DisparityRange {
            min: -reach,
            max: reach,
        },
    )?;
    let mut known: Vec<f64> = dl
        .data
        .iter()
        .filter(|v| **v > 0.0)
        .map(|&v| v as f64 - offset as f64)
        .collect();
    if known.len() < 16 || known.len() * 100 < dl.data.len() {
        return Ok(None);
    }
    known.sort_by(f64::total_cmp);
    let at = |q: f64| known[((known.len() - 1) as f64 * q).round() as usize] * f as f64;
    let (lo, hi) = (at(TAIL), at(1.0 - TAIL));
    // The coarse pass is about one coarse pixel off: that and a pixel either way. A wider range
    // costs the matcher more false matches than it finds (Tsukuba 2+4 -> 3 with --fill: 0..32
    // px 29.59 dB, -10..39 px 29.15 dB). A pair with no negative disparity at the coarse level
    // searches from 0, as the unsigned matcher always did.
    let margin = f as f64 + 1.0;
    let limit = left.width as i64 - 1;
    let min = match lo >= 0.0 {
        true => 0,
        false => ((lo - margin).floor() as i64).clamp(-limit, limit - 1),
    };
    let max = ((hi + margin).ceil() as i64).clamp(min + 1, limit);
    Ok(Some(DisparityRange {
        min: min as i32,
        max: max as i32,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A textured pair whose right image is the left one moved by `shift(x, y)` px.
    fn pair(w: u32, h: u32, shift: impl Fn(u32, u32) -> i64) -> (RgbImage, RgbImage) {
        let tex = |x: i64, y: i64| -> [u8; 3] {
            let v = ((x * 37 + y * 11) ^ (x * x * 3 + y * 5)).rem_euclid(251) as u8;
            [v, v.wrapping_mul(3), 255 - v]
        };
        let mut l = Vec::new();
        let mut r = Vec::new();
        for y in 0..h {
            for x in 0..w {
                l.extend(tex(x as i64, y as i64));
                // Right pixel x sees the left pixel x + d.
                r.extend(tex(x as i64 + shift(x, y), y as i64));
            }
        }
        (RgbImage::new(w, h, l).unwrap(), RgbImage::new(w, h, r).unwrap())
    }

    #[test]
    fn a_negative_disparity_is_found_and_stored_above_the_offset() {
        // Every disparity -6: the unsigned search from 0 cannot find it.
        let (l, r) = pair(64, 24, |_, _| -6);
        let (dl, dr, o) = estimate_signed(&l, &r, DisparityRange { min: -10, max: 4 }).unwrap();
        assert_eq!(o, 10);
        let inner = |m: &DepthMap| {
            m.data
                .chunks_exact(64)
                .skip(4)
                .take(16)
                .flat_map(|row| row[12..52].to_vec())
                .collect::<Vec<f32>>()
        };
        for v in inner(&dl).into_iter().chain(inner(&dr)) {
            assert!(
                (v - (o as f32 - 6.0)).abs() < 0.25,
                "stored {v}, want {}",
                o as f32 - 6.0
            );
        }
    }

    #[test]
    fn a_positive_range_runs_as_the_unsigned_matcher_bit_for_bit() {
        let (l, r) = pair(48, 16, |x, _| if x < 24 { 3 } else { 7 });
        let (dl, dr, o) = estimate_signed(&l, &r, DisparityRange { min: 1, max: 12 }).unwrap();
        assert_eq!(o, 0);
        let (el, er) = estimate_disparities(&l, &r, 12).unwrap();
        assert_eq!((dl.data, dr.data), (el.data, er.data));
    }

    #[test]
    fn the_estimated_range_holds_disparities_either_side_of_zero() {
        // Left half at -9 px, right half at +13 px.
        let (l, r) = pair(256, 96, |x, _| if x < 128 { -9 } else { 13 });
        let range = estimate_range(&l, &r).unwrap().expect("a textured pair gives a range");
        assert!(range.min <= -9 && range.min >= -20, "{range:?}");
        assert!(range.max >= 13 && range.max <= 24, "{range:?}");
    }

    #[test]
    fn an_empty_or_too_wide_range_is_refused_by_name() {
        let e = DisparityRange { min: 5, max: 5 }.validate(100).unwrap_err();
        assert!(e.to_string().contains("--min-disparity"), "{e}");
        assert!(DisparityRange { min: -100, max: 5 }.validate(100).is_err());
        assert!(DisparityRange { min: -99, max: 99 }.validate(100).is_ok());
    }
}
