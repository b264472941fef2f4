//! Where a twin's f64 decision could go the other way in the GPU's f32 (issue 38). The gather and
//! splat-gather twins ([`super::reference::ambiguity`], [`super::splat_reference::ambiguity`])
//! compare every decision they take (a texel or pixel chosen by `floor`, an image-range check, a
//! distance against a threshold) with the f32 error bound of the quantity it tests. A pixel with
//! any decision within that bound is ambiguous: the GPU may answer it otherwise, and the
//! GPU-vs-twin tests excuse those pixels, and only those; every other pixel must carry the twin's
//! answer.
//!
//! The bounds, with u = 2^-24 (f32 unit roundoff); an n-term f32 dot product lies within n u of
//! the sum of its terms' magnitudes, and each f32-stored matrix entry or parameter adds u:
//! - **A window position** (px) carried through the matrix chain: view ray (a 4x4 product and a
//!   divide, 6 u), scaled by a distance (1), inverse view (5), view-projection (5), perspective
//!   divide (1), to the window (2): ~20 u of the NDC range. The terms' magnitudes exceed the
//!   result's by up to ~3 (camera offsets against distances), so [`POSITION_OPS`] = 64 u of the
//!   image size: 64 x 2^-24 x 160 px ~ 6e-4 px on the built-in scene, 1.7e-3 px on Cones (450 px).
//! - **A distance** (relative) reconstructed from a stored depth: the same chain,
//!   [`DISTANCE_OPS`] = 32 u, times the unprojection's condition ([`row_condition`]: 1 for a view
//!   distance; for device depth the inverse projection's w row, sum of |terms| over |w|, ~ z / near:
//!   ~120 at 6 m with near 0.05 m, 2.3e-4 relative).
//! - **A position read at a distance z** also carries z's relative error times the parallax
//!   |d px / d ln z|, which for a pinhole is the point's shift between z and infinity.
//!
//! These are worst cases (every rounding the same way); errors measured on llvmpipe are 10-30x
//! smaller. A loose bound only excuses more pixels, and the tests bound the excused share.

use crate::camera::mat4::Mat4;
use std::cell::Cell;

/// f32 unit roundoff.
pub const EPS32: f64 = 1.0 / (1u64 << 24) as f64;
/// Roundings in a window position, in units of the image size (see the module comment).
pub const POSITION_OPS: f64 = 64.0;
/// Roundings in a reconstructed distance, relative, before the unprojection's condition.
pub const DISTANCE_OPS: f64 = 32.0;

/// Bound (px) on the f32 error of a window position in an image of `size` px (its larger side),
/// read at a distance of relative error `rel_z` where the parallax is `shift` px.
pub fn position_bound(size: f64, rel_z: f64, shift: f64) -> f64 {
    EPS32 * POSITION_OPS * size + rel_z * shift
}

/// Bound on the relative f32 error of a distance reconstructed with condition `cond`.
pub fn distance_bound(cond: f64) -> f64 {
    EPS32 * DISTANCE_OPS * cond.max(1.0)
}

/// Sum of |terms| over |result| of row `row` of `m` applied to `p`: how much the row's roundings
/// grow relative to its result (1 without cancellation; infinite at a zero result).
pub fn row_condition(m: &Mat4, row: usize, p: [f64; 4]) -> f64 {
    let terms = (0..4).map(|j| m[row][j] * p[j]);
    let abs: f64 = terms.clone().map(f64::abs).sum();
    abs / terms.sum::<f64>().abs()
}

/// The decisions of one pixel: set when any came within reach of its boundary. Off (when only
/// the twin's answer is wanted) it records nothing.
pub(crate) struct Reach {
    on: bool,
    hit: Cell<bool>,
}

impl Reach {
    pub fn new(on: bool) -> Self {
        Reach {
            on,
            hit: Cell::new(false),
        }
    }
    pub fn on(&self) -> bool {
        self.on
    }
    /// Whether the pixel's decisions so far came within reach; clears for the next pixel.
    pub fn take(&self) -> bool {
        self.hit.replace(false)
    }
    /// A `floor(v)` (and range checks at integers): within `bound` of an integer.
    pub fn floor(&self, v: f64, bound: f64) {
        if self.on && (v - v.round()).abs() <= bound {
            self.hit.set(true);
        }
    }
    /// Mark the pixel outright (a choice within reach whose alternative answers otherwise).
    pub fn mark(&self) {
        if self.on {
            self.hit.set(true);
        }
    }
    /// A comparison whose quantity lies `margin` from its threshold, with error up to `bound`.
    pub fn threshold(&self, margin: f64, bound: f64) {
        // NaN margins count as within reach.
        if self.on && margin.abs().partial_cmp(&bound) != Some(std::cmp::Ordering::Greater) {
            self.hit.set(true);
        }
    }
}
