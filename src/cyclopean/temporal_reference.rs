//! The CPU twin of the temporal passes ([`super::temporal`]): the same carry rule in the
//! shaders' f32 comparisons and the same reprojection in f64, so the history it keeps is what
//! the GPU keeps (tests in `viewsynth_tests`' `cyclopean::temporal`).

use super::temporal::{check_rule, color_and_depth, FROM_HISTORY};
use crate::camera::mat4;
use crate::camera::rays;
use crate::convention::{Conventions, RowOrder};
use crate::error::{Error, Result};
use crate::stereo::gather::CyclopeanOutput;
use crate::stereo::MiddleCamera;

/// Whether texel (x, top-down row y) of the last view is carried into the next frame: an eye
/// rendered it (not the history) at a usable distance, and so did each of its 4-neighbours in
/// the image, none of them farther than `tolerance` relative. Why the neighbours: a texel at a
/// depth break or beside a hole is an edge, and an edge texel (moved to the nearest pixel
/// centre, up to half a pixel past its surface; or an edge pixel mixing both surfaces) would
/// fill the background a disocclusion uncovers with the foreground's colour. The comparison
/// is f32, as the shader's, so both choose the same texels.
pub fn carried(
    view: &CyclopeanOutput,
    depth: &crate::io::DepthMap,
    x: usize,
    y: usize,
    w: usize,
    h: usize,
    tolerance: f64,
) -> bool {
    let rendered = |i: usize| {
        let d = depth.data[i];
        ![0, FROM_HISTORY].contains(&view.sources[i]) && d.is_finite() && d > 0.0
    };
    let i = y * w + x;
    if !rendered(i) {
        return false;
    }
    let far = depth.data[i] * (1.0 + tolerance as f32);
    let neighbours = [
        (x > 0).then(|| i - 1),
        (x + 1 < w).then(|| i + 1),
        (y > 0).then(|| i - w),
        (y + 1 < h).then(|| i + w),
    ];
    neighbours
        .into_iter()
        .flatten()
        .all(|n| rendered(n) && depth.data[n] <= far)
}

/// Exponential accumulation of successive middle views, holes filled from the reprojected history.
pub struct TemporalAccumulator {
    /// Weight of the current frame where both are valid (1 = no accumulation).
    alpha: f64,
    /// Relative middle-distance disagreement above which history is rejected.
    depth_tolerance: f64,
    history: Option<(CyclopeanOutput, MiddleCamera)>,
    conv: Conventions,
}

impl TemporalAccumulator {
    /// An empty history; `alpha` in (0, 1] weighs the current frame, `depth_tolerance` (relative) rejects history at another depth.
    pub fn new(alpha: f64, depth_tolerance: f64, conv: Conventions) -> Result<Self> {
        check_rule(alpha, depth_tolerance)?;
        Ok(TemporalAccumulator {
            alpha,
            depth_tolerance,
            history: None,
            conv,
        })
    }

    /// Forgets the history: the next frame is taken as it is (e.g. after a scene cut).
    pub fn reset(&mut self) {
        self.history = None;
    }

    /// Accumulate `current` (seen by `mid`) with the history; returns the accumulated frame,
    /// which becomes the history.
    pub fn push(&mut self, current: &CyclopeanOutput, mid: &MiddleCamera) -> Result<CyclopeanOutput> {
        let (w, h) = (mid.width as usize, mid.height as usize);
        let (cur_color, cur_depth) = color_and_depth(current)?;
        if current.sources.len() != w * h || cur_color.data.len() != w * h * 3 {
            return Err(Error::SizeMismatch {
                message: format!("frame does not match the middle camera's {w}x{h}"),
            });
        }
        let (mut color, mut depth, mut sources) = (cur_color.clone(), cur_depth.clone(), current.sources.clone());
        if let Some((prev, prev_cam)) = &self.history {
            let (hist_color, hist_z) = self.reproject(prev, prev_cam, mid)?;
            for i in 0..w * h {
                let hz = hist_z[i];
                if !(hz.is_finite() && hz > 0.0) {
                    continue;
                }
                let cz = cur_depth.data[i] as f64;
                if current.sources[i] != 0 && cz > 0.0 {
                    if (hz - cz).abs() <= self.depth_tolerance * cz {
                        for (c, h) in hist_color[i].iter().enumerate() {
                            let v = self.alpha * cur_color.data[i * 3 + c] as f64 + (1.0 - self.alpha) * h;
                            color.data[i * 3 + c] = v.round().clamp(0.0, 255.0) as u8;
                        }
                    }
                } else {
                    for (c, h) in hist_color[i].iter().enumerate() {
                        color.data[i * 3 + c] = h.round().clamp(0.0, 255.0) as u8;
                    }
                    depth.data[i] = hz as f32;
                    sources[i] = FROM_HISTORY;
                }
            }
        }
        let out = CyclopeanOutput {
            color: Some(color),
            depth: Some(depth),
            sources,
        }
        .finite();
        self.history = Some((out.clone(), *mid));
        Ok(out)
    }

    /// The previous frame splatted into the current camera: colour and middle distance per
    /// pixel (distance 0 where nothing landed), nearest surface first.
    fn reproject(
        &self,
        prev: &CyclopeanOutput,
        prev_cam: &MiddleCamera,
        mid: &MiddleCamera,
    ) -> Result<(Vec<[f64; 3]>, Vec<f64>)> {
        let (prev_color, prev_depth) = color_and_depth(prev)?;
        let singular = |what: &str| Error::param(what.to_string(), "singular");
        let basis = rays::ray_basis(&prev_cam.proj).ok_or_else(|| singular("previous middle projection"))?;
        let inv_view = mat4::inverse(&prev_cam.view).ok_or_else(|| singular("previous middle view"))?;
        let vp = mat4::mul(&mid.proj, &mid.view);
        let (pw, ph) = (prev_cam.width as usize, prev_cam.height as usize);
        let (w, h) = (mid.width as usize, mid.height as usize);
        let mut color = vec![[0.0; 3]; w * h];
        let mut z = vec![0.0; w * h];
        for y in 0..ph {
            for x in 0..pw {
                let i = y * pw + x;
                let d = prev_depth.data[i] as f64;
                if !carried(prev, prev_depth, x, y, pw, ph, self.depth_tolerance) {
                    continue;
                }
                let ndc = pixel_ndc(x, y, pw, ph, &self.conv);
                let r = rays::view_ray(&basis, ndc);
                let view = [r[0] * d, r[1] * d, r[2] * d];
                let world = mat4::transform_point(&inv_view, view);
                let clip = mat4::transform(&vp, [world[0], world[1], world[2], 1.0]);
                if clip[3].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                    continue;
                }
                let wx = (clip[0] / clip[3] * 0.5 + 0.5) * w as f64;
                let wy = (clip[1] / clip[3] * 0.5 + 0.5) * h as f64;
                if !(wx >= 0.0 && wx < w as f64 && wy >= 0.0 && wy < h as f64) {
                    continue;
                }
                let (tx, ty_mem) = (wx as usize, wy as usize);
                let ty = if self.conv.row_order == RowOrder::BottomUp {
                    h - 1 - ty_mem
                } else {
                    ty_mem
                };
                let o = ty * w + tx;
                let dist = -mat4::transform_point(&mid.view, world)[2];
                if z[o] == 0.0 || dist < z[o] {
                    z[o] = dist;
                    color[o] = [0, 1, 2].map(|c| prev_color.data[i * 3 + c] as f64);
                }
            }
        }
        Ok((color, z))
    }
}

/// NDC of pixel (x, image row y) under the row order.
fn pixel_ndc(x: usize, y: usize, w: usize, h: usize, conv: &Conventions) -> [f64; 2] {
    let y_mem = if conv.row_order == RowOrder::BottomUp {
        h - 1 - y
    } else {
        y
    };
    [
        rays::pixel_ndc(x as f64, w as f64),
        rays::pixel_ndc(y_mem as f64, h as f64),
    ]
}
