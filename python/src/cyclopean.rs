//! `Renderer.cyclopean` for a rectified pair with disparities: the library calls of the CLI's
//! disparity mode (`viewsynth cyclopean --left-disparity ...`), numpy in and out.

use crate::arrays;
use crate::errors;
use crate::renderer::SameThread;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use viewsynth::convention::Conventions;
use viewsynth::cyclopean::disparity_frame::{disparity_frame, DisparityRig};
use viewsynth::cyclopean::forward::ForwardWarp;
use viewsynth::cyclopean::render::CyclopeanRenderer;
use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
use viewsynth::cyclopean::{
    CyclopeanOutput, CyclopeanOutputs, CyclopeanParams, Method as GatherMethod, MiddleCamera, StereoFrame,
};
use viewsynth::gpu::{Gpu, Timing};
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::refocus::{BreakRule, OutputSet};

/// The methods of `viewsynth cyclopean --method`.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Method {
    SplatGather,
    Seed,
    Refine,
    Forward,
}

impl Method {
    fn parse(name: &str) -> PyResult<Self> {
        Ok(match name {
            "splat-gather" => Method::SplatGather,
            "seed" => Method::Seed,
            "refine" => Method::Refine,
            "forward" => Method::Forward,
            _ => {
                return Err(errors::invalid(
                    "method",
                    format!("'{name}': expected \"splat-gather\", \"seed\", \"refine\" or \"forward\""),
                ))
            }
        })
    }
}

/// The arguments of one call, as Python gave them.
pub struct CyclopeanArgs<'a, 'py> {
    pub left_rgb: &'a Bound<'py, PyAny>,
    pub right_rgb: &'a Bound<'py, PyAny>,
    pub left_disparity: &'a Bound<'py, PyAny>,
    pub right_disparity: &'a Bound<'py, PyAny>,
    pub position: f64,
    pub method: &'a str,
    pub focal: Option<f64>,
    pub baseline: Option<f64>,
    pub doffs: f64,
    pub outputs: Option<&'a Bound<'py, PyAny>>,
}

/// A call's inputs, validated while the GIL is held.
struct Job {
    frame: StereoFrame,
    mid: MiddleCamera,
    method: Method,
    /// Seed/refine start from it: the median depth the left eye saw (as the CLI).
    fixation: f64,
    wanted: CyclopeanOutputs,
}

/// The same renderer the CLI picks for `method`, with its defaults.
fn render(gpu: &Gpu, job: &Job) -> viewsynth::Result<(f64, CyclopeanOutput, Timing)> {
    let t0 = std::time::Instant::now();
    let (frame, mid, wanted) = (&job.frame, &job.mid, job.wanted);
    let (out, timing) = match job.method {
        Method::Seed | Method::Refine => {
            let mut params = CyclopeanParams::seed(job.fixation);
            if job.method == Method::Refine {
                // The CLI's default --refine-steps.
                params.method = GatherMethod::Refine { steps: 3 };
            }
            params.validate()?;
            let mut r = CyclopeanRenderer::with_outputs(gpu, frame, params, wanted)?;
            r.render(mid)?
        }
        Method::Forward => ForwardWarp::new(gpu, frame, &BreakRule::default())?.render(mid)?,
        Method::SplatGather => SplatRenderer::new(gpu, frame, SplatParams::default(), wanted)?.render(mid)?,
    };
    // Everything before the render itself: uploads, meshes, programs.
    let setup_ms = (t0.elapsed().as_secs_f64() * 1e3 - timing.wall_ms).max(0.0);
    Ok((setup_ms, out, timing))
}

fn eye(
    rgb: &Bound<'_, PyAny>,
    rgb_name: &str,
    disparity: &Bound<'_, PyAny>,
    disparity_name: &str,
) -> PyResult<(RgbImage, DepthMap)> {
    Ok((
        arrays::rgb_image(rgb, rgb_name)?,
        arrays::float_map(disparity, disparity_name)?,
    ))
}

/// Validates `a`, renders the view with the GIL released, and returns the result dict.
pub fn cyclopean<'py>(py: Python<'py>, gpu: Gpu, a: CyclopeanArgs<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let method = Method::parse(a.method)?;
    let metric = match (a.focal, a.baseline) {
        (Some(_), Some(_)) => true,
        (None, None) => false,
        (Some(_), None) => return Err(errors::invalid("baseline", "focal needs baseline (metres) too")),
        (None, Some(_)) => return Err(errors::invalid("focal", "baseline needs focal (pixels) too")),
    };
    let outputs = match a.outputs {
        Some(_) => crate::renderer::output_set(a.outputs)?,
        None => OutputSet {
            rgb: true,
            depth: metric,
            mask: true,
        },
    };
    if outputs.depth && !metric {
        return Err(errors::invalid(
            "outputs",
            "\"depth\" needs focal and baseline (the depth is metric)",
        ));
    }
    let left = eye(a.left_rgb, "left_rgb", a.left_disparity, "left_disparity")?;
    let right = eye(a.right_rgb, "right_rgb", a.right_disparity, "right_disparity")?;
    let (w, h) = (left.0.width, left.0.height);
    // Named here: the library's size message does not say which argument to fix.
    for (name, (width, height)) in [
        ("left_disparity", (left.1.width, left.1.height)),
        ("right_rgb", (right.0.width, right.0.height)),
        ("right_disparity", (right.1.width, right.1.height)),
    ] {
        if (width, height) != (w, h) {
            return Err(errors::invalid(
                name,
                format!("{width}x{height} (W x H) differs from left_rgb's {w}x{h}"),
            ));
        }
    }
    gpu.check_image_size("left_rgb", w, h).map_err(errors::from_library)?;
    // Without a calibration only f B matters for the view; any nominal values do (as the CLI).
    let rig = DisparityRig {
        focal_px: a.focal.unwrap_or(w as f64),
        baseline: a.baseline.unwrap_or(0.1),
        doffs: a.doffs,
        position: a.position,
    };
    let (frame, mid) = disparity_frame(left, right, &rig, Conventions::default()).map_err(errors::from_library)?;
    let mut z: Vec<f32> = frame.left.depth.data.iter().copied().filter(|z| *z > 0.0).collect();
    if z.is_empty() {
        return Err(errors::invalid(
            "left_disparity",
            "no known disparity (all 0, negative or non-finite)",
        ));
    }
    let half = z.len() / 2;
    let fixation = *z.select_nth_unstable_by(half, f32::total_cmp).1 as f64;
    frame.validate().map_err(errors::from_library)?;
    let job = Job {
        frame,
        mid,
        method,
        fixation,
        wanted: CyclopeanOutputs {
            color: outputs.rgb,
            depth: outputs.depth,
        },
    };

    // The inputs were copied out of numpy above; see SameThread for why the move is sound.
    let work = SameThread((gpu, job));
    let result = py.detach(move || {
        let work = work;
        let (gpu, job) = work.0;
        SameThread(render(&gpu, &job))
    });
    let (setup_ms, out, timing) = result.0.map_err(errors::from_library)?;

    let d = PyDict::new(py);
    let valid = out.sources.iter().filter(|s| **s != 0).count();
    d.set_item("coverage", valid as f64 / out.sources.len() as f64)?;
    let timings = PyDict::new(py);
    timings.set_item("setup_ms", setup_ms)?;
    timings.set_item("render_ms", timing.wall_ms)?;
    timings.set_item("gpu_ms", timing.gpu_ms)?;
    d.set_item("timings", timings)?;
    // The forward method renders colour and depth whatever was asked: keep only what was.
    if let Some(img) = out.color.filter(|_| outputs.rgb) {
        d.set_item("rgb", arrays::rgb_array(py, img))?;
    }
    if let Some(z) = out.depth.filter(|_| outputs.depth) {
        d.set_item("depth", arrays::depth_array(py, z))?;
    }
    if outputs.mask {
        let mask = viewsynth::io::Mask::new(w, h, out.sources.iter().map(|s| (*s != 0) as u8).collect())
            .map_err(errors::from_library)?;
        d.set_item("mask", arrays::mask_array(py, mask))?;
    }
    Ok(d)
}
