//! Two images alone: the disparity range searched (given ends, the others estimated from the
//! images), both eyes' disparities from the stereo matcher, and those below the minimum
//! confidence made unknown.

use super::plan::{CyclopeanPlan, InputName};
use super::reuse::Reused;
use crate::io::{DepthMap, RgbImage};
use crate::pass::Device;
use crate::stereo::matcher::range::{estimate_range, DisparityRange, SignedSearch};
use crate::stereo::matcher::MatcherMethod;

/// Highest confidence an inferred disparity carries (`--confidence`, `--min-confidence`): the
/// semi-global matcher took it from the surface around, not from its own costs.
pub const INFERRED_CONFIDENCE: f32 = 0.25;

/// The matcher's disparities of a pair, the matched ones where the matcher is the semi-global
/// one, and their confidences where asked for.
struct Matched {
    disparity: [DepthMap; 2],
    /// The semi-global disparities the census matcher's supports ([`crate::stereo::trust`]).
    matched: Option<[DepthMap; 2]>,
    confidence: Option<[DepthMap; 2]>,
}

/// Both eyes' disparities of the (widened) pair by `method` over 0..=`max_disparity`, on a
/// sequence's `reuse` or a matcher made for the call (the semi-global one checked, in the same
/// run); the confidence stage runs only `with_confidence`.
fn run_matcher(
    device: &Device,
    reuse: Option<&mut Reused>,
    method: MatcherMethod,
    (l, r): (&RgbImage, &RgbImage),
    max_disparity: u32,
    with_confidence: bool,
) -> crate::Result<Matched> {
    let mut own;
    let matcher = match reuse {
        Some(re) => re.matcher(device, l.width, l.height, max_disparity, method)?,
        None => {
            own = Reused::make_matcher(device, l.width, l.height, max_disparity, method)?;
            &mut own
        }
    };
    Ok(match (method, with_confidence) {
        (MatcherMethod::Sgm, _) => {
            let c = matcher.estimate_checked(l, r, with_confidence)?;
            Matched {
                disparity: c.disparity,
                matched: Some(c.matched),
                confidence: c.confidence,
            }
        }
        (MatcherMethod::Census, true) => {
            let [el, er] = matcher.estimate_with_confidence(l, r)?;
            Matched {
                disparity: [el.disparity, er.disparity],
                matched: None,
                confidence: Some([el.confidence, er.confidence]),
            }
        }
        (MatcherMethod::Census, false) => {
            let (dl, dr) = matcher.estimate(l, r)?;
            Matched {
                disparity: [dl, dr],
                matched: None,
                confidence: None,
            }
        }
    })
}

/// The confidence of each disparity of `all` that `matched` leaves out (an inferred one) held
/// to [`INFERRED_CONFIDENCE`].
fn cap_inferred(confidence: &mut DepthMap, all: &DepthMap, matched: &DepthMap) {
    for ((c, a), m) in confidence.data.iter_mut().zip(&all.data).zip(&matched.data) {
        if *a > 0.0 && *m <= 0.0 {
            *c = c.min(INFERRED_CONFIDENCE);
        }
    }
}

/// The matcher's search range for two images alone when none is given and the images give none
/// (too little texture for the coarse pass): a sixth of the width
/// (Middlebury's quarter-size pairs need about a seventh), rounded up to 16 px, in 16..=256.
pub fn default_max_disparity(width: u32) -> u32 {
    (width.div_ceil(6).div_ceil(16) * 16).clamp(16, 256)
}

/// Disparities whose `confidence` is below `min` made unknown (0).
fn confident(disparity: &mut DepthMap, confidence: &DepthMap, min: f64) {
    for (v, c) in disparity.data.iter_mut().zip(&confidence.data) {
        if f64::from(*c) < min {
            *v = 0.0;
        }
    }
}

/// A pair alone's disparities ([`CyclopeanPlan::frame`]).
pub(super) struct Estimate {
    /// Left and right matched disparities, stored as d + offset (0 unknown), the input's
    /// columns: what renders as 255 in the mask.
    pub(super) left: DepthMap,
    pub(super) right: DepthMap,
    /// With the semi-global matcher, both eyes' disparities inferred ones included: what the
    /// dense frame (`--fill`) starts from. None: `left` and `right` are all there is.
    pub(super) with_inferred: Option<(DepthMap, DepthMap)>,
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

    /// Both eyes' disparities of a pair alone over its signed range, by the plan's matcher on
    /// `device` (those below the minimum confidence made unknown; the semi-global one's split
    /// into matched and inferred), and their confidence when asked for. Stored as d + offset ([`SignedSearch`]).
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
        // The confidence stage runs only when something reads it.
        let with_confidence = self.min_confidence.is_some() || self.confidence;
        let m = run_matcher(
            device,
            reuse,
            self.matcher,
            (l, r),
            search.max_disparity,
            with_confidence,
        )?;
        let [dl, dr] = m.disparity;
        let (mut dl, mut dr) = search.crop(dl, dr, left.width)?;
        let mut confidence = match m.confidence {
            Some([cl, cr]) => Some(search.crop(cl, cr, left.width)?),
            None => None,
        };
        // The semi-global matcher's disparities split into matched and inferred by the census
        // matcher's on the same pair (stereo::trust), in the matcher's own run.
        let mut matched = match m.matched {
            Some([ml, mr]) => {
                let (ml, mr) = search.crop(ml, mr, left.width)?;
                if let Some((kl, kr)) = confidence.as_mut() {
                    cap_inferred(kl, &dl, &ml);
                    cap_inferred(kr, &dr, &mr);
                }
                Some((ml, mr))
            }
            None => None,
        };
        if let (Some(min), Some((kl, kr))) = (self.min_confidence, &confidence) {
            confident(&mut dl, kl, min);
            confident(&mut dr, kr, min);
            if let Some((ml, mr)) = matched.as_mut() {
                confident(ml, kl, min);
                confident(mr, kr, min);
            }
        }
        // Matched disparities render as 255 in the mask; the dense frame (--fill) starts from
        // every disparity, inferred ones included.
        let (left_map, right_map, with_inferred) = match matched {
            Some((ml, mr)) => (ml, mr, Some((dl, dr))),
            None => (dl, dr, None),
        };
        Ok(Estimate {
            left: left_map,
            right: right_map,
            with_inferred,
            confidence: confidence.filter(|_| self.confidence).map(|(l, r)| [l, r]),
            offset: search.offset,
            range,
            estimated,
        })
    }
}
