//! The CPU twin of the fill pass ([`super::fill`]): the same rule in the shader's f32
//! arithmetic, pixel for pixel what the GPU writes (tests in `viewsynth_tests`'
//! `cyclopean::fill`).

use super::fill::{planes, FILLED, REACH, ROW_LEFT, ROW_RIGHT, SAME_SURFACE};
use crate::error::Result;
use crate::stereo::gather::CyclopeanOutput;

/// The twin of [`Filler::fill`]: the same rule on the CPU, in the shader's f32 arithmetic.
pub fn fill_reference(out: &CyclopeanOutput, width: u32, height: u32) -> Result<CyclopeanOutput> {
    let (color, depth) = planes(out)?;
    let (w, h) = (width as i64, height as i64);
    let valid = |x: i64, y: i64| out.sources[(y * w + x) as usize] != 0;
    let mut filled = out.clone();
    let (fc, fd) = (
        filled.color.as_mut().expect("checked above"),
        filled.depth.as_mut().expect("checked above"),
    );
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if out.sources[i] != 0 {
                continue;
            }
            // (depth, distance, index) of the first rendered pixel along each direction; and
            // whether the row runs off the image either way with none (a border strip).
            let hits: Vec<_> = crate::stereo::walk::DIRECTIONS
                .iter()
                .map(|&d| crate::stereo::walk::first_along((x, y), d, (w, h), w.max(h), valid))
                .collect();
            let (right, left) = (hits[ROW_RIGHT], hits[ROW_LEFT]);
            let border_strip = right.is_none() || left.is_none();
            // Inside, the reach: twice the row's far end. A hole's two sides are across it along
            // the row (the baseline's direction), so a walk along a thin hole that meets a far
            // surface beyond its end is no candidate.
            let reach = match (right, left) {
                (Some((_, a)), Some((_, b))) => REACH * a.max(b),
                _ => i64::MAX,
            };
            let mut candidates: Vec<(f32, i64, usize)> = hits
                .into_iter()
                .flatten()
                .filter(|&(_, r)| r <= reach)
                .map(|((qx, qy), r)| {
                    let j = (qy * w + qx) as usize;
                    (depth.data[j], r, j)
                })
                .collect();
            if candidates.is_empty() {
                fc.data[3 * i..3 * i + 3].fill(0);
                fd.data[i] = 0.0;
                continue;
            }
            // Far to near, stable (the shader's insertion keeps direction order at equal depths).
            candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
            // The layer's seed: the farthest candidate, or in a border strip the nearest one
            // (first of the nearest in far-to-near order); then its chain either way.
            let seed = match border_strip {
                false => 0,
                true => (0..candidates.len())
                    .min_by_key(|&k| candidates[k].1)
                    .expect("not empty"),
            };
            let linked = |k: usize| candidates[k - 1].0 - candidates[k].0 <= SAME_SURFACE * candidates[k - 1].0;
            let (mut lo, mut hi) = (seed, seed + 1);
            while lo > 0 && linked(lo) {
                lo -= 1;
            }
            while hi < candidates.len() && linked(hi) {
                hi += 1;
            }
            let (mut rgb, mut z, mut total) = ([0f32; 3], 0f32, 0f32);
            for &(zq, r, j) in &candidates[lo..hi] {
                let wq = 1.0 / (r * r) as f32;
                for (c, acc) in rgb.iter_mut().enumerate() {
                    *acc += wq * (color.data[3 * j + c] as f32 / 255.0);
                }
                z += wq * zq;
                total += wq;
            }
            for (c, acc) in rgb.iter().enumerate() {
                fc.data[3 * i + c] = ((acc / total) * 255.0).round().clamp(0.0, 255.0) as u8;
            }
            fd.data[i] = z / total;
            filled.sources[i] = FILLED;
        }
    }
    Ok(filled)
}
