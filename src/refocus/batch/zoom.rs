//! Random zoom for augmentation (`--zoom-random LO,HI --samples K --seed S`): K focal scales per
//! frame, drawn from the seed and the frame's name alone, so a rerun, a resumed run and any
//! sharding of the manifest draw the same scales for the same frame.
//!
//! Log-uniform in [LO, HI]: a focal scale acts multiplicatively (zooming in by 1.5 and out by
//! 1 / 1.5 are the same change of field of view), so log-uniform draws zoom-in and zoom-out
//! around the geometric mean equally often; uniform draws in [0.6, 1.8] would zoom in 2 times out
//! of 3. The stream is SplitMix64 seeded with FNV-1a 64 of the name mixed with the seed: both are
//! fixed, documented functions (std's hasher is randomly keyed per process and may change between
//! releases), so the scales are stable across runs, machines and versions.

use crate::error::{Error, Result};
use serde::Serialize;

/// Most samples a frame may draw (each target costs a render and its files).
pub const MAX_SAMPLES: usize = 256;

/// K random focal scales per frame in [lo, hi], log-uniform, from `seed` and the frame's name.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ZoomRandom {
    /// Smallest scale, > 0.
    pub lo: f64,
    /// Largest scale, > lo.
    pub hi: f64,
    /// Scales drawn per frame.
    pub samples: usize,
    /// The seed; with the frame's name it decides the scales.
    pub seed: u64,
}

impl ZoomRandom {
    /// Checks the range and the sample count; errors name `--zoom-random` or `--samples`.
    pub fn new(lo: f64, hi: f64, samples: usize, seed: u64) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
            return Err(Error::param(
                crate::Field::ZoomRandom,
                crate::msg![
                    format!("{lo},{hi}: expected LO,HI with 0 < LO < HI (a fixed scale is "),
                    crate::Field::ZoomRange,
                    ")"
                ],
            ));
        }
        if samples == 0 || samples > MAX_SAMPLES {
            return Err(Error::param(
                crate::Field::Samples,
                format!("{samples}: expected 1 to {MAX_SAMPLES} scales per frame"),
            ));
        }
        // A frame's scales have distinct file tags (6 decimals): the range must hold as many.
        let tags = tag_number(hi) - tag_number(lo) + 1;
        if tags < samples as u64 {
            return Err(Error::param(
                crate::msg![crate::Field::ZoomRandom, "/", crate::Field::Samples],
                crate::msg![
                    format!(
                        "{lo},{hi} holds {tags} distinct scale{} at the 6 decimals of the file tags, \
                         fewer than the {samples} samples asked for per frame; widen the range or \
                         lower ",
                        if tags == 1 { "" } else { "s" }
                    ),
                    crate::Field::Samples
                ],
            ));
        }
        Ok(ZoomRandom { lo, hi, samples, seed })
    }

    /// The frame's scales, in draw order. Scales that would share a file tag (6 decimals) are
    /// drawn again, so a frame's K targets are K different scales.
    pub fn scales(&self, frame: &str) -> Vec<f64> {
        let mut rng = SplitMix64(fnv1a64(frame.as_bytes()) ^ splitmix(self.seed));
        let (ln_lo, ln_hi) = (self.lo.ln(), self.hi.ln());
        let mut out: Vec<f64> = Vec::with_capacity(self.samples);
        let taken = |out: &[f64], s: f64| out.iter().any(|&o| tag_number(o) == tag_number(s));
        // `new` checked that the range holds enough tags, but a tag at an end may cover almost
        // none of it: past this many draws the rest are taken in order (a bounded loop).
        let mut draws = MAX_DRAWS_PER_SAMPLE * self.samples;
        while out.len() < self.samples && draws > 0 {
            draws -= 1;
            // 53 random bits -> [0, 1); clamped because exp(ln x) may round past the ends.
            let t = (rng.next() >> 11) as f64 / (1u64 << 53) as f64;
            let s = (ln_lo + t * (ln_hi - ln_lo)).exp().clamp(self.lo, self.hi);
            if !taken(&out, s) {
                out.push(s);
            }
        }
        let mut tag = tag_number(self.lo);
        while out.len() < self.samples && tag <= tag_number(self.hi) {
            // The tag's own value, or the range's end where the tag's value lies outside it.
            let s = (tag as f64 / 1e6).clamp(self.lo, self.hi);
            if !taken(&out, s) {
                out.push(s);
            }
            tag += 1;
        }
        out
    }

    /// File-name tags of a frame's targets: `z{k}_s{scale}`, unique within the frame by k.
    pub fn tags(scales: &[f64]) -> Vec<String> {
        scales
            .iter()
            .enumerate()
            .map(|(k, &s)| format!("z{k}_{}", super::super::manifest::scale_tag(s)))
            .collect()
    }
}

/// Draws per sample before the remaining scales are taken in tag order.
const MAX_DRAWS_PER_SAMPLE: usize = 64;

/// A scale's file tag as a whole number: its value in millionths, rounded as the tag's text
/// (`manifest::scale_tag`, 6 decimals) rounds it.
fn tag_number(scale: f64) -> u64 {
    format!("{scale:.6}").replace('.', "").parse().unwrap_or(0)
}

/// FNV-1a, 64 bits.
fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// SplitMix64's output function.
fn splitmix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        splitmix(self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_are_in_range_distinct_per_frame_and_differ_between_frames() {
        let z = ZoomRandom::new(0.6, 1.8, 3, 7).unwrap();
        let (a, b) = (z.scales("f0"), z.scales("f1"));
        for s in [&a, &b] {
            assert_eq!(s.len(), 3);
            assert!(s.iter().all(|&x| (0.6..=1.8).contains(&x)), "{s:?}");
            assert!(s[0] != s[1] && s[1] != s[2] && s[0] != s[2], "{s:?}");
        }
        assert_ne!(a, b);
        // Deterministic: the same call again, and another seed differs.
        assert_eq!(z.scales("f0"), a);
        assert_ne!(ZoomRandom::new(0.6, 1.8, 3, 8).unwrap().scales("f0"), a);
        let tags = ZoomRandom::tags(&a);
        assert!(tags[0].starts_with("z0_s") && tags[2].starts_with("z2_s"), "{tags:?}");
    }

    #[test]
    fn the_stream_is_pinned() {
        // FNV-1a 64 test vectors, and the first scales of a fixed frame: a change to either
        // function would silently change every dataset made before it.
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        let s = ZoomRandom::new(0.6, 1.8, 2, 7).unwrap().scales("frame");
        let again = ZoomRandom::new(0.6, 1.8, 2, 7).unwrap().scales("frame");
        assert_eq!(s, again);
        assert_eq!(format!("{:.6},{:.6}", s[0], s[1]), PINNED);
    }

    const PINNED: &str = "0.678064,1.538551";

    #[test]
    fn log_uniform_draws_zoom_in_and_out_equally_often() {
        // Around the geometric mean sqrt(0.5 * 2) = 1: about half below, half above.
        let z = ZoomRandom::new(0.5, 2.0, 1, 1).unwrap();
        let below = (0..4000).filter(|i| z.scales(&format!("f{i}"))[0] < 1.0).count();
        assert!((1800..=2200).contains(&below), "{below} of 4000 below 1");
    }

    #[test]
    fn a_range_with_fewer_tags_than_samples_is_refused_and_a_tight_one_ends() {
        // 1..1.0000001 rounds to one tag (s1): two samples cannot be distinct (this looped).
        let e = ZoomRandom::new(1.0, 1.0000001, 2, 0).unwrap_err().to_string();
        assert!(
            e.contains("--zoom-random/--samples") && e.contains("1 distinct scale"),
            "{e}"
        );
        // Exactly as many tags as samples, the end tags covering a sliver of the range
        // (1.0000004999 rounds to s1, 1.0000035001 to s1.000004): every tag is taken, each
        // once, in a bounded number of draws.
        let z = ZoomRandom::new(1.0000004999, 1.0000035001, 5, 3).unwrap();
        let scales = z.scales("f");
        assert!(scales.iter().all(|s| (z.lo..=z.hi).contains(s)), "{scales:?}");
        let mut tags: Vec<u64> = scales.iter().map(|&s| tag_number(s)).collect();
        tags.sort_unstable();
        assert_eq!(tags, (1_000_000..=1_000_004).collect::<Vec<u64>>());
    }

    #[test]
    fn bad_ranges_and_counts_are_refused_by_name() {
        assert!(ZoomRandom::new(0.0, 1.0, 1, 0)
            .unwrap_err()
            .to_string()
            .contains("--zoom-random"));
        assert!(ZoomRandom::new(2.0, 1.0, 1, 0)
            .unwrap_err()
            .to_string()
            .contains("--zoom-random"));
        assert!(ZoomRandom::new(1.0, f64::INFINITY, 1, 0).is_err());
        assert!(ZoomRandom::new(0.5, 1.0, 0, 0)
            .unwrap_err()
            .to_string()
            .contains("--samples"));
    }
}
