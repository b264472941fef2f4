//! Float64 CPU twin of the reprojection passes: the shift gathers of shaders/reproject/shift.frag
//! step for step, and the 3-D gather through `cyclopean::reference`. Rows top-down (the shift
//! works per row, so memory order does not change it).

use super::merge_nearer;
use super::{
    check, gather3d_params, one_eye_frame, Geometry, Method, ReprojectOutput, ReprojectParams, ReprojectSource,
    ShiftModel,
};
use crate::error::Result;
use crate::io::{DepthMap, RgbImage};
use crate::stereo::gather::reference::cyclopean_reference;

/// Margin (texels) added to each end of the scan window, so f32 rounding of the window bounds
/// on the GPU never drops a segment the f64 window holds.
pub const SCAN_MARGIN: i64 = 1;

/// Unquantised result, rows top-down.
#[derive(Debug, Clone)]
pub struct ReprojectReference {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Colour per pixel, 0..=255 per channel, unrounded; 0 where invalid.
    pub color: Vec<[f64; 3]>,
    /// Target view Z, 0 where invalid.
    pub depth: Vec<f64>,
    /// Per pixel, whether the target sees a source surface.
    pub mask: Vec<bool>,
}

impl ReprojectReference {
    /// Rounded to the output types (colour and depth both present).
    pub fn to_output(&self) -> Result<ReprojectOutput> {
        Ok(ReprojectOutput {
            color: Some(RgbImage::new(
                self.width,
                self.height,
                self.color
                    .iter()
                    .flat_map(|c| c.map(crate::metrics::quantize_u8))
                    .collect(),
            )?),
            depth: Some(DepthMap::new(
                self.width,
                self.height,
                self.depth.iter().map(|z| *z as f32).collect(),
            )?),
            mask: self.mask.iter().map(|m| if *m { 255 } else { 0 }).collect(),
        })
    }
}

/// One source row prepared for the shift: inverse depth per texel and colour.
struct Row<'a> {
    q: &'a [Option<f64>],
    color: &'a [u8],
}

/// A covering candidate: interpolated inverse depth and colour; `hole` for a depth-edge segment
/// (an unseen surface between the two sides: whatever lies behind it is hidden).
#[derive(Clone, Copy)]
struct Hit {
    q: f64,
    color: [f64; 3],
    hole: bool,
}

struct ShiftCtx {
    model: ShiftModel,
    tau_rel: f64,
    width: i64,
    q_min: f64,
    q_max: f64,
}

impl ShiftCtx {
    /// Segment [j, j+1] covering target column u (the rule in mod.rs), or None.
    fn segment(&self, row: &Row, j: i64, u: f64) -> Option<Hit> {
        if j < 0 || j + 1 >= self.width {
            return None;
        }
        let (q0, q1) = (row.q[j as usize]?, row.q[j as usize + 1]?);
        let f0 = self.model.forward(j as f64, q0);
        let f1 = self.model.forward(j as f64 + 1.0, q1);
        let hole = (q0 - q1).abs() > self.tau_rel * q0.min(q1) || f1 <= f0;
        // A hole also covers the gap between the samples mapped at either end's depth (where
        // the edge really is between them is unknown): one pixel beyond each end.
        let pad = if hole { 1.0 } else { 0.0 };
        let (lo, hi) = (f0.min(f1 - pad), (f0 + pad).max(f1));
        if !(lo <= u && u <= hi) {
            return None;
        }
        let t = if f1 != f0 {
            ((u - f0) / (f1 - f0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let c = |k: usize| {
            let (a, b) = (
                row.color[j as usize * 3 + k] as f64,
                row.color[j as usize * 3 + 3 + k] as f64,
            );
            a + (b - a) * t
        };
        Some(Hit {
            q: q0 + (q1 - q0) * t,
            color: [c(0), c(1), c(2)],
            hole,
        })
    }

    /// The nearer of two candidates; ties keep the first unless only it is a hole.
    fn nearer(best: Option<Hit>, h: Option<Hit>) -> Option<Hit> {
        match (best, h) {
            (Some(b), Some(h)) if h.q > b.q || (h.q == b.q && b.hole && !h.hole) => Some(h),
            (None, h) => h,
            (b, _) => b,
        }
    }

    fn scan(&self, row: &Row, u: f64) -> Option<Hit> {
        let m = &self.model;
        let s_a = u - m.a_px + m.b_px * self.q_min;
        let s_b = u - m.a_px + m.b_px * self.q_max;
        let (lo, hi) = (
            s_a.min(s_b).floor() as i64 - 1 - SCAN_MARGIN,
            s_a.max(s_b).floor() as i64 + SCAN_MARGIN,
        );
        let (lo, hi) = (lo.max(0), hi.min(self.width - 2));
        let mut best = None;
        for j in lo..=hi {
            best = Self::nearer(best, self.segment(row, j, u));
        }
        best
    }

    /// k fixed-point steps s <- u - a + b q(round(s)) from `s`, then the segments around the end.
    fn walk(&self, row: &Row, u: f64, mut s: f64, steps: u32) -> Option<Hit> {
        let m = &self.model;
        for _ in 0..steps {
            let j = ((s + 0.5).floor() as i64).clamp(0, self.width - 1);
            let Some(q) = row.q[j as usize] else { break };
            s = u - m.a_px + m.b_px * q;
        }
        let j0 = (s.floor() as i64).clamp(-1, self.width);
        let mut best = None;
        for j in j0 - 1..=j0 + 1 {
            best = Self::nearer(best, self.segment(row, j, u));
        }
        best
    }
}

fn shift_reference(src: &ReprojectSource, model: ShiftModel, params: &ReprojectParams) -> ReprojectReference {
    let (w, h) = (src.color.width as usize, src.color.height as usize);
    let q = src.inverse_depths();
    let mut out = ReprojectReference {
        width: w as u32,
        height: h as u32,
        color: vec![[0.0; 3]; w * h],
        depth: vec![0.0; w * h],
        mask: vec![false; w * h],
    };
    let Some((q_min, q_max)) = src.inverse_depth_range() else {
        return out;
    };
    let ctx = ShiftCtx {
        model,
        tau_rel: params.tau_rel,
        width: w as i64,
        q_min,
        q_max,
    };
    for y in 0..h {
        let row = Row {
            q: &q[y * w..(y + 1) * w],
            color: &src.color.data[y * w * 3..(y + 1) * w * 3],
        };
        for x in 0..w {
            let u = x as f64;
            let hit = match params.method {
                Method::ShiftScan => ctx.scan(&row, u),
                Method::Shift { steps } => {
                    let zero_parallax = ctx.walk(&row, u, u, steps);
                    let near = ctx.walk(&row, u, u - model.a_px + model.b_px * q_max, steps);
                    ShiftCtx::nearer(zero_parallax, near)
                }
                Method::Gather3d { .. } => None,
            };
            if let Some(hit) = hit.filter(|h| !h.hole) {
                let o = y * w + x;
                out.color[o] = hit.color;
                out.depth[o] = 1.0 / hit.q;
                out.mask[o] = true;
            }
        }
    }
    out
}

/// The f64 reference of any method.
pub fn reproject_reference(
    src: &ReprojectSource,
    geometry: &Geometry,
    params: &ReprojectParams,
) -> Result<ReprojectReference> {
    match (check(src, geometry, params)?, params.method) {
        (Some(model), _) => Ok(shift_reference(src, model, params)),
        (None, Method::Gather3d { steps }) => {
            let (frame, target) = one_eye_frame(src, geometry)?;
            let [p0, p1] = gather3d_params(src, geometry, steps);
            let (a, b) = (
                cyclopean_reference(&frame, &target, &p0)?,
                cyclopean_reference(&frame, &target, &p1)?,
            );
            let n = a.sources.len();
            let mut out = ReprojectReference {
                width: target.width,
                height: target.height,
                color: vec![[0.0; 3]; n],
                depth: vec![0.0; n],
                mask: vec![false; n],
            };
            for i in 0..n {
                let first = (a.sources[i] != 0, a.depth[i]);
                let r = if merge_nearer(first, (b.sources[i] != 0, b.depth[i])) {
                    &b
                } else {
                    &a
                };
                if r.sources[i] != 0 {
                    out.color[i] = r.color[i];
                    out.depth[i] = r.depth[i];
                    out.mask[i] = true;
                }
            }
            Ok(out)
        }
        (None, _) => Err(crate::Error::param("method", "shift method without a shift model")),
    }
}
