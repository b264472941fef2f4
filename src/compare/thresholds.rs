//! `compare`'s pass/fail limits for CI. Beside the limits on a whole-image figure (RMSE, PSNR,
//! largest depth error, FLIP mean) there is a gate by share: at most this fraction of the
//! compared pixels may be bad, a pixel being bad when its error is over a per-pixel threshold.
//! A share gate passes a run that one stray pixel would fail on a maximum.

use super::{Comparison, DepthShare};
use crate::error::{Error, Result};

/// When a pixel counts as bad for `--max-bad-share`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BadPixel {
    /// Colour: the largest channel difference is over this many 8-bit levels.
    pub color_levels: f64,
    /// Depth: the relative view-Z error |A - B| / A is over this (pixels valid in both), or
    /// the pixel is valid on one side only.
    pub depth_rel: f64,
}

impl Default for BadPixel {
    /// 8 levels (3 % of the range: past rounding and dithering, as rasterisers differ at
    /// edges) and 1e-3 (1 mm at 1 m; f32 window depth converts to 1e-5 or better).
    fn default() -> Self {
        BadPixel {
            color_levels: 8.0,
            depth_rel: 1e-3,
        }
    }
}

/// Pass/fail limits for `compare` in CI; unset limits are not checked.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Thresholds {
    /// Largest colour RMSE allowed, 8-bit levels.
    pub max_color_rmse: Option<f64>,
    /// Smallest colour PSNR allowed, dB (inf: identical colour required).
    #[serde(serialize_with = "super::optional_infinite_as_string")]
    pub min_psnr_db: Option<f64>,
    /// Largest relative view-Z error allowed over pixels valid in both.
    pub max_depth_rel: Option<f64>,
    /// Largest share of bad pixels allowed, colour and depth each (a fraction in [0, 1]; depth:
    /// of the pixels with depth on either side, [`DepthShare`]).
    pub max_bad_share: Option<f64>,
    /// What makes a pixel bad for `max_bad_share` (also reported without that gate).
    pub bad: BadPixel,
    /// Largest FLIP mean allowed, in [0, 1].
    pub max_flip_mean: Option<f64>,
}

impl Thresholds {
    /// Refuses a negative or non-finite limit, a share outside [0, 1] and a NaN PSNR limit,
    /// naming the option.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("max-colour-rmse", self.max_color_rmse),
            ("max-depth-rel", self.max_depth_rel),
            ("max-flip", self.max_flip_mean),
            ("bad-colour", Some(self.bad.color_levels)),
            ("bad-depth-rel", Some(self.bad.depth_rel)),
        ] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(Error::param(name, format!("{v}: must be finite and >= 0")));
            }
        }
        if let Some(v) = self.max_bad_share.filter(|v| !(0.0..=1.0).contains(v)) {
            return Err(Error::param(
                "max-bad-share",
                format!("{v}: a share of the pixels, in [0, 1] (0.001 = 0.1 %)"),
            ));
        }
        if let Some(v) = self.min_psnr_db.filter(|v| v.is_nan()) {
            return Err(Error::param("min-psnr", format!("{v} is not a number")));
        }
        Ok(())
    }

    /// The limits `c` breaks, each as a sentence with the measured value.
    pub fn broken(&self, c: &Comparison) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(max) = self.max_color_rmse.filter(|max| c.color_rmse > *max) {
            out.push(format!("colour RMSE {:.4} > {max} levels", c.color_rmse));
        }
        if let Some(min) = self.min_psnr_db.filter(|min| c.psnr_db < *min) {
            out.push(format!("PSNR {:.2} dB < {min} dB", c.psnr_db));
        }
        if let Some(max) = self.max_depth_rel {
            match c.depth_max_rel {
                Some(rel) if rel > max => out.push(format!("max relative depth error {rel:.3e} > {max:e}")),
                Some(_) => {}
                None => out.push("max relative depth error: no depth was compared".into()),
            }
        }
        if let Some(max) = self.max_bad_share {
            let level = self.bad.color_levels;
            match c.color_error.share_over(level) {
                Some(s) if s > max => out.push(format!(
                    "{} of the pixels differ in colour by more than {level} levels > {}",
                    percent(s),
                    percent(max)
                )),
                Some(_) => {}
                None => out.push(format!("share over {level} levels: not measured")),
            }
            // Depth only where both sides have it: a colour-only comparison is gated on colour.
            // A pixel valid on one side only is bad (a surface against none), and the share is
            // over every pixel with depth on either side; no such pixel compared nothing: a
            // share of nothing is no pass.
            let rel = self.bad.depth_rel;
            match &c.depth_bad {
                None => {}
                Some(DepthShare { share: None, .. }) => out.push(format!(
                    "share over relative depth error {rel:e}: no pixel holds valid depth on either side, \
                     nothing was compared"
                )),
                Some(d @ DepthShare { share: Some(s), .. }) if *s > max => out.push(format!(
                    "{} of the pixels with depth are bad ({} over relative depth error {rel:e} + {} valid on \
                     one side only, of {}) > {}",
                    percent(*s),
                    d.over_threshold,
                    d.one_side,
                    d.denominator,
                    percent(max)
                )),
                Some(_) => {}
            }
        }
        if let Some(max) = self.max_flip_mean {
            match c.flip_mean {
                Some(m) if m > max => out.push(format!("FLIP mean {m:.4} > {max}")),
                Some(_) => {}
                None => out.push("FLIP mean: not measured".into()),
            }
        }
        out
    }
}

/// A share as a percentage with enough digits for a one-in-a-million pixel.
pub fn percent(share: f64) -> String {
    let p = share * 100.0;
    if p == 0.0 || p >= 0.1 {
        format!("{p:.2} %")
    } else {
        format!("{p:.1e} %")
    }
}

/// A relative tolerance as a percentage ("1 %", "0.1 %").
pub(super) fn relative(tolerance: f64) -> String {
    format!("{} %", (tolerance * 100.0 * 1e6).round() / 1e6)
}
