//! The semi-global matcher (issue 48): the census matcher's cost with smoothness, so that a
//! region without texture takes its disparity from the surface around it instead of being left
//! unknown.
//!
//! Design (Hirschmüller's semi-global matching, integers throughout):
//! - Cost: the census matcher's Hamming distance (its 7 x 5 census of grey = r + g + b) summed
//!   over a 5 x 5 box, borders replicated; a disparity that looks outside the right image
//!   (x < d) costs [`COST_OUTSIDE`].
//! - Repeated texture (the coarsest level, whose pixels see the whole search): where a
//!   pixel's costs have a second basin, a local minimum at least [`REPEAT_GAP`] disparities from
//!   the lowest cost with a ridge between them ([`REPEAT_RIDGE_PERCENT`] % of the way from the
//!   lowest cost to the mean), whose floor is nearly as low ([`REPEAT_SECOND_PERCENT`] % of that
//!   way), the data cannot say which period is the surface's; every cost is raised to that
//!   floor, so both basins are flat and the paths (the surface around) decide
//!   ([`repeated_floor`]). Stripes that repeat every few pixels otherwise match one period off
//!   wherever that shift lines up better, in both eyes alike, which no check catches.
//! - Path costs along 8 directions: L(p, d) = C(p, d) + min(L(q, d), L(q, d +- 1) + [`P1`],
//!   min_k L(q, k) + P2') - min_k L(q, k), q the previous pixel on the path; P2' is [`P2`]
//!   lowered across a strong grey edge between q and p (divided by |dI| / [`EDGE_GREY`] above
//!   it, never below P1 + 1). Their sum S is the aggregated cost.
//! - Winner takes all on S, the right eye from the same sums (its pixel x at disparity d is the
//!   left pixel x + d's), then the census matcher's uniqueness test, sub-pixel parabola,
//!   left-right check and 3 x 3 median, unchanged.
//! - The work does not grow with the search: a search wider than [`FULL_SEARCH`] disparities
//!   (or a volume above [`MAX_CELLS`]) is matched on a 2x-downsampled pair first (recursively,
//!   grey levels averaged), and each finer level searches only a window of [`WINDOW`]
//!   disparities around twice the coarser level's winner. [`Plan`] lays the levels out; its
//!   cell count is the work.
//!
//! The CPU twin is [`reference`]; the GPU stages ([`gpu`], run by [`super::Matcher`]) compute the same integers, so the two
//! give the same disparities bit for bit.

pub(crate) mod gpu;
pub mod reference;

pub use reference::estimate_disparities_sgm;

/// Half-size of the box the Hamming costs are summed over (5 x 5).
pub const COST_RADIUS: usize = 2;
/// Largest cost of a cell: every bit of every census code of the box differs.
pub const COST_MAX: u32 = 34 * ((2 * COST_RADIUS as u32 + 1) * (2 * COST_RADIUS as u32 + 1));
/// Cost of a disparity that looks outside the right image (x < d): below an uncorrelated
/// match's (about half the bits differ, 425), so that paths run through the left border's
/// strip without a bias against the larger disparities. Measured: [`COST_MAX`] there cost
/// 0.5 dB over the issue-48 pairs.
pub const COST_OUTSIDE: u32 = 306;
/// Nearest disparity to the lowest cost where a second basin's floor may lie (a repeated texture's
/// period is at least this).
pub const REPEAT_GAP: usize = 3;
/// A second basin's floor counts when it is within this share (percent) of the way from the
/// lowest cost to the mean cost of the pixel's disparities.
pub const REPEAT_SECOND_PERCENT: u32 = 35;
/// ... and the costs between the two rise above it by at least this share (percent) of that way.
pub const REPEAT_RIDGE_PERCENT: u32 = 30;
/// Penalty of a disparity change of one along a path (a slanted surface).
pub const P1: u32 = 60;
/// Penalty of a larger change (a depth edge), before the edge lowering.
pub const P2: u32 = 1000;
/// Grey difference (of r + g + b) above which P2 is lowered in proportion.
pub const EDGE_GREY: u32 = 24;
/// Widest search matched in one level: a wider one starts on a downsampled pair.
pub const FULL_SEARCH: u32 = 64;
/// Largest cost volume (cells) of the coarsest level.
pub const MAX_CELLS: usize = 1 << 24;
/// Disparities a finer level searches around twice the coarser level's winner.
pub const WINDOW: u32 = 5;
/// The 8 path directions (dx, dy): the previous pixel of p on a path is p - (dx, dy).
pub const DIRECTIONS: [[i32; 2]; 8] = [[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [-1, -1], [1, -1], [-1, 1]];

// Sums of 8 path costs fit the 16-bit lanes the winner stage shares with the census matcher.
const _: () = assert!(8 * (COST_MAX + P2) < 0xffff);

/// One level of the pyramid: its size, its search 0..=`max_disparity`, and the disparities
/// each pixel searches (`window` of them from a per-pixel start).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Level {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Largest disparity at this level.
    pub max_disparity: u32,
    /// Disparities searched per pixel: the whole range at the coarsest level, [`WINDOW`] (or
    /// fewer, when the range is narrower) at the finer ones.
    pub window: u32,
}

impl Level {
    /// Cells of the level's cost volume.
    pub fn cells(&self) -> usize {
        self.width as usize * self.height as usize * self.window as usize
    }
}

/// The levels of a search, finest (the pair itself) first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plan {
    /// Level 0 is the pair; each next one half its size (rounded up), searching half as far.
    pub levels: Vec<Level>,
}

impl Plan {
    /// The levels for a `width` x `height` pair searched over 0..=`max_disparity`.
    pub fn new(width: u32, height: u32, max_disparity: u32) -> Plan {
        let (mut w, mut h, mut d) = (width, height, max_disparity);
        let mut sizes = vec![(w, h, d)];
        // Down to a 1 x 1 level if need be: the coarsest window must fit the path stage's arrays.
        while d + 1 > FULL_SEARCH || (w as usize * h as usize * (d as usize + 1) > MAX_CELLS && (w > 1 || h > 1)) {
            (w, h, d) = (w.div_ceil(2), h.div_ceil(2), d.div_ceil(2));
            sizes.push((w, h, d));
        }
        let coarsest = sizes.len() - 1;
        let levels = sizes
            .into_iter()
            .enumerate()
            .map(|(l, (width, height, max_disparity))| Level {
                width,
                height,
                max_disparity,
                window: match l == coarsest {
                    true => max_disparity + 1,
                    false => WINDOW.min(max_disparity + 1),
                },
            })
            .collect();
        Plan { levels }
    }

    /// Cost-volume cells over all levels: the work (each cell is costed once and updated along
    /// each of the 8 paths).
    pub fn cells(&self) -> usize {
        self.levels.iter().map(Level::cells).sum()
    }
}

/// The first disparity a pixel of a finer level searches: its window of `level.window`
/// disparities centred on `2 guide`, the coarser level's winner at (x / 2, y / 2) doubled,
/// moved inside 0..=`level.max_disparity`.
pub fn window_start(level: &Level, guide: u32) -> u32 {
    let half = (level.window - 1) / 2;
    let top = level.max_disparity + 1 - level.window;
    (2 * guide).saturating_sub(half).min(top)
}

/// The floor every cost of a pixel is raised to when its costs `cells` (disparities 0.., those
/// that look inside the right image) show a repeated texture (see the design above), or None:
/// the lowest local minimum at least [`REPEAT_GAP`] from the lowest cost (the first of equal
/// ones) with a ridge between them, if it is near enough to the lowest cost. Integers only, so
/// the GPU's cost stage finds the same floor.
pub fn repeated_floor(cells: &[u32]) -> Option<u32> {
    let m = cells.len();
    if m < 2 * REPEAT_GAP + 1 {
        return None;
    }
    let (mut d1, mut m1) = (0, cells[0]);
    for (k, &c) in cells.iter().enumerate() {
        if c < m1 {
            (d1, m1) = (k, c);
        }
    }
    // m x (mean - lowest): the way from the lowest cost to the mean, times m.
    let spread = cells.iter().sum::<u32>() - m1 * m as u32;
    let local_min = |k: usize| (k == 0 || cells[k] <= cells[k - 1]) && (k + 1 == m || cells[k] <= cells[k + 1]);
    let mut second = None::<u32>;
    for side in [&mut (d1 + 1..m) as &mut dyn Iterator<Item = usize>, &mut (0..d1).rev()] {
        let mut ridge = m1;
        for k in side {
            let c = cells[k];
            ridge = ridge.max(c);
            if k.abs_diff(d1) >= REPEAT_GAP
                && local_min(k)
                && (ridge - c) * 100 * m as u32 >= REPEAT_RIDGE_PERCENT * spread
            {
                second = Some(second.map_or(c, |s| s.min(c)));
            }
        }
    }
    second.filter(|&s| (s - m1) * 100 * (m as u32) < REPEAT_SECOND_PERCENT * spread)
}

/// P2 between the previous pixel on a path and this one, whose grey levels differ by `dgrey`.
pub fn p2_across(dgrey: u32) -> u32 {
    match dgrey > EDGE_GREY {
        true => (P2 * EDGE_GREY / dgrey).max(P1 + 1),
        false => P2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The GLSL constants (shaders/cyclopean/matcher_sgm.glsl) are the Rust ones.
    #[test]
    fn the_shader_constants_are_the_twins() {
        let glsl = include_str!("../../../../shaders/cyclopean/matcher_sgm.glsl");
        for line in [
            format!("const int COST_RADIUS = {COST_RADIUS};"),
            format!("const uint COST_MAX = {COST_MAX}u;"),
            format!("const uint COST_OUTSIDE = {COST_OUTSIDE}u;"),
            format!("const uint P1 = {P1}u;"),
            format!("const uint P2 = {P2}u;"),
            format!("const uint EDGE_GREY = {EDGE_GREY}u;"),
            format!("const int FULL_SEARCH = {FULL_SEARCH};"),
            format!("const int REPEAT_GAP = {REPEAT_GAP};"),
            format!("const uint REPEAT_SECOND_PERCENT = {REPEAT_SECOND_PERCENT}u;"),
            format!("const uint REPEAT_RIDGE_PERCENT = {REPEAT_RIDGE_PERCENT}u;"),
            format!("const int WINDOW = {WINDOW};"),
        ] {
            assert!(glsl.contains(&line), "matcher_sgm.glsl lacks `{line}`");
        }
    }

    #[test]
    fn a_search_as_wide_as_the_image_is_bounded_work() {
        // 0..=w-1 at any width: the cells stay within a few per pixel and level 0 searches a
        // window, not the range.
        for (w, h) in [
            (640u32, 480u32),
            (1280, 720),
            (4096, 2160),
            (16384, 64),
            (1001, 8),
            (3000, 1),
        ] {
            let plan = Plan::new(w, h, w - 1);
            let pixels = w as usize * h as usize;
            assert_eq!(plan.levels[0].window, WINDOW);
            let coarsest = plan.levels.last().unwrap();
            assert!(coarsest.window <= FULL_SEARCH, "{plan:?}");
            assert!(coarsest.cells() <= MAX_CELLS.max(coarsest.width as usize * coarsest.height as usize * 2));
            // Finer levels: WINDOW cells a pixel over a geometric series (4/3 the finest).
            assert!(
                plan.cells() <= 2 * WINDOW as usize * pixels + coarsest.cells(),
                "{w}x{h}: {} cells, {plan:?}",
                plan.cells()
            );
        }
        // A narrow search is one level over the whole range.
        let plan = Plan::new(450, 375, 40);
        assert_eq!(plan.levels.len(), 1);
        assert_eq!(plan.levels[0].window, 41);
    }

    #[test]
    fn a_window_stays_in_the_range_around_the_doubled_guide() {
        let level = Level {
            width: 8,
            height: 8,
            max_disparity: 20,
            window: 5,
        };
        assert_eq!(window_start(&level, 0), 0);
        assert_eq!(window_start(&level, 5), 8);
        assert_eq!(window_start(&level, 10), 16);
        assert_eq!(window_start(&level, 11), 16);
        assert_eq!(p2_across(0), P2);
        assert_eq!(p2_across(2 * EDGE_GREY), P2 / 2);
        assert_eq!(p2_across(765), (P2 * EDGE_GREY / 765).max(P1 + 1));
    }

    /// A pixel's costs over 24 disparities: uncorrelated (425, half the bits) but for basins at
    /// `dips` (disparity, floor), each with walls of floor + 100 and floor + 200 on both sides.
    fn curve(dips: &[(usize, u32)]) -> Vec<u32> {
        let mut c = vec![425u32; 24];
        for &(d, floor) in dips {
            c[d] = floor;
            for (k, wall) in [(1, 100), (2, 200)] {
                c[d - k] = c[d - k].min(floor + wall);
                c[d + k] = c[d + k].min(floor + wall);
            }
        }
        c
    }

    #[test]
    fn a_second_basin_nearly_as_low_is_a_repeated_texture() {
        // Tsukuba 2+4's binder labels at left pixel (66, 74), disparities 5..=24 (recomputed in
        // NumPy from the census rule): 45 at 19 px (one period off), 149 at the surface's 10 px.
        let labels = [
            687, 532, 465, 303, 245, 149, 320, 489, 499, 740, 511, 480, 335, 295, 45, 298, 404, 476, 670, 626,
        ];
        assert_eq!(repeated_floor(&labels), Some(149));
        assert_eq!(repeated_floor(&curve(&[(10, 120), (19, 45)])), Some(120));
        // Either side of the lowest cost; the lower of two other basins.
        assert_eq!(repeated_floor(&curve(&[(4, 45), (15, 120)])), Some(120));
        assert_eq!(repeated_floor(&curve(&[(4, 130), (12, 45), (20, 120)])), Some(120));
        // One basin, or a second one well above it: the data decide.
        assert_eq!(repeated_floor(&curve(&[(19, 45)])), None);
        assert_eq!(repeated_floor(&curve(&[(10, 250), (19, 45)])), None);
        // A local minimum within REPEAT_GAP of the lowest cost is its own basin's wall.
        let mut c = curve(&[(19, 45)]);
        c[17] = 60;
        assert_eq!(repeated_floor(&c), None);
        c[16] = 60;
        c[17] = 300;
        assert_eq!(repeated_floor(&c), Some(60));
        // No ridge between: one wide valley with a dent, not two periods.
        let mut c = curve(&[(19, 45)]);
        for (k, v) in c.iter_mut().enumerate().take(19).skip(10) {
            *v = 120 + (k as u32 - 10);
        }
        assert_eq!(repeated_floor(&c), None);
        // Too few disparities to tell (fewer than 2 REPEAT_GAP + 1), and a flat curve.
        assert_eq!(repeated_floor(&[300, 45, 300, 50, 300, 300]), None);
        assert_eq!(repeated_floor(&[300; 24]), None);
    }
}
