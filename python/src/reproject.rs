//! `Renderer.reproject` (the method in its own `#[pymethods]` block) on a parallel stereo rig: the
//! library calls of the CLI's rig mode (`viewsynth reproject --fx ... --baseline ...`), numpy in
//! and out. The keyword arguments fill the library's `ReprojectRequest`; its checks decide the
//! views, the depth kind and the rig.

use crate::arrays;
use crate::backend::Backend;
use crate::errors;
use crate::renderer::Renderer;
use crate::shared::{choice, outputs_given, SameThread};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use viewsynth::camera::stereo::Eye;
use viewsynth::convention::Conventions;
use viewsynth::job::reproject::{RenderedTarget, ReprojectRequest};
use viewsynth::pass::ToDevice;

/// The arguments of one call: the arrays, and the settings as the library's request.
struct ReprojectArgs<'a, 'py> {
    pub rgb: &'a Bound<'py, PyAny>,
    pub depth: &'a Bound<'py, PyAny>,
    pub k: &'a Bound<'py, PyAny>,
    pub request: ReprojectRequest,
}

#[pymethods]
impl Renderer {
    #[doc = include_str!("doc/reproject.txt")]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (rgb, depth, K, *, depth_kind = "view-z", baseline = None, focal = None, doffs = 0.0,
                        separation = None, convergence = None, near = None, far = None, source = "left",
                        target = "right", method = None, steps = 3, tau_rel = 0.05, outputs = None))]
    fn reproject<'py>(
        &self,
        py: Python<'py>,
        rgb: &Bound<'py, PyAny>,
        depth: &Bound<'py, PyAny>,
        K: &Bound<'py, PyAny>,
        depth_kind: &str,
        baseline: Option<f64>,
        focal: Option<f64>,
        doffs: f64,
        separation: Option<f64>,
        convergence: Option<f64>,
        near: Option<f64>,
        far: Option<f64>,
        source: &str,
        target: &str,
        method: Option<&str>,
        #[pyo3(from_py_with = crate::ints::steps)] steps: u32,
        tau_rel: f64,
        outputs: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (gpu, _busy) = self.enter()?;
        // The settings as the library's request: it alone decides and checks them.
        let request = ReprojectRequest {
            depth_kind: choice(viewsynth::Field::DepthKind, depth_kind)?,
            near,
            far,
            baseline,
            focal,
            doffs,
            separation,
            convergence,
            from: choice(viewsynth::Field::From, source)?,
            to: choice(viewsynth::Field::To, target)?,
            // None: the library's default for a rig (shift-scan), as the CLI's.
            method: method.map(|m| choice(viewsynth::Field::Method, m)).transpose()?,
            steps,
            tau_rel,
            outputs: outputs_given(outputs)?,
        };
        reproject(
            py,
            gpu,
            ReprojectArgs {
                rgb,
                depth,
                k: K,
                request,
            },
        )
    }
}

fn eye_name(eye: Eye) -> &'static str {
    match eye {
        Eye::Left => "left",
        Eye::Right => "right",
    }
}

/// Validates `a`, renders every target with the GIL released, and returns {eye name: dict}.
fn reproject<'py>(py: Python<'py>, gpu: Backend, a: ReprojectArgs<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let request = a.request;
    let k = arrays::intrinsics(a.k, "K")?;
    let plan = request.rig(k.fx).map_err(errors::from_request)?;
    let src = plan.source(
        arrays::rgb_image(a.rgb, "rgb")?,
        arrays::float_map(a.depth, "depth")?,
        Conventions::default(),
    );
    let (w, h) = (src.color.width, src.color.height);
    if (src.depth.width, src.depth.height) != (w, h) {
        return Err(errors::invalid(
            "depth",
            format!(
                "{}x{} (W x H) differs from rgb's {w}x{h}",
                src.depth.width, src.depth.height
            ),
        ));
    }
    src.validate().map_err(errors::from_library)?;
    gpu.check_image_size("rgb", w, h).map_err(errors::from_library)?;
    src.require_valid_depth(&format!("depth_kind=\"{}\"", request.depth_kind.option_value()))
        .map_err(|e| errors::invalid("depth", e))?;

    // The inputs were copied out of numpy above; see SameThread for why the move is sound.
    let work = SameThread((gpu, src, plan));
    let result = py.detach(move || {
        let work = work;
        let (gpu, src, plan) = work.0;
        SameThread(gpu.to_device().and_then(|device| plan.render(&device, &src, k)))
    });
    let rendered = result.0.map_err(errors::from_library)?;

    let views = PyDict::new(py);
    for RenderedTarget {
        to,
        out,
        timing,
        setup_ms,
    } in rendered
    {
        let d = PyDict::new(py);
        d.set_item("coverage", out.coverage())?;
        let timings = PyDict::new(py);
        timings.set_item("setup_ms", setup_ms)?;
        timings.set_item("render_ms", timing.wall_ms)?;
        timings.set_item("gpu_ms", timing.gpu_ms)?;
        d.set_item("timings", timings)?;
        if let Some(img) = out.color {
            d.set_item("rgb", arrays::rgb_array(py, img))?;
        }
        if let Some(z) = out.depth {
            d.set_item("depth", arrays::depth_array(py, z))?;
        }
        if request.outputs().mask {
            let bits = out.mask.iter().map(|m| (*m != 0) as u8).collect();
            let mask = viewsynth::io::Mask::new(w, h, bits).map_err(errors::from_library)?;
            d.set_item("mask", arrays::mask_array(py, mask))?;
        }
        // A rig's targets are eyes; the middle camera is a camera file's (not given here).
        views.set_item(to.map_or("centre", eye_name), d)?;
    }
    Ok(views)
}
