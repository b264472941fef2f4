//! What a loaded disparity map holds, in pixels (size, valid fraction, min / median / max), and
//! the signs that it was decoded with the wrong `--disparity-scale`: a range no rectified pair
//! of that width has, or views that agree at another scale ([`ScaleFit`]). Middlebury 2003's
//! 4 units a pixel read as 1 rendered a doubled view at exit 0 with nothing said.

use std::fmt;

use crate::field::{Field, Message};
use crate::io::depth::disparity_fit::ScaleFit;
use crate::io::{DepthMap, DepthSummary};
use crate::msg;

/// A 95th-percentile disparity beyond this share of the image width is implausible: the
/// widest common rigs (KITTI) stay under a fifth of it; Cones read at 1 instead of 4 is 45 %.
pub const PLAUSIBLE_P95_WIDTH_SHARE: f64 = 0.3;

/// A disparity map's statistics; valid = finite and > 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisparitySummary {
    /// Counts and ranks, the values read as pixels.
    pub stats: DepthSummary,
    /// The scale it was decoded with (raw units per pixel).
    pub scale: f64,
    /// The photometric check against the pair, when both views and maps were at hand.
    pub fit: Option<ScaleFit>,
}

/// A sign of a wrongly decoded disparity map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DisparityWarning {
    /// No pixel holds a valid disparity.
    NoValid,
    /// Less than half the pixels hold a valid disparity.
    MostlyInvalid {
        /// Fraction of valid pixels, in [0, 0.5).
        valid_fraction: f64,
    },
    /// The 95th percentile spans more than [`PLAUSIBLE_P95_WIDTH_SHARE`] of the width.
    TooWide {
        /// 95th percentile, pixels.
        p95: f64,
        /// Image width, pixels.
        width: u32,
        /// The scale given.
        scale: f64,
    },
    /// The views agree far better at another scale.
    OtherScaleFits {
        /// The scale that fits.
        scale: f64,
        /// Its mean grey difference.
        error: f64,
        /// The scale given.
        given: f64,
        /// The given scale's mean grey difference (None: most shifts left the view).
        given_error: Option<f64>,
    },
}

impl DisparitySummary {
    /// The statistics of `map` (pixels) decoded at `scale`, with the pair's check if any.
    pub fn of(map: &DepthMap, scale: f64, fit: Option<ScaleFit>) -> Self {
        DisparitySummary {
            stats: DepthSummary::of(map),
            scale,
            fit,
        }
    }

    /// Everything that suggests a wrong scale, most telling first.
    pub fn warnings(&self) -> Vec<DisparityWarning> {
        let s = &self.stats;
        if s.range.is_none() {
            return vec![DisparityWarning::NoValid];
        }
        let mut w = Vec::new();
        if let Some(fit) = self.fit {
            if let Some(scale) = fit.better() {
                w.push(DisparityWarning::OtherScaleFits {
                    scale,
                    error: fit.best.1,
                    given: fit.given,
                    given_error: fit.given_error,
                });
            }
        }
        if let Some((_, p95)) = s.p05_p95 {
            if p95 > PLAUSIBLE_P95_WIDTH_SHARE * f64::from(s.width) {
                w.push(DisparityWarning::TooWide {
                    p95,
                    width: s.width,
                    scale: self.scale,
                });
            }
        }
        if s.valid_fraction() < 0.5 {
            w.push(DisparityWarning::MostlyInvalid {
                valid_fraction: s.valid_fraction(),
            });
        }
        w
    }
}

impl fmt::Display for DisparitySummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.stats;
        write!(
            f,
            "{}x{}, {:.1} % valid disparity",
            s.width,
            s.height,
            s.valid_fraction() * 100.0
        )?;
        if let Some((lo, median, hi)) = s.range {
            write!(f, ", min {lo:.2} / median {median:.2} / max {hi:.2} px")?;
        }
        write!(f, " at {} {}", Field::DisparityScale, self.scale)
    }
}

impl DisparityWarning {
    /// The warning, naming the option that sets the scale.
    pub fn message(&self) -> Message {
        match *self {
            DisparityWarning::NoValid => msg!["no pixel holds a valid disparity (> 0)"],
            DisparityWarning::MostlyInvalid { valid_fraction } => msg![format!(
                "only {:.1} % of the pixels hold a valid disparity",
                valid_fraction * 100.0
            )],
            DisparityWarning::TooWide { p95, width, scale } => msg![
                format!(
                    "95 % of the disparities reach {p95:.1} px, {:.0} % of the {width} px width: implausible \
                     for a rectified pair; check ",
                    100.0 * p95 / f64::from(width)
                ),
                Field::DisparityScale,
                format!(" (given {scale}; raw units per pixel, 4 for Middlebury 2003)")
            ],
            DisparityWarning::OtherScaleFits {
                scale,
                error,
                given,
                given_error,
            } => msg![
                "the views agree far better at ",
                Field::DisparityScale,
                format!(" {scale} (mean grey difference {error:.1} "),
                match given_error {
                    Some(e) => format!("against {e:.1} at the scale given, {given})"),
                    None => format!("; at the scale given, {given}, most shifts leave the view)"),
                },
                ": pass ",
                Field::DisparityScale,
                format!(" {scale} if that is how the maps are stored")
            ],
        }
    }
}

impl fmt::Display for DisparityWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.message().fmt(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(width: u32, data: Vec<f32>) -> DepthMap {
        let h = data.len() as u32 / width;
        DepthMap::new(width, h, data).unwrap()
    }

    #[test]
    fn a_range_too_wide_for_the_image_names_the_scale_option() {
        // 100 px wide: 95 % of the values at 40 px exceed 30 % of the width.
        let wide = DisparitySummary::of(&map(100, vec![40.0; 100]), 1.0, None);
        let w = wide.warnings();
        assert!(matches!(w[..], [DisparityWarning::TooWide { width: 100, .. }]), "{w:?}");
        assert!(w[0].to_string().contains("--disparity-scale"), "{}", w[0]);
        let ok = DisparitySummary::of(&map(100, vec![10.0; 100]), 4.0, None);
        assert!(ok.warnings().is_empty());
        assert_eq!(
            ok.to_string(),
            "100x1, 100.0 % valid disparity, min 10.00 / median 10.00 / max 10.00 px at --disparity-scale 4"
        );
        let none = DisparitySummary::of(&map(2, vec![0.0, f32::NAN]), 1.0, None);
        assert_eq!(none.warnings(), [DisparityWarning::NoValid]);
    }

    #[test]
    fn a_better_fitting_scale_is_named_with_its_value() {
        let fit = ScaleFit {
            given: 1.0,
            given_error: Some(38.2),
            best: (4.0, 6.8),
        };
        let s = DisparitySummary::of(&map(100, vec![10.0; 100]), 1.0, Some(fit));
        let w = s.warnings();
        assert!(
            matches!(w[..], [DisparityWarning::OtherScaleFits { scale, .. }] if scale == 4.0),
            "{w:?}"
        );
        assert!(w[0].to_string().contains("--disparity-scale 4 "), "{}", w[0]);
        // Only clearly better counts.
        let close = ScaleFit {
            best: (4.0, 25.0),
            ..fit
        };
        assert!(DisparitySummary::of(&map(100, vec![10.0; 100]), 1.0, Some(close))
            .warnings()
            .is_empty());
    }
}
