//! The view from a frame: the render by the plan's method, the holes taken from the dense
//! frame's view, the temporal history and the fill, and the mask rule.

use super::plan::CyclopeanPlan;
use super::reuse::Reused;
use crate::cyclopean::fill::{Filler, FILLED};
use crate::cyclopean::forward::ForwardWarp;
use crate::cyclopean::splat::{SplatParams, SplatRenderer};
use crate::cyclopean::temporal::FROM_HISTORY;
use crate::cyclopean::CyclopeanMethod;
use crate::io;
use crate::mesh::BreakRule;
use crate::pass::Device;
use crate::stereo::gather::gpu::CyclopeanRenderer;
use crate::stereo::gather::CyclopeanOutputs;
use crate::stereo::{MiddleCamera, StereoFrame};
use crate::view::ViewOutput;

/// `out` with its holes taken from `dense` where that view has a pixel, marked [`FILLED`].
fn holes_from(
    mut out: crate::stereo::gather::CyclopeanOutput,
    dense: &crate::stereo::gather::CyclopeanOutput,
) -> crate::Result<crate::stereo::gather::CyclopeanOutput> {
    let missing = || crate::Error::param("fill", "the dense view needs colour and depth");
    let (dc, dd) = (
        dense.color.as_ref().ok_or_else(missing)?,
        dense.depth.as_ref().ok_or_else(missing)?,
    );
    let (oc, od) = (
        out.color.as_mut().ok_or_else(missing)?,
        out.depth.as_mut().ok_or_else(missing)?,
    );
    for (i, s) in out.sources.iter_mut().enumerate() {
        if *s == 0 && dense.sources[i] != 0 {
            *s = FILLED;
            oc.data[3 * i..3 * i + 3].copy_from_slice(&dc.data[3 * i..3 * i + 3]);
            od.data[i] = dd.data[i];
        }
    }
    Ok(out)
}

/// The view synthesised: its planes and mask (1 rendered, [`io::MASK_FILLED`] filled, 0 hole).
pub struct Synthesised {
    /// Colour, depth (those asked for) and the mask.
    pub view: ViewOutput,
    /// Fraction of pixels some eye saw in this frame (filled pixels not counted).
    pub coverage: f64,
    /// Milliseconds before the render itself: uploads, meshes, programs.
    pub setup_ms: f64,
}

impl CyclopeanPlan {
    /// Renders the view with the plan's method (and fill) on `device`.
    /// A sequence passes what it keeps between frames (`reuse`): the default method's renderer
    /// and the fill are reused, and with `fill` the holes the last frame's eyes saw take the
    /// temporal history first and the fill fills the rest (both count as filled in the mask).
    /// `dense`: disparities (given or estimated) with `fill`, the frame on dense disparities; its
    /// view fills the holes of `frame`'s first (pixels from densified disparities count as filled,
    /// so the mask's rendered pixels stay those of given or matched disparities), then the fill
    /// fills the rest.
    pub fn synthesise(
        &self,
        device: &Device,
        frame: &StereoFrame,
        mid: &MiddleCamera,
        fixation: f64,
        dense: Option<&StereoFrame>,
        mut reuse: Option<&mut Reused>,
    ) -> crate::Result<Synthesised> {
        let t0 = std::time::Instant::now();
        frame.validate()?;
        let params = self.gather.map(|g| g.params(fixation)).transpose()?;
        // The fill (and the history) read both planes whatever is returned.
        let wanted = CyclopeanOutputs {
            color: self.outputs.rgb || self.fill,
            depth: self.outputs.depth || self.fill,
        };
        let render = |frame: &StereoFrame, reuse: &mut Option<&mut Reused>| match (self.method, params) {
            (CyclopeanMethod::Seed | CyclopeanMethod::Refine, Some(p)) => {
                CyclopeanRenderer::with_outputs(device, frame, p, wanted)?.render(mid)
            }
            (CyclopeanMethod::Forward, _) => ForwardWarp::new(device, frame, &BreakRule::default())?.render(mid),
            _ => match reuse {
                Some(r) => r.splat(device, frame, wanted)?.render(mid),
                None => SplatRenderer::new(device, frame, SplatParams::default(), wanted)?.render(mid),
            },
        };
        let (mut out, mut timing) = render(frame, &mut reuse)?;
        if let Some(dense) = dense.filter(|_| self.fill) {
            dense.validate()?;
            let (from_dense, t) = render(dense, &mut reuse)?;
            timing.wall_ms += t.wall_ms;
            timing.gpu_ms = timing.gpu_ms.zip(t.gpu_ms).map(|(a, b)| a + b);
            out = holes_from(out, &from_dense)?;
        }
        if self.fill {
            out = match reuse {
                Some(r) => {
                    out = r.history(device, frame.conv)?.push(&out, mid)?;
                    r.filler(device)?.fill(&out, mid.width, mid.height)?
                }
                None => Filler::new(device)?.fill(&out, mid.width, mid.height)?,
            };
        }
        let setup_ms = (t0.elapsed().as_secs_f64() * 1e3 - timing.wall_ms).max(0.0);
        // The mask: 1 where an eye gave the pixel, MASK_FILLED where filled (from the history
        // or from the background side).
        let mask = io::Mask::new(
            mid.width,
            mid.height,
            out.sources
                .iter()
                .map(|&s| match s {
                    0 => 0,
                    FILLED | FROM_HISTORY => io::MASK_FILLED,
                    _ => 1,
                })
                .collect(),
        )?;
        // Seen by an eye in this frame: neither unseen, filled nor carried from history.
        let coverage = crate::metrics::valid_fraction(&out.sources, |s| ![0, FILLED, FROM_HISTORY].contains(s));
        // Some methods render planes that were not asked for: keep only those that were.
        let view = ViewOutput {
            width: mid.width,
            height: mid.height,
            color: out.color.filter(|_| self.outputs.rgb),
            depth: out.depth.filter(|_| self.outputs.depth),
            mask: Some(mask),
            timing: Some(timing),
            exact: None,
        };
        Ok(Synthesised {
            view,
            coverage,
            setup_ms,
        })
    }
}
