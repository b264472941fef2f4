//! The CPU twin of the densify pass ([`super::densify`]): the same integer weights and walk,
//! bit for bit what the GPU writes (tests in `viewsynth_tests`' `cyclopean::densify` and
//! `cyclopean::given_disparities`).

use super::densify::{check, weight, Dense, OtherEye, FILLED, OUT_OF_FRAME_PERCENT, QUANTILE_PERCENT, RADIUS};
use crate::error::Result;
use crate::io::{DepthMap, RgbImage};

/// The twin of [`Densifier::densify`]: the same rule on the CPU.
pub fn densify_reference(disparity: &DepthMap, color: &RgbImage, other: OtherEye) -> Result<Dense> {
    check(disparity, color)?;
    let (w, h) = (disparity.width as i64, disparity.height as i64);
    let at = |x: i64, y: i64| disparity.data[(y * w + x) as usize];
    let rgb = |x: i64, y: i64| {
        let i = 3 * (y * w + x) as usize;
        [color.data[i], color.data[i + 1], color.data[i + 2]]
    };
    let mut out = disparity.data.clone();
    let mut filled = vec![0u8; out.len()];
    for y in 0..h {
        for x in 0..w {
            if at(x, y) > 0.0 {
                continue;
            }
            let c = rgb(x, y);
            let mut candidates: Vec<(f32, u32, bool)> = super::walk::DIRECTIONS
                .iter()
                .filter_map(|&d| super::walk::first_along((x, y), d, (w, h), RADIUS as i64, |qx, qy| at(qx, qy) > 0.0))
                .map(|((qx, qy), r)| {
                    let cq = rgb(qx, qy);
                    let diff: u32 = (0..3).map(|k| c[k].abs_diff(cq[k]) as u32).sum();
                    let v = at(qx, qy);
                    (v, weight(diff, r as u32), other.outside(x as f32, v, w as f32))
                })
                .collect();
            if candidates.is_empty() {
                continue;
            }
            // Candidates that put p's match outside the other eye's frame explain its being
            // unknown without an occluder: those alone, and no lean to the background.
            let percent = match candidates.iter().any(|c| c.2) {
                true => {
                    candidates.retain(|c| c.2);
                    OUT_OF_FRAME_PERCENT
                }
                false => QUANTILE_PERCENT,
            };
            // Stable: equal disparities keep direction order, as the shader's insertion.
            candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
            let total: u64 = candidates.iter().map(|c| c.1 as u64).sum();
            let mut running = 0u64;
            let pick = candidates
                .iter()
                .position(|c| {
                    running += c.1 as u64;
                    running * 100 >= total * percent as u64
                })
                .unwrap_or(candidates.len() - 1);
            let i = (y * w + x) as usize;
            out[i] = candidates[pick].0;
            filled[i] = FILLED;
        }
    }
    Ok(Dense {
        disparity: DepthMap::new(disparity.width, disparity.height, out)?,
        filled,
    })
}
