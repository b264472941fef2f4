//! The CPU twin of the trust stage ([`super::trust`]): the same rule, bit for bit what the GPU
//! writes (tests in `viewsynth_tests`' `cyclopean::trust`).

use super::matcher::{CENSUS_HALF_H, CENSUS_HALF_W};
use super::trust::{check, AGREE_PX, FLAT_GREY};
use crate::error::Result;
use crate::io::{DepthMap, RgbImage};

/// The twin of the trust stage ([`super::trust`]; [`Matcher::estimate_checked`](super::matcher::Matcher::estimate_checked)'s `matched`): `semi_global`'s disparities the
/// census matcher's `census` agrees with, or whose census window in `color` is flat; 0 elsewhere.
pub fn trust_reference(semi_global: &DepthMap, census: &DepthMap, color: &RgbImage) -> Result<DepthMap> {
    check(semi_global, census, color)?;
    let (w, h) = (color.width as i64, color.height as i64);
    let grey = |x: i64, y: i64| {
        let i = 3 * (y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize;
        color.data[i..i + 3].iter().map(|c| *c as i32).sum::<i32>()
    };
    let (hw, hh) = (CENSUS_HALF_W as i64, CENSUS_HALF_H as i64);
    let mut out = vec![0.0f32; semi_global.data.len()];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (s, c) = (semi_global.data[i], census.data[i]);
            if s <= 0.0 {
                continue;
            }
            let matched = match c > 0.0 {
                true => (s - c).abs() <= AGREE_PX,
                false => {
                    let window = (-hh..=hh).flat_map(|dy| (-hw..=hw).map(move |dx| grey(x + dx, y + dy)));
                    let (lo, hi) = window.fold((i32::MAX, i32::MIN), |(lo, hi), g| (lo.min(g), hi.max(g)));
                    hi - lo <= FLAT_GREY
                }
            };
            if matched {
                out[i] = s;
            }
        }
    }
    DepthMap::new(color.width, color.height, out)
}
