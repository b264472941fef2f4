//! The semi-global matcher's CPU twin: the rule of [`super`], plainly, one level at a time,
//! one path direction at a time over whole cost volumes. The GPU stages
//! ([`super::gpu`], run by [`crate::stereo::matcher::Matcher`]) reproduce it bit for bit.

use super::{p2_across, repeated_floor, window_start, Level, Plan, COST_OUTSIDE, COST_RADIUS, DIRECTIONS, P1};
use crate::error::Result;
use crate::io::{DepthMap, RgbImage};
use crate::stereo::matcher::reference::{census, grey, left_right_check, median_of_known, subpixel, NO_COST};
use crate::stereo::matcher::{check_pair, check_range};

/// Disparities of both eyes of a rectified pair by semi-global matching over
/// 0..=`max_disparity` px (0 = unknown, as the census matcher's
/// [`estimate_disparities`](crate::stereo::matcher::estimate_disparities)). Fails as that
/// does on images of different sizes and on the range.
pub fn estimate_disparities_sgm(left: &RgbImage, right: &RgbImage, max_disparity: u32) -> Result<(DepthMap, DepthMap)> {
    check_pair(left, right)?;
    check_range(left.width, max_disparity)?;
    let plan = Plan::new(left.width, left.height, max_disparity);
    // Grey levels of both eyes at every level.
    let mut greys = vec![(grey(left), grey(right))];
    for pair in plan.levels.windows(2) {
        let (fine, coarse) = (&pair[0], &pair[1]);
        let (gl, gr) = greys.last().unwrap();
        greys.push((downsample(gl, fine, coarse), downsample(gr, fine, coarse)));
    }
    // The coarser level's integer winners of both eyes (before any check).
    let mut guide: Option<(Vec<u32>, Vec<u32>)> = None;
    for l in (0..plan.levels.len()).rev() {
        let level = plan.levels[l];
        let (w, h) = (level.width as usize, level.height as usize);
        let (gl, gr) = &greys[l];
        let (cl, cr) = (census(gl, w, h), census(gr, w, h));
        let starts = |coarse: Option<&Vec<u32>>| -> Vec<u32> {
            match coarse {
                None => vec![0; w * h],
                Some(g) => {
                    let c = &plan.levels[l + 1];
                    (0..w * h)
                        .map(|i| {
                            let (x, y) = ((i % w) / 2, (i / w) / 2);
                            window_start(&level, g[y * c.width as usize + x])
                        })
                        .collect()
                }
            }
        };
        let start_l = starts(guide.as_ref().map(|g| &g.0));
        let start_r = starts(guide.as_ref().map(|g| &g.1));
        let mut costs = cost_volume(&level, &cl, &cr, &start_l);
        if guide.is_none() {
            flatten_repeated(&level, &mut costs);
        }
        let sums = aggregate(&level, gl, &costs, &start_l);
        let wins_l = winners_left(&level, &sums, &start_l);
        let wins_r = winners_right(&level, &sums, &start_l, &start_r);
        if l > 0 {
            guide = Some((
                guides(&wins_l, &start_l, level.window),
                guides(&wins_r, &start_r, level.window),
            ));
            continue;
        }
        let raw = |wins: &[Win]| -> Vec<f32> {
            wins.iter()
                .map(|v| subpixel(v.cost, v.d, v.below, v.above, v.second))
                .collect()
        };
        let (raw_l, raw_r) = (raw(&wins_l), raw(&wins_r));
        let checked_l = left_right_check(&raw_l, &raw_r, w, h, -1.0);
        let checked_r = left_right_check(&raw_r, &raw_l, w, h, 1.0);
        return Ok((
            DepthMap::new(level.width, level.height, median_of_known(&checked_l, w, h))?,
            DepthMap::new(level.width, level.height, median_of_known(&checked_r, w, h))?,
        ));
    }
    unreachable!("a plan has at least one level")
}

/// Grey levels of the next coarser level: the mean of each 2 x 2 block (rounded half up; the
/// last row and column replicated at odd sizes).
fn downsample(grey: &[u16], fine: &Level, coarse: &Level) -> Vec<u16> {
    let (w, h) = (fine.width as usize, fine.height as usize);
    let mut out = Vec::with_capacity(coarse.width as usize * coarse.height as usize);
    for y in 0..coarse.height as usize {
        for x in 0..coarse.width as usize {
            let (x0, y0) = (2 * x, 2 * y);
            let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
            let sum = grey[y0 * w + x0] as u32
                + grey[y0 * w + x1] as u32
                + grey[y1 * w + x0] as u32
                + grey[y1 * w + x1] as u32;
            out.push(((sum + 2) / 4) as u16);
        }
    }
    out
}

/// Cell (p, k) is the cost of disparity `start[p] + k` at pixel p: Hamming distances of the
/// census codes summed over the box (coordinates clamped to the image), [`COST_OUTSIDE`] where
/// the disparity looks outside the right image (x < d).
fn cost_volume(level: &Level, cl: &[u64], cr: &[u64], start: &[u32]) -> Vec<u32> {
    let (w, h, n) = (level.width as i64, level.height as i64, level.window as usize);
    let r = COST_RADIUS as i64;
    let mut out = vec![0u32; level.cells()];
    for y in 0..h {
        for x in 0..w {
            let p = (y * w + x) as usize;
            for k in 0..n {
                let d = (start[p] as usize + k) as i64;
                out[p * n + k] = if x < d {
                    COST_OUTSIDE
                } else {
                    let mut sum = 0;
                    for yy in (y - r..=y + r).map(|v| v.clamp(0, h - 1)) {
                        for xx in (x - r..=x + r).map(|v| v.clamp(0, w - 1)) {
                            let xr = (xx - d).clamp(0, w - 1);
                            sum += (cl[(yy * w + xx) as usize] ^ cr[(yy * w + xr) as usize]).count_ones();
                        }
                    }
                    sum
                };
            }
        }
    }
    out
}

/// The coarsest level's costs (every pixel's window starts at 0) of a repeated texture raised
/// to its [`repeated_floor`]: at pixel x, the disparities 0..=x that look inside the right image.
fn flatten_repeated(level: &Level, costs: &mut [u32]) {
    let (w, n) = (level.width as usize, level.window as usize);
    for (p, cells) in costs.chunks_mut(n).enumerate() {
        let inside = &mut cells[..(p % w + 1).min(n)];
        if let Some(floor) = repeated_floor(inside) {
            for c in inside {
                *c = (*c).max(floor);
            }
        }
    }
}

/// The sum over the 8 directions of the path costs (see [`super`]).
fn aggregate(level: &Level, grey: &[u16], costs: &[u32], start: &[u32]) -> Vec<u32> {
    let (w, h, n) = (level.width as i64, level.height as i64, level.window as usize);
    let mut sums = vec![0u32; level.cells()];
    let mut path = vec![0u32; level.cells()];
    for [dx, dy] in DIRECTIONS {
        // Rows and columns in the order the path runs, so each previous pixel comes first.
        let ys: Vec<i64> = match dy < 0 {
            true => (0..h).rev().collect(),
            false => (0..h).collect(),
        };
        let xs: Vec<i64> = match dx < 0 {
            true => (0..w).rev().collect(),
            false => (0..w).collect(),
        };
        for &y in &ys {
            for &x in &xs {
                let p = (y * w + x) as usize;
                let (qx, qy) = (x - dx as i64, y - dy as i64);
                if qx < 0 || qx >= w || qy < 0 || qy >= h {
                    path[p * n..(p + 1) * n].copy_from_slice(&costs[p * n..(p + 1) * n]);
                } else {
                    let q = (qy * w + qx) as usize;
                    let prev = path[q * n..(q + 1) * n].to_vec();
                    let low = *prev.iter().min().unwrap();
                    let p2 = p2_across((grey[p] as i32 - grey[q] as i32).unsigned_abs());
                    let shift = start[p] as i64 - start[q] as i64;
                    let at = |k: i64| -> u32 {
                        match (0..n as i64).contains(&k) {
                            true => prev[k as usize],
                            false => NO_COST,
                        }
                    };
                    for k in 0..n {
                        // Disparity start[p] + k is index k + shift of q's window.
                        let kq = k as i64 + shift;
                        let best = (low + p2)
                            .min(at(kq))
                            .min(at(kq - 1).saturating_add(P1))
                            .min(at(kq + 1).saturating_add(P1));
                        path[p * n + k] = costs[p * n + k] + best - low;
                    }
                }
                for k in 0..n {
                    sums[p * n + k] += path[p * n + k];
                }
            }
        }
    }
    sums
}

/// One eye's winner at a pixel: the lowest sum and its disparity, the sums one below and above
/// it and the lowest at least two away ([`NO_COST`] where none).
#[derive(Debug, Clone, Copy)]
struct Win {
    cost: u32,
    d: u32,
    below: u32,
    above: u32,
    second: u32,
}

/// The winner over the disparities `d` a pixel offers with `cost(d)` (None: not searched or
/// outside the other image); ties keep the smaller disparity.
fn winner(ds: std::ops::Range<u32>, cost: impl Fn(u32) -> Option<u32>) -> Win {
    let (mut best, mut at) = (NO_COST, 0);
    for d in ds.clone() {
        if let Some(c) = cost(d) {
            if c < best {
                (best, at) = (c, d);
            }
        }
    }
    if best == NO_COST {
        return Win {
            cost: NO_COST,
            d: 0,
            below: NO_COST,
            above: NO_COST,
            second: NO_COST,
        };
    }
    let second = ds
        .filter(|d| d.abs_diff(at) >= 2)
        .filter_map(&cost)
        .min()
        .unwrap_or(NO_COST);
    Win {
        cost: best,
        d: at,
        below: at.checked_sub(1).and_then(&cost).unwrap_or(NO_COST),
        above: cost(at + 1).unwrap_or(NO_COST),
        second,
    }
}

/// The left eye's winners: pixel x offers the disparities of its window up to x.
fn winners_left(level: &Level, sums: &[u32], start: &[u32]) -> Vec<Win> {
    let (w, n) = (level.width as usize, level.window);
    (0..sums.len() / n as usize)
        .map(|p| {
            let (x, s) = ((p % w) as u32, start[p]);
            winner(s..s + n, |d| {
                (d >= s && d < s + n && d <= x).then(|| sums[p * n as usize + (d - s) as usize])
            })
        })
        .collect()
}

/// The right eye's winners: pixel x offers the disparities of its own window whose left pixel
/// x + d is in the image and searched d; the sum is that left pixel's.
fn winners_right(level: &Level, sums: &[u32], start_l: &[u32], start_r: &[u32]) -> Vec<Win> {
    let (w, n) = (level.width as usize, level.window);
    (0..start_r.len())
        .map(|p| {
            let (x, s) = (p % w, start_r[p]);
            let row = p - x;
            winner(s..s + n, |d| {
                let xl = x + d as usize;
                if d < s || d >= s + n || xl >= w {
                    return None;
                }
                let sl = start_l[row + xl];
                (d >= sl && d < sl + n).then(|| sums[(row + xl) * n as usize + (d - sl) as usize])
            })
        })
        .collect()
}

/// The disparities guiding the next finer level: each winner, or its window's middle where the
/// pixel had none.
fn guides(wins: &[Win], start: &[u32], window: u32) -> Vec<u32> {
    wins.iter()
        .zip(start)
        .map(|(v, s)| match v.cost {
            NO_COST => s + (window - 1) / 2,
            _ => v.d,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stereo::matcher::reference::tests::{image, texture};

    /// A textured wall at disparity 6 with a flat grey band across it, textured only at its
    /// ends: the census matcher leaves the band's middle unknown (no trusted minimum), the
    /// semi-global one carries the wall's disparity into it from the texture around.
    #[test]
    fn a_flat_band_takes_the_surrounding_surface_s_disparity() {
        let (w, h, shift) = (96usize, 64usize, 6usize);
        let tex = texture(w + shift, h, 0x5EED_0048);
        let band = |y: usize| (16..48).contains(&y);
        let px = |x: usize, y: usize| match band(y) && (16..w - 8).contains(&x) {
            true => [128, 128, 128],
            false => tex[y * (w + shift) + x],
        };
        let left = image(w, h, px);
        let right = image(w, h, |x, y| px(x + shift, y));
        let inside = |d: &DepthMap| -> (usize, usize) {
            let mut n = 0;
            let mut right_d = 0;
            for y in 28..36 {
                for x in 40..70 {
                    n += 1;
                    right_d += ((d.data[y * w + x] - shift as f32).abs() <= 0.5) as usize;
                }
            }
            (right_d, n)
        };
        let (census_l, _) = crate::stereo::matcher::estimate_disparities(&left, &right, 16).unwrap();
        let (sgm_l, sgm_r) = estimate_disparities_sgm(&left, &right, 16).unwrap();
        let (c, n) = inside(&census_l);
        let (s, _) = inside(&sgm_l);
        println!("in the band: census {c}, semi-global {s} of {n} right");
        assert!(c * 2 < n, "census: {c} of {n} in the band right");
        assert!(s * 10 >= n * 9, "semi-global: {s} of {n} in the band right");
        // Textured rows: both eyes right.
        let good = |d: &DepthMap, xs: std::ops::Range<usize>| {
            (4..12)
                .flat_map(|y| xs.clone().map(move |x| (x, y)))
                .filter(|&(x, y)| (d.data[y * w + x] - shift as f32).abs() <= 0.25)
                .count()
        };
        assert!(good(&sgm_l, 20..80) >= 8 * 60 * 95 / 100);
        assert!(good(&sgm_r, 10..70) >= 8 * 60 * 95 / 100);
    }

    /// A search as wide as the image runs coarse to fine and still finds a constant shift.
    #[test]
    fn a_wide_search_runs_coarse_to_fine_and_finds_the_shift() {
        let (w, h, shift) = (200usize, 48usize, 37usize);
        let tex = texture(w + shift, h, 0x5EED_0049);
        let left = image(w, h, |x, y| tex[y * (w + shift) + x]);
        let right = image(w, h, |x, y| tex[y * (w + shift) + x + shift]);
        assert!(Plan::new(w as u32, h as u32, w as u32 - 1).levels.len() >= 3);
        let (dl, _) = estimate_disparities_sgm(&left, &right, w as u32 - 1).unwrap();
        let judged: Vec<f32> = (8..h - 8)
            .flat_map(|y| (shift + 8..w - 8).map(move |x| (x, y)))
            .map(|(x, y)| dl.data[y * w + x])
            .collect();
        let right_d = judged.iter().filter(|d| (**d - shift as f32).abs() <= 0.25).count();
        assert!(right_d * 100 >= judged.len() * 95, "{right_d} of {}", judged.len());
    }
}
