//! Two images alone: the disparity range searched (given ends, the others estimated from the
//! images), both eyes' disparities from the stereo matcher, and those below the minimum
//! confidence made unknown.

use super::plan::{CyclopeanPlan, InputName};
use super::reuse::Reused;
use crate::io::{DepthMap, RgbImage};
use crate::pass::Device;
use crate::stereo::matcher::range::{estimate_range, DisparityRange, SignedSearch};
use crate::stereo::matcher::{EyeEstimate, Matcher};

/// The matcher's search range for two images alone when none is given and the images give none
/// (too little texture for the coarse pass): a sixth of the width
/// (Middlebury's quarter-size pairs need about a seventh), rounded up to 16 px, in 16..=256.
pub fn default_max_disparity(width: u32) -> u32 {
    (width.div_ceil(6).div_ceil(16) * 16).clamp(16, 256)
}

/// An eye's estimated disparities with those below `min` confidence (if any) made unknown (0).
fn confident(eye: &mut EyeEstimate, min: Option<f64>) {
    let Some(min) = min else { return };
    for (v, c) in eye.disparity.data.iter_mut().zip(&eye.confidence.data) {
        if f64::from(*c) < min {
            *v = 0.0;
        }
    }
}

/// A pair alone's disparities ([`CyclopeanPlan::frame`]).
pub(super) struct Estimate {
    /// Left and right disparities, stored as d + offset (0 unknown), the input's columns.
    pub(super) left: DepthMap,
    pub(super) right: DepthMap,
    pub(super) confidence: Option<[DepthMap; 2]>,
    pub(super) offset: u32,
    pub(super) range: DisparityRange,
    pub(super) estimated: bool,
}

impl CyclopeanPlan {
    /// The search range of a pair alone: the ends given, the others estimated from the images
    /// (a lone `--max-disparity` keeps its meaning of a search from 0 where the images show no
    /// negative disparity; without an estimate, 0..=[`default_max_disparity`]). True when an end
    /// was estimated.
    pub(super) fn range(
        &self,
        left: &RgbImage,
        right: &RgbImage,
        left_rgb: InputName,
    ) -> crate::Result<(DisparityRange, bool)> {
        let (lo, hi) = self.range;
        let estimated = match (lo, hi) {
            (Some(_), Some(_)) => None,
            _ => estimate_range(left, right)?,
        };
        let base = estimated.unwrap_or(DisparityRange {
            min: 0,
            max: default_max_disparity(left.width) as i32,
        });
        let range = DisparityRange {
            min: lo.unwrap_or(match hi {
                Some(_) => base.min.min(0),
                None => base.min,
            }),
            max: hi.unwrap_or(match lo {
                Some(lo) => base.max.max(lo + 1),
                None => base.max,
            }),
        };
        range
            .validate(left.width)
            .map_err(|e| left_rgb.error(format!("{} px wide: {e}", left.width)))?;
        Ok((range, lo.is_none() || hi.is_none()))
    }

    /// Both eyes' disparities of a pair alone over its signed range, by the census matcher on
    /// `device` (those below the minimum confidence made unknown), and their confidence when
    /// asked for. Stored as d + offset ([`SignedSearch`]).
    pub(super) fn estimate(
        &self,
        device: &Device,
        left: &RgbImage,
        right: &RgbImage,
        left_rgb: InputName,
        reuse: Option<&mut Reused>,
    ) -> crate::Result<Estimate> {
        let (range, estimated) = self.range(left, right, left_rgb)?;
        let search = SignedSearch::new(range);
        // A negative minimum widens both images by its size: the widened pair must fit the GPU.
        device
            .check_image_size("widened pair", search.width(left.width), left.height)
            .map_err(|e| {
                left_rgb.error(crate::msg![
                    format!(
                        "{} px wide, widened by {} columns for the search {}..{} px (",
                        left.width, search.offset, range.min, range.max
                    ),
                    crate::Field::MinDisparity,
                    "/",
                    crate::Field::MaxDisparity,
                    format!("): {e}")
                ])
            })?;
        let widened;
        let (l, r) = match search.offset {
            0 => (left, right),
            _ => {
                widened = search.widen(left, right)?;
                (&widened.0, &widened.1)
            }
        };
        let mut own;
        let matcher = match reuse {
            Some(re) => re.matcher(device, l.width, l.height, search.max_disparity, self.matcher)?,
            None => {
                own = Matcher::with_method(device, l.width, l.height, search.max_disparity, self.matcher)?;
                &mut own
            }
        };
        // The confidence stage runs only when something reads it.
        let (dl, dr, confidence) = if self.min_confidence.is_none() && !self.confidence {
            let (dl, dr) = matcher.estimate(l, r)?;
            (dl, dr, None)
        } else {
            let [mut el, mut er] = matcher.estimate_with_confidence(l, r)?;
            confident(&mut el, self.min_confidence);
            confident(&mut er, self.min_confidence);
            let confidence = match self.confidence {
                true => {
                    let (cl, cr) = search.crop(el.confidence, er.confidence, left.width)?;
                    Some([cl, cr])
                }
                false => None,
            };
            (el.disparity, er.disparity, confidence)
        };
        let (dl, dr) = search.crop(dl, dr, left.width)?;
        Ok(Estimate {
            left: dl,
            right: dr,
            confidence,
            offset: search.offset,
            range,
            estimated,
        })
    }
}
