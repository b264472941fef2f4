//! The 2.5D grid mesh shared by every refocus path (CPU reference, GPU mesh, GPU full-screen).
//!
//! Vertices sit on source pixel centres, plus a border ring half a pixel outside the image
//! (depth copied from the nearest pixel) so the mesh covers the whole image [-0.5, W - 0.5]:
//! without it the last row and column are lost to the fill rule. Vertex column i (0..=W+1) is
//! at u = -0.5, 0, 1, .., W-1, W-0.5 and takes its depth from pixel clamp(i - 1, 0, W - 1).
//! Cell (i, j) (0..=W, 0..=H) has corners v00 = (i, j), v10 = (i+1, j), v01 = (i, j+1),
//! v11 = (i+1, j+1) and two triangles, tri1 = v00 v10 v11 (local a >= b) and
//! tri2 = v00 v11 v01 (local a <= b), where (a, b) are the cell-local coordinates in [0, 1].

use serde::{Deserialize, Serialize};

/// When an edge between two valid depths is a discontinuity. An edge breaks if
/// |za - zb| > tau_abs OR |za - zb| > tau_rel * min(za, zb) (the seed's two rules, either
/// suffices). A triangle is kept only if its three corners are valid and no edge breaks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BreakRule {
    /// Relative break threshold: an edge breaks when |za - zb| > tau_rel * min(za, zb).
    pub tau_rel: f64,
    /// Metres; `f64::INFINITY` disables the absolute rule.
    pub tau_abs: f64,
}

impl Default for BreakRule {
    /// tau_rel 0.05 (a 5 % jump: 25 cm at 5 m, several times Kinect-class noise) and
    /// tau_abs 0.2 m (the top of the seed's range, so it only bites beyond 4 m).
    fn default() -> Self {
        BreakRule {
            tau_rel: 0.05,
            tau_abs: 0.2,
        }
    }
}

impl BreakRule {
    /// Refuses thresholds that are negative or NaN.
    pub fn validate(&self) -> crate::Result<()> {
        // NaN fails every comparison, so `is_ge` alone rejects it.
        if !self.tau_rel.partial_cmp(&0.0).is_some_and(|o| o.is_ge()) {
            return Err(crate::Error::param("tau-rel", format!("{} must be >= 0", self.tau_rel)));
        }
        if !self.tau_abs.partial_cmp(&0.0).is_some_and(|o| o.is_ge()) {
            return Err(crate::Error::param("tau-abs", format!("{} must be >= 0", self.tau_abs)));
        }
        Ok(())
    }

    /// True if the edge between two valid depths is continuous (kept).
    #[inline]
    pub fn continuous(&self, za: f64, zb: f64) -> bool {
        let d = (za - zb).abs();
        !(d > self.tau_abs || d > self.tau_rel * za.min(zb))
    }
}

/// A depth is valid when finite and positive (0, NaN, +-Inf and negatives are holes).
#[inline]
pub fn valid_depth(z: f32) -> bool {
    z.is_finite() && z > 0.0
}

/// Grid geometry for a W x H source.
#[derive(Debug, Clone, Copy)]
pub struct Grid {
    /// Source width in pixels.
    pub width: u32,
    /// Source height in pixels.
    pub height: u32,
}

pub const TRI1: u8 = 1;
pub const TRI2: u8 = 2;
/// The cell's left edge (vertex column i, rows j..j+1) belongs to a kept triangle.
pub const LEFT_EDGE: u8 = 4;
/// The cell's top edge (vertex row j, columns i..i+1) belongs to a kept triangle.
pub const TOP_EDGE: u8 = 8;
/// The cell's corner vertex (i, j) belongs to a kept triangle.
pub const VERTEX: u8 = 16;

impl Grid {
    /// Source coordinate of vertex column (or row) `i` along an axis of `n` pixels.
    #[inline]
    pub fn vertex_pos(i: i64, n: u32) -> f64 {
        if i <= 0 {
            -0.5
        } else if i > n as i64 {
            n as f64 - 0.5
        } else {
            (i - 1) as f64
        }
    }

    /// Pixel whose depth vertex `i` carries.
    #[inline]
    pub fn vertex_pixel(i: i64, n: u32) -> usize {
        (i - 1).clamp(0, n as i64 - 1) as usize
    }

    /// Cells per row: W + 1 (the border ring adds one).
    pub fn cells_x(&self) -> usize {
        self.width as usize + 1
    }
    /// Cells per column: H + 1.
    pub fn cells_y(&self) -> usize {
        self.height as usize + 1
    }

    /// Depth at vertex (i, j).
    #[inline]
    pub fn vertex_depth(&self, depth: &[f32], i: i64, j: i64) -> f32 {
        depth[Self::vertex_pixel(j, self.height) * self.width as usize + Self::vertex_pixel(i, self.width)]
    }

    /// Per cell, bit TRI1 / TRI2 set where that triangle is kept. Row-major, cells_x wide.
    pub fn keep_mask(&self, depth: &[f32], rule: &BreakRule) -> Vec<u8> {
        let (cx, cy) = (self.cells_x(), self.cells_y());
        let mut out = vec![0u8; cx * cy];
        for j in 0..cy as i64 {
            for i in 0..cx as i64 {
                let z00 = self.vertex_depth(depth, i, j);
                let z10 = self.vertex_depth(depth, i + 1, j);
                let z01 = self.vertex_depth(depth, i, j + 1);
                let z11 = self.vertex_depth(depth, i + 1, j + 1);
                let (v00, v10, v01, v11) = (valid_depth(z00), valid_depth(z10), valid_depth(z01), valid_depth(z11));
                let (z00, z10, z01, z11) = (z00 as f64, z10 as f64, z01 as f64, z11 as f64);
                let diag = v00 && v11 && rule.continuous(z00, z11);
                let mut bits = 0;
                if diag && v10 && rule.continuous(z00, z10) && rule.continuous(z10, z11) {
                    bits |= TRI1;
                }
                if diag && v01 && rule.continuous(z11, z01) && rule.continuous(z00, z01) {
                    bits |= TRI2;
                }
                out[j as usize * cx + i as usize] = bits;
            }
        }
        out
    }

    /// The keep mask plus, per cell, whether its left edge, top edge and top-left vertex belong
    /// to any kept triangle (of this cell or a neighbour). With these, a point on a cell border
    /// is decided from one cell, which is what the full-screen pass reads.
    pub fn coverage_flags(&self, keep: &[u8]) -> Vec<u8> {
        let (cx, cy) = (self.cells_x() as i64, self.cells_y() as i64);
        let at = |i: i64, j: i64| {
            if i < 0 || j < 0 || i >= cx || j >= cy {
                0
            } else {
                keep[(j * cx + i) as usize]
            }
        };
        let mut out = keep.to_vec();
        for j in 0..cy {
            for i in 0..cx {
                let mut bits = at(i, j);
                // Left edge: tri2 of this cell (v00-v01), tri1 of the left cell (v10-v11).
                if bits & TRI2 != 0 || at(i - 1, j) & TRI1 != 0 {
                    bits |= LEFT_EDGE;
                }
                // Top edge: tri1 of this cell (v00-v10), tri2 of the cell above (v01-v11).
                if bits & TRI1 != 0 || at(i, j - 1) & TRI2 != 0 {
                    bits |= TOP_EDGE;
                }
                // Vertex (i, j): v00 here, v11 up-left (both), v10 of the left cell (tri1), v01
                // of the cell above (tri2).
                if at(i, j) != 0 || at(i - 1, j - 1) != 0 || at(i - 1, j) & TRI1 != 0 || at(i, j - 1) & TRI2 != 0 {
                    bits |= VERTEX;
                }
                out[(j * cx + i) as usize] = bits;
            }
        }
        out
    }

    /// Vertices (W+2) x (H+2) whose six incident triangles are all kept (the outer ring never
    /// is: its outside neighbours do not exist).
    pub fn surrounded_vertices(&self, keep: &[u8]) -> Vec<bool> {
        let (cx, cy) = (self.cells_x() as i64, self.cells_y() as i64);
        let at = |i: i64, j: i64| {
            if i < 0 || j < 0 || i >= cx || j >= cy {
                0
            } else {
                keep[(j * cx + i) as usize]
            }
        };
        let both = TRI1 | TRI2;
        let mut out = vec![false; ((cx + 1) * (cy + 1)) as usize];
        for j in 0..=cy {
            for i in 0..=cx {
                out[(j * (cx + 1) + i) as usize] = at(i, j) == both
                    && at(i - 1, j - 1) == both
                    && at(i - 1, j) & TRI1 != 0
                    && at(i, j - 1) & TRI2 != 0;
            }
        }
        out
    }

    /// Grid vertex ids (i + j (W+2)) of the corners of triangle `code`, in the order tri1:
    /// v00 v10 v11, tri2: v00 v11 v01 (the order the shaders use).
    pub fn triangle_vertices(&self, code: u32) -> [u32; 3] {
        let cells_x = self.cells_x() as u32;
        let (cell, tri2) = (code >> 1, code & 1 == 1);
        let (i, j) = (cell % cells_x, cell / cells_x);
        let row = cells_x + 1;
        let v = |di: u32, dj: u32| (j + dj) * row + i + di;
        if tri2 {
            [v(0, 0), v(1, 1), v(0, 1)]
        } else {
            [v(0, 0), v(1, 0), v(1, 1)]
        }
    }

    /// Kept triangles split into interior ones (every corner surrounded by kept triangles: a
    /// pixel centre the rasteriser gives them lies in a kept triangle whatever the fill rule)
    /// and boundary ones (the rest), as codes.
    pub fn split_kept_triangles(&self, keep: &[u8]) -> (Vec<u32>, Vec<u32>) {
        let surrounded = self.surrounded_vertices(keep);
        let (mut interior, mut boundary) = (Vec::new(), Vec::new());
        for code in self.kept_triangles(keep) {
            if self.triangle_vertices(code).iter().all(|&v| surrounded[v as usize]) {
                interior.push(code);
            } else {
                boundary.push(code);
            }
        }
        (interior, boundary)
    }

    /// Kept triangles as codes `(cell_index << 1) | (tri2 ? 1 : 0)`, for the mesh path.
    pub fn kept_triangles(&self, keep: &[u8]) -> Vec<u32> {
        let mut out = Vec::with_capacity(keep.len());
        for (cell, &bits) in keep.iter().enumerate() {
            if bits & TRI1 != 0 {
                out.push((cell as u32) << 1);
            }
            if bits & TRI2 != 0 {
                out.push(((cell as u32) << 1) | 1);
            }
        }
        out
    }
}

/// Closed-triangle tolerance in cell units, shared with the shaders (CELL_EPS): it only has to
/// absorb the f32 rounding of cell-local coordinates computed in double (~6e-8), and a point
/// within it of a border is valued on that border, so it also bounds that depth error
/// (1e-5 x the depth change across the cell).
pub const CELL_EPS: f64 = 1e-5;

/// The source-image span, along an axis of `n` pixels, of the points the lookups locate (the
/// grid with its border ring, [-0.5, n - 0.5], widened by half the closed tolerance): the source
/// frame as the passes see it. `--rgb-everywhere` colours exactly the points inside it on both
/// axes, so the twin uses it too.
pub fn frame_span(n: u32) -> (f64, f64) {
    (-0.5 - 0.5 * CELL_EPS, n as f64 - 0.5 + 0.5 * CELL_EPS)
}

/// Same-pose lookup along one axis, for the full-screen path: for each target column (or row)
/// x, the source coordinate u = c_src + (x - c_dst) * ratio is located in f64 and stored as
/// [cell, local coordinate in it, 1 if u lies on (within CELL_EPS of) the cell's left/top
/// border else 0, unused]; cell = -1 where u is outside the mesh. A point on a border between
/// two cells is always given to the right/lower cell, so one cell's coverage flags decide it.
/// The mapping is separable: W' + H' of these replace per-pixel double arithmetic.
pub fn axis_lookup(n_src: u32, c_src: f64, c_dst: f64, ratio: f64, n_dst: u32) -> Vec<[f32; 4]> {
    let n = n_src as i64;
    let (lo, hi) = frame_span(n_src);
    let local = |u: f64, i: i64| {
        let x0 = Grid::vertex_pos(i, n_src);
        (u - x0) / (Grid::vertex_pos(i + 1, n_src) - x0)
    };
    (0..n_dst)
        .map(|x| {
            let u = c_src + (x as f64 - c_dst) * ratio;
            if !(u >= lo && u <= hi) {
                return [-1.0, 0.0, 0.0, 0.0];
            }
            let mut i = ((u.floor() as i64) + 1).clamp(0, n);
            let mut a = local(u, i);
            if a >= 1.0 - CELL_EPS && i < n {
                i += 1;
                a = local(u, i);
            }
            let border = (a <= CELL_EPS) as u8;
            [i as f32, a as f32, border as f32, 0.0]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn border_ring_spans_the_whole_image() {
        assert_eq!(Grid::vertex_pos(0, 4), -0.5);
        assert_eq!(Grid::vertex_pos(1, 4), 0.0);
        assert_eq!(Grid::vertex_pos(4, 4), 3.0);
        assert_eq!(Grid::vertex_pos(5, 4), 3.5);
        assert_eq!(Grid::vertex_pixel(0, 4), 0);
        assert_eq!(Grid::vertex_pixel(5, 4), 3);
        // A 1-pixel axis still forms two half cells around its pixel.
        assert_eq!(
            [Grid::vertex_pos(0, 1), Grid::vertex_pos(1, 1), Grid::vertex_pos(2, 1)],
            [-0.5, 0.0, 0.5]
        );
    }

    #[test]
    fn axis_lookup_locates_cells_and_neighbours() {
        // 4 source pixels, same centre, scale 1: target x sits on vertex x + 1, i.e. on the left
        // border of cell x + 1 and the right border of cell x.
        let t = axis_lookup(4, 1.5, 1.5, 1.0, 4);
        assert_eq!(t[0], [1.0, 0.0, 1.0, 0.0]);
        assert_eq!(t[3], [4.0, 0.0, 1.0, 0.0]);
        // Half scale: x = 0 maps to u = -1.5 (outside), x = 1 to u = 0.5 (inside cell 1).
        let t = axis_lookup(4, 1.5, 1.5, 2.0, 4);
        assert_eq!(t[0][0], -1.0);
        assert_eq!(t[1], [1.0, 0.5, 0.0, 0.0]);
        // Just below a border: handed to the next cell, on its left border.
        let t = axis_lookup(4, 1.0 - 1e-7, 0.0, 1.0, 1);
        assert_eq!((t[0][0], t[0][2]), (2.0, 1.0));
        // The border ring: u = -0.25 is in the half-width cell 0 at a = 0.5.
        let t = axis_lookup(4, 1.5, 1.75, 1.0, 1);
        assert_eq!(t[0], [0.0, 0.5, 0.0, 0.0]);
    }

    #[test]
    fn break_rule_uses_either_threshold() {
        let r = BreakRule {
            tau_rel: 0.05,
            tau_abs: 0.2,
        };
        assert!(r.continuous(1.0, 1.04));
        assert!(!r.continuous(1.0, 1.06)); // relative
        assert!(r.continuous(10.0, 10.19));
        assert!(!r.continuous(10.0, 10.21)); // absolute (relative alone would keep 2.1 %)
        let inf = BreakRule {
            tau_rel: 0.05,
            tau_abs: f64::INFINITY,
        };
        assert!(inf.continuous(10.0, 10.4));
    }

    #[test]
    fn invalid_corner_drops_exactly_the_triangles_touching_it() {
        // 3x3 plane with a hole in the centre pixel.
        let mut depth = vec![2.0f32; 9];
        depth[4] = f32::NAN;
        let g = Grid { width: 3, height: 3 };
        let keep = g.keep_mask(&depth, &BreakRule::default());
        // Vertex (2, 2) carries pixel (1, 1); it is a corner of cells (1..=2, 1..=2).
        for j in 0..4 {
            for i in 0..4 {
                let bits = keep[j * 4 + i];
                let touches = (1..=2).contains(&i) && (1..=2).contains(&j);
                if !touches {
                    assert_eq!(bits, TRI1 | TRI2, "cell {i},{j}");
                }
            }
        }
        // The hole is v11 of cell (1,1), v01 of (2,1), v10 of (1,2) and v00 of (2,2); only the
        // triangle of each cell that avoids that corner survives.
        assert_eq!(keep[4 + 1], 0);
        assert_eq!(keep[4 + 2], TRI1);
        assert_eq!(keep[2 * 4 + 1], TRI2);
        assert_eq!(keep[2 * 4 + 2], 0);
        assert_eq!(g.kept_triangles(&keep).len(), 2 * 16 - 6);
        // The hole's vertex (2, 2) still belongs to tri1 of cell (2, 1) (its v01? no: tri1 is
        // v00 v10 v11) -- it belongs to no kept triangle: every triangle touching it is gone.
        let flags = g.coverage_flags(&keep);
        assert_eq!(flags[2 * 4 + 2] & VERTEX, 0);
        // Vertex (1, 1) is shared by intact cells: covered. The left edge of cell (2, 1)
        // (column 2, rows 1..2) is v10-v11 of cell (1, 1) (gone) and v00-v01 of cell (2, 1)
        // (tri2, gone): not covered.
        assert_ne!(flags[4 + 1] & VERTEX, 0);
        assert_eq!(flags[4 + 2] & LEFT_EDGE, 0);
        // The top edge of cell (2, 1) is v00-v10 of its kept tri1: covered.
        assert_ne!(flags[4 + 2] & TOP_EDGE, 0);

        // Interior triangles: all corners surrounded. Only vertices (2..=3, 2..=3) minus those
        // touching the hole's broken triangles are surrounded here; every interior triangle's
        // corners are, and interior + boundary = kept.
        let (interior, boundary) = g.split_kept_triangles(&keep);
        assert_eq!(interior.len() + boundary.len(), g.kept_triangles(&keep).len());
        let surrounded = g.surrounded_vertices(&keep);
        assert!(!surrounded[0] && !surrounded[2 * 5 + 2]);
        for code in &interior {
            assert!(g.triangle_vertices(*code).iter().all(|v| surrounded[*v as usize]));
        }
        assert_eq!(g.triangle_vertices(((4 + 2) << 1) | 1), [5 + 2, 2 * 5 + 3, 2 * 5 + 2]);
    }
}
