//! The spread of a per-pixel error over the compared pixels: median, p99, p99.9, maximum and the
//! share of pixels over each threshold. A maximum alone lets one stray pixel decide a CI run;
//! the share over a threshold is what a gate should read.

/// The share of the compared pixels whose error is strictly over `threshold`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ShareOver {
    /// The per-pixel threshold, in the error's unit.
    pub threshold: f64,
    /// Fraction of the compared pixels over it, in [0, 1].
    pub share: f64,
}

/// Order statistics of a per-pixel error (nearest rank: the p-quantile is the smallest value
/// with at least p of the pixels at or below it).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ErrorDistribution {
    /// Pixels measured.
    pub pixels: usize,
    /// Half the pixels are at or below this.
    pub median: f64,
    /// 99 % of the pixels are at or below this.
    pub p99: f64,
    /// 99.9 % of the pixels are at or below this.
    #[serde(rename = "p99_9")]
    pub p999: f64,
    /// The largest error.
    pub max: f64,
    /// The share over each threshold, thresholds ascending.
    pub share_over: Vec<ShareOver>,
}

impl ErrorDistribution {
    /// The distribution of `errors` (NaN is not an error value: callers leave such pixels
    /// out), with the share over each of `thresholds`; None when `errors` is empty.
    pub fn of(mut errors: Vec<f64>, thresholds: &[f64]) -> Option<Self> {
        if errors.is_empty() {
            return None;
        }
        errors.sort_unstable_by(f64::total_cmp);
        let n = errors.len();
        let rank = |p: f64| errors[((p * n as f64).ceil() as usize).clamp(1, n) - 1];
        let mut ts: Vec<f64> = thresholds.iter().copied().filter(|t| t.is_finite()).collect();
        ts.sort_unstable_by(f64::total_cmp);
        ts.dedup();
        let share_over = ts
            .into_iter()
            .map(|threshold| {
                // Errors are sorted: the count at or below the threshold is a partition point.
                let at_or_below = errors.partition_point(|e| *e <= threshold);
                ShareOver {
                    threshold,
                    share: (n - at_or_below) as f64 / n as f64,
                }
            })
            .collect();
        Some(ErrorDistribution {
            pixels: n,
            median: rank(0.5),
            p99: rank(0.99),
            p999: rank(0.999),
            max: errors[n - 1],
            share_over,
        })
    }

    /// The share over `threshold`, if it was one of the thresholds measured.
    pub fn share_over(&self, threshold: f64) -> Option<f64> {
        self.share_over
            .iter()
            .find(|s| s.threshold == threshold)
            .map(|s| s.share)
    }
}

#[cfg(test)]
mod tests {
    use super::ErrorDistribution;

    #[test]
    fn nearest_rank_quantiles_and_strict_shares() {
        // 1000 pixels: 0, 1, ..., 999.
        let d = ErrorDistribution::of((0..1000).map(f64::from).collect(), &[499.0, 989.0, 5000.0]).unwrap();
        assert_eq!(
            (d.pixels, d.median, d.p99, d.p999, d.max),
            (1000, 499.0, 989.0, 998.0, 999.0)
        );
        assert_eq!(d.share_over(499.0), Some(0.5));
        assert_eq!(d.share_over(989.0), Some(0.01));
        assert_eq!(d.share_over(5000.0), Some(0.0));
        assert_eq!(d.share_over(1.0), None);
        // One stray pixel in a million moves the maximum only.
        let mut e = vec![0.0; 1_000_000];
        e[123] = 1.4;
        let d = ErrorDistribution::of(e, &[1e-3]).unwrap();
        assert_eq!((d.median, d.p99, d.p999, d.max), (0.0, 0.0, 0.0, 1.4));
        assert_eq!(d.share_over(1e-3), Some(1e-6));
        assert!(ErrorDistribution::of(Vec::new(), &[1.0]).is_none());
        // A single pixel is every quantile.
        let d = ErrorDistribution::of(vec![3.0], &[]).unwrap();
        assert_eq!((d.median, d.p99, d.p999, d.max), (3.0, 3.0, 3.0, 3.0));
    }
}
