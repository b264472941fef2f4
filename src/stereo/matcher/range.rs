//! Signed disparity ranges (issue 38): a pair whose disparities cross zero (a converged rig, or
//! images cropped or shifted after rectification) is matched over its own range, negative values
//! included, by the same census matcher.
//!
//! - [`estimate_range`]: the pair's range from the images alone. A coarse pass (both images box-
//!   averaged to at most [`COARSE_WIDTH`] columns, searched over a third of that width either
//!   way), whose left-right-checked disparities give the 1st and 99th percentiles, scaled back
//!   and widened by a margin for the coarse pass's error; from 0 where the coarse pass saw no
//!   negative disparity. A small cluster wholly below 0 and apart from the rest is left out
//!   first: a repeated texture matched one period off ([`MIN_CLUSTER`]).
//! - [`SignedSearch`]: how a signed range runs on the unsigned matcher. The matcher searches
//!   0..=max with 0 meaning unknown; a range whose minimum is negative is moved up by an offset
//!   `o = -min` by widening both images by `o` columns (the left one replicated on its left,
//!   the right one on its right), so that the left pixel x still meets the right pixel x - d
//!   at the stored disparity d + o >= 0 (the range's lowest end, like 0 before, reads as
//!   unknown). The maps are cropped back to the input's columns, their
//!   values kept as d + o (0 still unknown), and [`SignedSearch::offset`] goes into the rig's
//!   `offset` (see [`crate::stereo::disparity_frame::DisparityRig`]). Nothing is lost at the
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

/// Width of the histogram bins (coarse pixels) that split the coarse disparities into clusters:
/// a bin holding under [`SPARSE_BIN`] of them is empty, and an empty bin ends a cluster.
const BIN: f64 = 1.0;
/// Share of the coarse pass's disparities under which a bin counts as empty (scattered
/// mismatches between two clusters do not join them).
const SPARSE_BIN: f64 = 0.001;
/// Share a cluster of negative disparities apart from the median's must hold to count. A
/// repeated texture (a grid, a fence) that the coarse pass matches one period off makes a small
/// cluster far from the scene's own disparities, which the left-right check passes (both eyes
/// agree on the wrong period): Middlebury Laundry's basket, 2.8 % of the coarse pixels near
/// -127 px, widened its search from 0..116 to -133..116 and cost 1.7 dB with `--fill`. Negative
/// disparities are real only behind a converged rig's zero-parallax plane or in a cropped pair,
/// where they are the background's, a large share joined to the rest; so only clusters wholly
/// below 0 are held to this share. Positive ones always count: a small near object (Tsukuba's
/// lamp, 3-4 % of the pixels, apart from the rest) is real more often than not.
const MIN_CLUSTER: f64 = 0.05;

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
                    crate::msg![crate::Field::MinDisparity, "/", crate::Field::MaxDisparity]
                } else {
                    crate::Field::MaxDisparity.into()
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
                crate::msg![crate::Field::MinDisparity, "/", crate::Field::MaxDisparity],
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

/// The coarse disparities (sorted) of the clusters that count (see [`BIN`]): the one holding the
/// median, every one reaching above 0, and one wholly below 0 only when it holds at least
/// [`MIN_CLUSTER`] of them. Sorted on return.
fn main_clusters(sorted: &[f64]) -> Vec<f64> {
    let n = sorted.len();
    let bin = |v: f64| (v / BIN).floor() as i64;
    let (first, last) = (bin(sorted[0]), bin(sorted[n - 1]));
    let mut counts = vec![0usize; (last - first + 1) as usize];
    for &v in sorted {
        counts[(bin(v) - first) as usize] += 1;
    }
    let full = |c: usize| c as f64 >= SPARSE_BIN * n as f64 && c > 0;
    // Clusters: maximal runs of full bins, as (first bin, last bin, count).
    let mut clusters: Vec<(i64, i64, usize)> = Vec::new();
    let mut open: Option<(i64, usize)> = None;
    for (i, &c) in counts.iter().enumerate() {
        let i = i as i64 + first;
        match (full(c), open) {
            (true, None) => open = Some((i, c)),
            (true, Some((s, sum))) => open = Some((s, sum + c)),
            (false, Some((s, sum))) => {
                clusters.push((s, i - 1, sum));
                open = None;
            }
            (false, None) => {}
        }
    }
    if let Some((s, sum)) = open {
        clusters.push((s, last, sum));
    }
    let median = bin(sorted[n / 2]);
    let keep = |&(s, e, sum): &(i64, i64, usize)| {
        (s..=e).contains(&median) || (e + 1) as f64 * BIN > 0.0 || sum as f64 >= MIN_CLUSTER * n as f64
    };
    let kept: Vec<&(i64, i64, usize)> = clusters.iter().filter(|c| keep(c)).collect();
    if kept.is_empty() {
        return sorted.to_vec();
    }
    sorted
        .iter()
        .copied()
        .filter(|&v| kept.iter().any(|&&(s, e, _)| (s..=e).contains(&bin(v))))
        .collect()
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
    let known = main_clusters(&known);
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

    /// `share` of 2,000 coarse disparities at `at`, the rest spread over 20..100.
    fn coarse(at: f64, share: f64) -> Vec<f64> {
        let n = 2000;
        let off = (n as f64 * share) as usize;
        let mut v: Vec<f64> = (0..n - off)
            .map(|i| 20.0 + 80.0 * i as f64 / (n - off) as f64)
            .collect();
        v.extend((0..off).map(|i| at + (i % 3) as f64 * 0.4));
        v.sort_by(f64::total_cmp);
        v
    }

    #[test]
    fn a_small_cluster_below_zero_apart_from_the_scene_is_left_out() {
        // A grid matched one period off: 3 % of the coarse pixels far below 0.
        let kept = main_clusters(&coarse(-21.0, 0.03));
        assert!(kept.iter().all(|&v| v >= 20.0), "{:?}", &kept[..5]);
        // Under the same 5 % but joined to the rest by a continuous run: kept (a slanted background).
        let mut joined = coarse(-21.0, 0.0);
        joined.extend((0..90).map(|i| -10.0 + 30.0 * i as f64 / 90.0));
        joined.sort_by(f64::total_cmp);
        assert_eq!(main_clusters(&joined).len(), joined.len());
    }

    #[test]
    fn a_large_negative_cluster_and_any_positive_one_are_kept() {
        // 10 % behind a converged rig's zero-parallax plane: real.
        let v = coarse(-21.0, 0.10);
        assert_eq!(main_clusters(&v).len(), v.len());
        // A small near object apart from the rest (Tsukuba's lamp): real.
        let v = coarse(140.0, 0.03);
        assert_eq!(main_clusters(&v).len(), v.len());
    }

    #[test]
    fn laundrys_basket_does_not_widen_its_search_below_zero() {
        // Middlebury Laundry (half size): true disparities 13.5..116 px. Its basket's grid made
        // the coarse pass's 1st percentile -127 px, a search of -133..116 (issue 48).
        let dir = crate::test_data::dir().join("middlebury2005_2006_dev/2005_laundry");
        let l = crate::io::load_rgb(&dir.join("view1.png")).unwrap();
        let r = crate::io::load_rgb(&dir.join("view5.png")).unwrap();
        let range = estimate_range(&l, &r).unwrap().unwrap();
        assert_eq!(range.min, 0, "{range:?}");
        assert!((110..=125).contains(&range.max), "{range:?}");
    }

    #[test]
    fn an_empty_or_too_wide_range_is_refused_by_name() {
        let e = DisparityRange { min: 5, max: 5 }.validate(100).unwrap_err();
        assert!(e.to_string().contains("--min-disparity"), "{e}");
        assert!(DisparityRange { min: -100, max: 5 }.validate(100).is_err());
        assert!(DisparityRange { min: -99, max: 99 }.validate(100).is_ok());
    }
}
