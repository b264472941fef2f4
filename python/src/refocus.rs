//! `Renderer.refocus`: the method (its own `#[pymethods]` block; a stack of frames is split by
//! `stack` into one call per frame), and its work on one frame: the inputs checked and copied out
//! of numpy while the GIL is held, the targets planned by the library's request, every target
//! rendered with the GIL released, the outputs handed back as numpy arrays.

use crate::arrays;
use crate::backend::Backend;
use crate::errors;
use crate::renderer::Renderer;
use crate::shared::{choice, outputs_given, SameThread};
use crate::stack;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use viewsynth::camera::PinholeCamera;
use viewsynth::convention::Conventions;
use viewsynth::job::refocus::RefocusRequest;
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusOutput, RefocusSource, Refocuser};

/// The arguments of one refocus call (one frame), as Python gave them.
struct RefocusArgs<'a, 'py> {
    pub rgb: &'a Bound<'py, PyAny>,
    pub depth: &'a Bound<'py, PyAny>,
    pub k: &'a Bound<'py, PyAny>,
    pub scales: Option<Vec<f64>>,
    pub k_out: Option<&'a Bound<'py, PyAny>>,
    pub size: Option<(u32, u32)>,
    pub principal: Option<(f64, f64)>,
    pub outputs: Option<&'a Bound<'py, PyAny>>,
    pub tau_rel: f64,
    pub tau_abs: f64,
    pub method: &'a str,
    pub rgb_everywhere: bool,
}

#[pymethods]
impl Renderer {
    #[doc = include_str!("doc/refocus.txt")]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (rgb, depth, K, *, scales = None, K_out = None, size = None, principal = None,
                        outputs = None, tau_rel = 0.05, tau_abs = 0.2, method = "fullscreen", rgb_everywhere = false))]
    fn refocus<'py>(
        &self,
        py: Python<'py>,
        rgb: &Bound<'py, PyAny>,
        depth: &Bound<'py, PyAny>,
        K: &Bound<'py, PyAny>,
        scales: Option<&Bound<'py, PyAny>>,
        K_out: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = crate::ints::size)] size: Option<(u32, u32)>,
        principal: Option<(f64, f64)>,
        outputs: Option<&Bound<'py, PyAny>>,
        tau_rel: f64,
        tau_abs: f64,
        method: &str,
        rgb_everywhere: bool,
    ) -> PyResult<Bound<'py, PyList>> {
        let args = |rgb, depth, k, scales| RefocusArgs {
            rgb,
            depth,
            k,
            scales,
            k_out: K_out,
            size,
            principal,
            outputs,
            tau_rel,
            tau_abs,
            method,
            rgb_everywhere,
        };
        let stacked = stack::frames(rgb, depth, K)?;
        // Per frame: the one list, or (a stack) each sample's own.
        let mut scales = match stack::scales(scales)? {
            Some(s) => s
                .per_frame(stacked.as_ref().map(Vec::len))?
                .into_iter()
                .map(Some)
                .collect(),
            None => vec![None; stacked.as_ref().map_or(1, Vec::len)],
        };
        let (gpu, _busy) = self.enter()?;
        let Some(frames) = stacked else {
            return refocus(py, gpu, args(rgb, depth, K, scales.pop().flatten()));
        };
        // One call over a stack: each frame as a call of its own, the Renderer busy throughout.
        let views = PyList::empty(py);
        for ((rgb, depth, k), scales) in frames.iter().zip(scales) {
            views.append(refocus(py, gpu.clone(), args(rgb, depth, k, scales))?)?;
        }
        Ok(views)
    }
}

/// A refocus call's inputs, validated while the GIL is held.
struct RefocusJob {
    source: RefocusSource,
    rule: BreakRule,
    method: Method,
    outputs: OutputSet,
    targets: Vec<PinholeCamera>,
    rgb_everywhere: bool,
}

/// The GPU work of one call: upload the source once, render every target.
fn render_all(gpu: &Backend, job: &RefocusJob) -> viewsynth::Result<(f64, Vec<RefocusOutput>)> {
    let t0 = std::time::Instant::now();
    let mut refocuser = Refocuser::new(
        gpu,
        &job.source,
        &job.rule,
        job.method,
        job.outputs,
        Conventions::default(),
    )?;
    refocuser.set_rgb_everywhere(job.rgb_everywhere);
    let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
    let rendered = job
        .targets
        .iter()
        .map(|t| refocuser.render(t))
        .collect::<viewsynth::Result<Vec<_>>>()?;
    Ok((setup_ms, rendered))
}

/// Refocus one frame on `gpu`: one dict per target (see `Renderer.refocus`).
#[allow(non_snake_case)]
fn refocus<'py>(py: Python<'py>, gpu: Backend, a: RefocusArgs<'_, 'py>) -> PyResult<Bound<'py, PyList>> {
    let RefocusArgs {
        rgb,
        depth,
        k: K,
        scales,
        k_out: K_out,
        size,
        principal,
        outputs,
        tau_rel,
        tau_abs,
        method,
        rgb_everywhere,
    } = a;
    let k = arrays::intrinsics(K, "K")?;
    let source = RefocusSource::new(arrays::rgb_image(rgb, "rgb")?, arrays::float_map(depth, "depth")?, k)
        .map_err(errors::from_library)?;
    if scales.is_some() && K_out.is_some() {
        return Err(errors::invalid("scales", "give scales or K_out, not both"));
    }
    let request = RefocusRequest {
        scales,
        size,
        principal,
        outputs: outputs_given(outputs)?,
        tau_rel,
        tau_abs,
        method: choice(viewsynth::Field::Method, method)?,
        rgb_everywhere,
        ..Default::default()
    };
    let plan = request.frame().map_err(errors::from_request)?;
    let camera = source.camera();
    let targets = match K_out {
        None => plan.targets(&camera).map_err(errors::from_library)?.1,
        Some(k_out) => {
            if principal.is_some() {
                return Err(errors::invalid("principal", "K_out already gives each target's cx, cy"));
            }
            let (width, height) = size.unwrap_or((camera.width, camera.height));
            let mut targets = Vec::new();
            for (i, item) in k_out
                .try_iter()
                .map_err(|_| errors::invalid("K_out", "expected a sequence of 3x3 matrices"))?
                .enumerate()
            {
                let k = arrays::intrinsics(&item?, &format!("K_out[{i}]"))?;
                let cam = PinholeCamera { k, width, height };
                cam.validate(&format!("K_out[{i}] target"))
                    .map_err(errors::from_library)?;
                targets.push(cam);
            }
            if targets.is_empty() {
                return Err(errors::invalid("K_out", "no target matrix given"));
            }
            targets
        }
    };
    let (rule, method, outputs) = (plan.rule, plan.method, plan.files.outputs);
    let job = RefocusJob {
        source,
        rule,
        method,
        outputs,
        targets,
        rgb_everywhere,
    };
    // The inputs were copied out of numpy above, so other Python threads may run (and even
    // modify those arrays) while the GPU works.
    let work = SameThread((gpu, job));
    let result = py.detach(move || {
        // A whole-value move, so the closure captures `work` and not its (non-Send) fields.
        let work = work;
        let (gpu, job) = work.0;
        SameThread(render_all(&gpu, &job))
    });
    let (setup_ms, rendered) = result.0.map_err(errors::from_library)?;

    let list = PyList::empty(py);
    for out in rendered {
        let d = PyDict::new(py);
        d.set_item("scale", out.camera.k.fx / k.fx)?;
        d.set_item("K", arrays::k_matrix(py, &out.camera.k))?;
        d.set_item("coverage", out.coverage())?;
        let timings = PyDict::new(py);
        timings.set_item("setup_ms", setup_ms)?;
        timings.set_item("render_ms", out.render.wall_ms)?;
        timings.set_item("gpu_ms", out.render.gpu_ms)?;
        timings.set_item("readback_ms", out.readback_ms)?;
        d.set_item("timings", timings)?;
        if let Some(img) = out.rgb {
            d.set_item("rgb", arrays::rgb_array(py, img))?;
        }
        if let Some(z) = out.depth {
            d.set_item("depth", arrays::depth_array(py, z))?;
        }
        if let Some(m) = out.mask {
            d.set_item("mask", arrays::mask_array(py, m))?;
        }
        list.append(d)?;
    }
    Ok(list)
}
