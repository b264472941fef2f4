//! Order statistics of a depth map's valid values (finite, > 0) without copying or sorting
//! them: positive finite f32s order as their bit patterns, so a histogram of the top 16 bits
//! finds the bucket holding each rank, and a selection among that bucket's values the exact
//! value. Two linear passes give what `select_nth_unstable` gives on a copy of the valid values;
//! the copy and three selections cost ~3 ms of every VGA batch frame's decode.

const BUCKETS: usize = 1 << 16;

fn is_valid(v: f32) -> bool {
    v.is_finite() && v > 0.0
}

fn high(v: f32) -> usize {
    (v.to_bits() >> 16) as usize
}

/// The valid values' count, extremes and top-16-bit histogram.
pub(super) struct ValidRanks {
    /// Valid values.
    pub count: usize,
    /// Smallest valid value (f32::MAX when none).
    pub min: f32,
    /// Largest valid value (f32::MIN when none).
    pub max: f32,
    /// Valid values equal to `max`.
    pub at_max: usize,
    histogram: Vec<u64>,
}

impl ValidRanks {
    /// One pass over `data`.
    pub fn of(data: &[f32]) -> Self {
        let mut histogram = vec![0u64; BUCKETS];
        let (mut min, mut max, mut at_max, mut count) = (f32::MAX, f32::MIN, 0usize, 0usize);
        for &v in data.iter().filter(|v| is_valid(**v)) {
            histogram[high(v)] += 1;
            count += 1;
            min = min.min(v);
            if v > max {
                (max, at_max) = (v, 1);
            } else if v == max {
                at_max += 1;
            }
        }
        ValidRanks {
            count,
            min,
            max,
            at_max,
            histogram,
        }
    }

    /// The valid values at 0-based `ranks` in ascending order (each < `count`), from the same
    /// `data` this was made of: one more pass over it.
    pub fn values_at<const N: usize>(&self, ranks: [usize; N], data: &[f32]) -> [f32; N] {
        // Each rank's bucket and its rank inside the bucket.
        let located = ranks.map(|r| {
            let mut below = 0u64;
            let r = r as u64;
            for (bucket, &n) in self.histogram.iter().enumerate() {
                if below + n > r {
                    return (bucket, r - below);
                }
                below += n;
            }
            // `ranks` are below `count`, the histogram's total, so the loop returned.
            unreachable!("rank {r} of {} valid values", self.count)
        });
        let mut buckets: Vec<usize> = located.iter().map(|l| l.0).collect();
        buckets.sort_unstable();
        buckets.dedup();
        // The values of those buckets (a few hundred each in a camera's depth map; at most the
        // valid values when all share one bucket), then an exact selection inside each.
        let mut members: Vec<Vec<f32>> = buckets
            .iter()
            .map(|&b| Vec::with_capacity(self.histogram[b] as usize))
            .collect();
        for &v in data.iter().filter(|v| is_valid(**v)) {
            if let Some(k) = buckets.iter().position(|&b| b == high(v)) {
                members[k].push(v);
            }
        }
        located.map(|(bucket, r)| {
            // `buckets` is the set of the located buckets.
            let k = buckets.iter().position(|&b| b == bucket).expect("bucket listed");
            *members[k].select_nth_unstable_by(r as usize, f32::total_cmp).1
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition: the sorted valid values.
    fn sorted_valid(data: &[f32]) -> Vec<f32> {
        let mut v: Vec<f32> = data.iter().copied().filter(|v| is_valid(*v)).collect();
        v.sort_by(f32::total_cmp);
        v
    }

    #[test]
    fn every_rank_is_the_sorted_valid_value() {
        // Ties, invalid values of every kind, subnormals, a wide range and values sharing a
        // top-16-bit bucket (1.0 and its next floats).
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut data: Vec<f32> = (0..20_000)
            .map(|_| match next() % 8 {
                0 => 0.0,
                1 => [f32::NAN, f32::INFINITY, -1.0, -0.0, f32::NEG_INFINITY][(next() % 5) as usize],
                2 => f32::from_bits(1.0f32.to_bits() + (next() % 300) as u32),
                3 => f32::from_bits((next() % 1000) as u32 + 1),
                4 => 2.5,
                _ => (next() % 1_000_000) as f32 * 1e-3 + 0.001,
            })
            .collect();
        data.push(f32::MAX);
        let sorted = sorted_valid(&data);
        let ranks = ValidRanks::of(&data);
        assert_eq!(ranks.count, sorted.len());
        assert_eq!((ranks.min, ranks.max), (sorted[0], *sorted.last().unwrap()));
        assert_eq!(ranks.at_max, 1);
        for r in (0..sorted.len()).step_by(97).chain([sorted.len() - 1]) {
            let [a, b] = ranks.values_at([r, sorted.len() - 1 - r], &data);
            assert_eq!(
                (a.to_bits(), b.to_bits()),
                (sorted[r].to_bits(), sorted[sorted.len() - 1 - r].to_bits()),
                "rank {r}"
            );
        }
    }

    #[test]
    fn one_value_and_all_equal_values() {
        let data = [0.0, 3.0, f32::NAN];
        let r = ValidRanks::of(&data);
        assert_eq!((r.count, r.min, r.max, r.at_max), (1, 3.0, 3.0, 1));
        assert_eq!(r.values_at([0, 0, 0], &data), [3.0; 3]);
        let data = vec![1.25; 1000];
        let r = ValidRanks::of(&data);
        assert_eq!((r.count, r.at_max), (1000, 1000));
        assert_eq!(r.values_at([0, 500, 999], &data), [1.25; 3]);
    }
}
