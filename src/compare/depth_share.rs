//! Which pixels hold depth on each side, and the depth share gate's reading. A pixel with
//! valid depth on one side only is a disagreement (one renderer saw a surface where the other
//! saw none), so it counts as bad: the share's denominator is every compared pixel with depth
//! on either side, not only those valid in both, and both counts are reported.

/// Depth validity over the compared pixels (after conversion to view Z).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct DepthValidity {
    /// Valid on both sides: their errors are measured.
    pub both: usize,
    /// Valid in A only.
    pub a_only: usize,
    /// Valid in B only.
    pub b_only: usize,
}

impl DepthValidity {
    /// Valid on exactly one side.
    pub fn one_side(&self) -> usize {
        self.a_only + self.b_only
    }

    /// Valid on either side: the depth share's denominator.
    pub fn either(&self) -> usize {
        self.both + self.one_side()
    }
}

/// The bad-depth share at one relative threshold, as the `--max-bad-share` gate reads it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DepthShare {
    /// The per-pixel relative threshold (`--bad-depth-rel`).
    pub threshold: f64,
    /// Pixels valid in both whose |A - B| / A is over the threshold.
    pub over_threshold: usize,
    /// Pixels valid on one side only (each a bad pixel).
    pub one_side: usize,
    /// Pixels with depth on either side: the share's denominator.
    pub denominator: usize,
    /// (over_threshold + one_side) / denominator; None when no pixel has depth on either side.
    pub share: Option<f64>,
}

impl DepthShare {
    /// The share over `threshold` of the relative errors `rel` (pixels valid in both) with the
    /// one-sided pixels of `valid` counted bad.
    pub fn of(rel: &[f64], valid: DepthValidity, threshold: f64) -> Self {
        let over_threshold = rel.iter().filter(|r| **r > threshold).count();
        let denominator = valid.either();
        DepthShare {
            threshold,
            over_threshold,
            one_side: valid.one_side(),
            denominator,
            share: (denominator > 0).then(|| (over_threshold + valid.one_side()) as f64 / denominator as f64),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{DepthShare, DepthValidity};

    #[test]
    fn one_sided_pixels_are_bad_and_in_the_denominator() {
        let valid = DepthValidity {
            both: 8,
            a_only: 1,
            b_only: 1,
        };
        let s = DepthShare::of(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5], valid, 1e-3);
        assert_eq!((s.over_threshold, s.one_side, s.denominator), (1, 2, 10));
        assert_eq!(s.share, Some(0.3));
        // Valid in both nowhere, on one side somewhere: all of it disagrees.
        let s = DepthShare::of(
            &[],
            DepthValidity {
                both: 0,
                a_only: 4,
                b_only: 0,
            },
            1e-3,
        );
        assert_eq!(s.share, Some(1.0));
        assert_eq!(DepthShare::of(&[], DepthValidity::default(), 1e-3).share, None);
    }
}
