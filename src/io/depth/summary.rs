//! What a loaded depth map holds, in metres (size, valid fraction, min / median / max), and the
//! signs that it was decoded with the wrong scale or kind: a wrong `--depth-scale`, a missing
//! SUN RGB-D bit rotation, disparity or device depth read as metres all load without error
//! and render a plausible-looking wrong result. Device depth decoded under the wrong NDC range,
//! reversed-Z or planes degenerates instead: nearly every pixel at one plane (Vulkan reversed-Z
//! read as GL standard-Z puts a whole room within a millimetre of the near plane), or a spread
//! no scene has; [`DepthSummary::with_device_planes`] adds those checks.

use std::fmt;

use crate::convention::DepthPlanes;
use crate::io::depth::ranks::ValidRanks;
use crate::io::DepthMap;

/// Medians outside this range (metres) are implausible for RGB-D cameras and most scenes.
pub const PLAUSIBLE_MEDIAN_M: (f64, f64) = (0.05, 20.0);

/// A depth map's statistics; valid = finite and > 0 (the crate's rule).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthSummary {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Number of pixels holding valid depth.
    pub valid: usize,
    /// Valid pixels equal to the largest valid value (a clipped or saturated sensor range).
    pub at_max: usize,
    /// (min, median, max) of the valid values; None when none is valid.
    pub range: Option<(f64, f64, f64)>,
    /// (5th, 95th) percentile of the valid values; None when none is valid.
    pub p05_p95: Option<(f64, f64)>,
    /// The planes device depth was decoded with, when it was ([`Self::with_device_planes`]).
    pub device_planes: Option<DepthPlanes>,
    /// Valid pixels within 10 % of the near plane (device depth only).
    pub at_near: usize,
    /// Valid pixels within 10 % of a finite far plane (device depth only).
    pub at_far: usize,
    /// Invalid pixels are background the input may rightly hold much of (a 360 capture's sky):
    /// no [`DepthWarning::MostlyInvalid`]. Set by [`Self::with_background_expected`].
    pub background_expected: bool,
}

/// A sign of a wrongly decoded depth map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DepthWarning {
    /// No pixel holds valid depth.
    NoValid,
    /// Less than half the pixels hold valid depth.
    MostlyInvalid {
        /// Fraction of pixels with valid depth, in [0, 0.5).
        valid_fraction: f64,
    },
    /// More than half the pixels sit at the largest value of a non-constant map.
    MostlySaturated {
        /// Fraction of all pixels at the largest value.
        fraction: f64,
        /// The largest value, metres.
        value: f64,
    },
    /// The median lies beyond the plausible range (above 20 m): millimetres read as metres, say.
    MedianTooFar {
        /// The median of the valid values, metres.
        median: f64,
    },
    /// The median lies below the plausible range (under 5 cm): too large a scale divisor, say.
    MedianTooNear {
        /// The median of the valid values, metres.
        median: f64,
    },
    /// Device depth: nearly every valid pixel decodes to within 10 % of one plane.
    AtOnePlane {
        /// "near" or "far".
        plane: &'static str,
        /// The plane, metres.
        at_m: f64,
        /// Fraction of the valid pixels there.
        share: f64,
    },
    /// Device depth: the middle 90 % of the pixels spans less than 0.1 % of the median.
    NoSpread {
        /// (95th - 5th percentile) / median.
        relative_spread: f64,
    },
}

/// Share of the valid pixels at one plane that makes decoded device depth degenerate.
const AT_ONE_PLANE: f64 = 0.9;
/// Relative spread of the middle 90 % below which no scene decodes (a wall square to the
/// camera aside).
const NO_SPREAD: f64 = 1e-3;
/// Valid pixels a map needs before its lack of spread says anything (64 x 64).
const NO_SPREAD_MIN_PIXELS: usize = 4096;

impl DepthSummary {
    /// Counts and ranks the valid (finite, > 0) values of `depth`.
    pub fn of(depth: &DepthMap) -> Self {
        let ranks = ValidRanks::of(&depth.data);
        let n = ranks.count;
        let (range, p05_p95, at_max) = if n == 0 {
            (None, None, 0)
        } else {
            let rank = |p: f64| ((p * n as f64).ceil() as usize).clamp(1, n) - 1;
            // The upper median, as `select_nth_unstable(n / 2)` gives.
            let [median, p05, p95] = ranks.values_at([n / 2, rank(0.05), rank(0.95)], &depth.data);
            (
                Some((f64::from(ranks.min), f64::from(median), f64::from(ranks.max))),
                Some((f64::from(p05), f64::from(p95))),
                ranks.at_max,
            )
        };
        DepthSummary {
            width: depth.width,
            height: depth.height,
            valid: ranks.count,
            at_max,
            range,
            p05_p95,
            device_planes: None,
            at_near: 0,
            at_far: 0,
            background_expected: false,
        }
    }

    /// The summary of device depth decoded to view Z (`view_z`, the map summarised) with
    /// `planes`: adds the checks for a degenerate decoding (nearly all at one plane, no spread).
    pub fn with_device_planes(self, view_z: &DepthMap, planes: DepthPlanes) -> Self {
        let valid = || {
            view_z
                .data
                .iter()
                .map(|v| f64::from(*v))
                .filter(|v| v.is_finite() && *v > 0.0)
        };
        DepthSummary {
            device_planes: Some(planes),
            at_near: valid().filter(|z| *z <= 1.1 * planes.near).count(),
            at_far: if planes.far.is_finite() {
                valid().filter(|z| *z >= planes.far / 1.1).count()
            } else {
                0
            },
            ..self
        }
    }

    /// The same summary, for an input where no-surface pixels are expected (cube faces).
    pub fn with_background_expected(self) -> Self {
        DepthSummary {
            background_expected: true,
            ..self
        }
    }

    /// Total pixels, `width * height`.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Fraction of pixels holding valid depth, in [0, 1] (0 for an empty map).
    pub fn valid_fraction(&self) -> f64 {
        self.valid as f64 / self.pixels().max(1) as f64
    }

    /// Everything that suggests a wrong scale or depth kind, most severe first.
    pub fn warnings(&self) -> Vec<DepthWarning> {
        let Some((lo, median, hi)) = self.range else {
            return vec![DepthWarning::NoValid];
        };
        let mut w = Vec::new();
        if self.valid_fraction() < 0.5 && !self.background_expected {
            w.push(DepthWarning::MostlyInvalid {
                valid_fraction: self.valid_fraction(),
            });
        }
        let saturated = self.at_max as f64 / self.pixels().max(1) as f64;
        if lo < hi && saturated > 0.5 {
            w.push(DepthWarning::MostlySaturated {
                fraction: saturated,
                value: hi,
            });
        }
        if let Some(planes) = self.device_planes {
            let valid = self.valid.max(1) as f64;
            for (plane, at_m, count) in [("near", planes.near, self.at_near), ("far", planes.far, self.at_far)] {
                if count as f64 / valid >= AT_ONE_PLANE {
                    w.push(DepthWarning::AtOnePlane {
                        plane,
                        at_m,
                        share: count as f64 / valid,
                    });
                }
            }
            if let Some((p05, p95)) = self.p05_p95 {
                let relative_spread = (p95 - p05) / median;
                // Only over a real image's worth of pixels: a tiny synthetic map may well be flat.
                if relative_spread < NO_SPREAD && self.valid >= NO_SPREAD_MIN_PIXELS && w.is_empty() {
                    w.push(DepthWarning::NoSpread { relative_spread });
                }
            }
        }
        if median > PLAUSIBLE_MEDIAN_M.1 {
            w.push(DepthWarning::MedianTooFar { median });
        } else if median < PLAUSIBLE_MEDIAN_M.0 {
            w.push(DepthWarning::MedianTooNear { median });
        }
        w
    }
}

impl fmt::Display for DepthSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}x{}, {:.1} % valid depth",
            self.width,
            self.height,
            self.valid_fraction() * 100.0
        )?;
        match self.range {
            Some((lo, median, hi)) => write!(f, ", min {lo:.3} / median {median:.3} / max {hi:.3} m"),
            None => Ok(()),
        }
    }
}

impl fmt::Display for DepthWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DepthWarning::NoValid => write!(f, "no pixel holds valid depth"),
            DepthWarning::MostlyInvalid { valid_fraction } => {
                write!(f, "only {:.1} % of the pixels hold valid depth", valid_fraction * 100.0)
            }
            DepthWarning::MostlySaturated { fraction, value } => write!(
                f,
                "{:.1} % of the pixels sit at the largest value ({value:.3} m): saturated or clipped",
                fraction * 100.0
            ),
            DepthWarning::MedianTooFar { median } => write!(
                f,
                "median depth {median:.2} m is implausibly far (> {} m)",
                PLAUSIBLE_MEDIAN_M.1
            ),
            DepthWarning::MedianTooNear { median } => write!(
                f,
                "median depth {median:.4} m is implausibly near (< {} m)",
                PLAUSIBLE_MEDIAN_M.0
            ),
            DepthWarning::AtOnePlane { plane, at_m, share } => write!(
                f,
                "{:.1} % of the pixels decode to within 10 % of the {plane} plane ({at_m} m): no scene \
                 looks like that; device depth read with reversed-Z the wrong way round or with the \
                 wrong planes",
                share * 100.0
            ),
            DepthWarning::NoSpread { relative_spread } => write!(
                f,
                "the middle 90 % of the pixels spans {:.3} % of the median depth: no spread any \
                 scene but a wall square to the camera has; check reversed-Z and the planes",
                relative_spread * 100.0
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(data: Vec<f32>) -> DepthMap {
        let n = data.len() as u32;
        DepthMap::new(n, 1, data).unwrap()
    }

    #[test]
    fn degenerate_device_depth_warns_naming_the_convention_options() {
        let planes = DepthPlanes { near: 0.05, far: 100.0 };
        // The case: Vulkan reversed-Z depth read as GL standard-Z, 0.0500 to 0.0513 m.
        let z = map((0..10_000).map(|i| 0.05 + 1.3e-7 * i as f32).collect());
        let w = DepthSummary::of(&z).with_device_planes(&z, planes).warnings();
        assert!(
            matches!(w[..], [DepthWarning::AtOnePlane { plane: "near", share, .. }] if share == 1.0),
            "{w:?}"
        );
        // The library names no option: each command's hint names its own (a warning once
        // suggested --ndc to cyclopean, which takes its conventions from cameras.json).
        let text = w[0].to_string();
        assert!(
            text.contains("reversed-Z") && text.contains("planes") && !text.contains("--"),
            "{text}"
        );
        // Nearly all at the far plane.
        let z = map((0..10_000).map(|i| 95.0 + 1e-4 * i as f32).collect());
        let w = DepthSummary::of(&z).with_device_planes(&z, planes).warnings();
        assert!(
            w.iter()
                .any(|w| matches!(w, DepthWarning::AtOnePlane { plane: "far", .. })),
            "{w:?}"
        );
        // 10,000 pixels within 0.01 % of 3 m: no spread; a scene from 1 to 6 m: plausible.
        let z = map((0..10_000).map(|i| 3.0 + 3e-8 * i as f32).collect());
        let w = DepthSummary::of(&z).with_device_planes(&z, planes).warnings();
        assert!(matches!(w[..], [DepthWarning::NoSpread { .. }]), "{w:?}");
        let z = map((0..10_000).map(|i| 1.0 + 5e-4 * i as f32).collect());
        assert!(DepthSummary::of(&z)
            .with_device_planes(&z, planes)
            .warnings()
            .is_empty());
        // Linear depth is not checked for planes it was never written with.
        let z = map(vec![0.05; 10_000]);
        assert!(!DepthSummary::of(&z)
            .warnings()
            .iter()
            .any(|w| matches!(w, DepthWarning::AtOnePlane { .. })));
    }

    #[test]
    fn statistics_skip_invalid_values() {
        let s = DepthSummary::of(&map(vec![0.0, 2.0, f32::NAN, 1.0, f32::INFINITY, 3.0, -1.0, 4.0]));
        assert_eq!((s.width, s.height, s.valid, s.at_max), (8, 1, 4, 1));
        // Upper median of 1, 2, 3, 4.
        assert_eq!(s.range, Some((1.0, 3.0, 4.0)));
        assert_eq!(s.valid_fraction(), 0.5);
        assert!(s.warnings().is_empty(), "{:?}", s.warnings());
        assert_eq!(
            s.to_string(),
            "8x1, 50.0 % valid depth, min 1.000 / median 3.000 / max 4.000 m"
        );
    }

    #[test]
    fn implausible_medians_warn() {
        let far = DepthSummary::of(&map(vec![54.0, 55.0, 60.0]));
        assert_eq!(far.warnings(), [DepthWarning::MedianTooFar { median: 55.0 }]);
        let near = DepthSummary::of(&map(vec![0.001, 0.002, 0.003]));
        assert_eq!(
            near.warnings(),
            [DepthWarning::MedianTooNear {
                median: f64::from(0.002_f32)
            }]
        );
        let ok = DepthSummary::of(&map(vec![0.06, 19.0, 19.5]));
        assert!(ok.warnings().is_empty());
    }

    #[test]
    fn mostly_invalid_and_saturated_maps_warn() {
        let none = DepthSummary::of(&map(vec![0.0, f32::NAN]));
        assert_eq!((none.range, none.warnings()), (None, vec![DepthWarning::NoValid]));
        assert_eq!(none.to_string(), "2x1, 0.0 % valid depth");
        let sparse = DepthSummary::of(&map(vec![0.0, 0.0, 0.0, 2.0]));
        assert_eq!(
            sparse.warnings(),
            [DepthWarning::MostlyInvalid { valid_fraction: 0.25 }]
        );
        // Cube faces that see sky: background is no sign of a wrong decoding, a bad range is.
        assert!(sparse.with_background_expected().warnings().is_empty());
        let far_sparse = DepthSummary::of(&map(vec![0.0, 0.0, 0.0, 2000.0])).with_background_expected();
        assert_eq!(far_sparse.warnings(), [DepthWarning::MedianTooFar { median: 2000.0 }]);
        let clipped = DepthSummary::of(&map(vec![1.0, 8.0, 8.0, 8.0]));
        assert_eq!(
            clipped.warnings(),
            [DepthWarning::MostlySaturated {
                fraction: 0.75,
                value: 8.0
            }]
        );
        // A flat wall is not saturation.
        assert!(DepthSummary::of(&map(vec![2.0; 4])).warnings().is_empty());
    }
}
