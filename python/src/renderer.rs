//! `viewsynth.Renderer`: an EGL context (`context`) or Vulkan device (`backend`) held for its
//! thread (`thread_bound`), and its calls' Python signatures: each capability's work is its own
//! module (`refocus`, `cyclopean`, `reproject`, `stitch`, `batch`), long docstrings in `doc/`.

use crate::backend::Backend;
use crate::context;
use crate::errors::{self, Kind};
use crate::shared::{choice, outputs_given};
use crate::thread_bound::ThreadBound;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use viewsynth::job::cyclopean::CyclopeanRequest;
use viewsynth::job::reproject::ReprojectRequest;

/// An OpenGL 4.5 context over EGL (a GPU, or Mesa's llvmpipe on the CPU), or a Vulkan 1.3
/// device running the same shaders (backend="vulkan"), for refocusing numpy
/// RGB-D frames (refocus), synthesising in-between views of stereo pairs (cyclopean),
/// reprojecting a view of a stereo rig to the other eye (reproject), stitching an ODS 360 from
/// cube faces (stitch), and refocusing frames from files into files as the CLI's batch
/// (refocus_batch).
///
/// device: "auto" (the CUDA_VISIBLE_DEVICES GPU, else EGL device 0, else Mesa surfaceless),
/// "surfaceless", or an EGL device index as a string ("0", "1", ...).
/// require_gpu: raise GpuUnavailableError when EGL only offers a software renderer (with
/// backend="vulkan": refuse a CPU Vulkan device such as lavapipe, as the CLI's --require-gpu).
/// backend: "gl" (default) or "vulkan", as the CLI's --backend: every call renders on it, with
/// the same outputs within the GL-vs-Vulkan agreement rule (device then is "auto" or an index of
/// `viewsynth info --backend vulkan`). gl_objects() is for GL only.
///
/// Threads: a Renderer belongs to the thread that created it; using it on another thread raises
/// WrongThreadError. Open one per thread (threading.local()); Renderers opened on the same
/// thread with the same device share one context. The GIL is released while the GPU renders.
///
/// Processes: an EGL context does not survive fork. With multiprocessing or a torch DataLoader,
/// create the Renderer inside each worker, lazily on first use (or in worker_init_fn):
/// - "spawn" / "forkserver" workers: always fine;
/// - "fork" workers (Linux default): fine only if the parent never opened a Renderer (nor called
///   viewsynth.info()); otherwise the child raises RendererForkedError instead of hanging.
/// A Renderer does not pickle: pass frames to workers, not the Renderer.
///
/// Release the context with close() or a with-block; garbage collection also releases it.
#[pyclass(module = "viewsynth")]
pub struct Renderer {
    gpu: ThreadBound<Option<Backend>>,
    /// Process that opened the context: a forked child must not use (or free) it.
    pid: u32,
    device: String,
}

impl Renderer {
    fn gpu(&self) -> PyResult<&Backend> {
        if self.pid != std::process::id() {
            return Err(errors::raise(
                Kind::Forked,
                format!(
                    "this Renderer was created in process {} and this is process {} (forked after it was \
                     created): an EGL context does not survive fork; create the Renderer inside each \
                     worker, after the fork (e.g. lazily on first use or in worker_init_fn)",
                    self.pid,
                    std::process::id()
                ),
                None,
            ));
        }
        self.gpu
            .get()?
            .as_ref()
            .ok_or_else(|| errors::raise(Kind::Closed, "this Renderer is closed", None))
    }

    fn close_inner(&mut self) -> PyResult<()> {
        let forked = self.pid != std::process::id();
        if let Some(backend) = self.gpu.get_mut()?.take() {
            match (backend, forked) {
                // The parent's context or device: never to be freed (or used) in the child.
                (backend, true) => std::mem::forget(backend),
                (Backend::Gl(gpu), false) => context::release(gpu),
                (Backend::Vulkan(..), false) => {}
            }
        }
        Ok(())
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        // On another thread `close_inner` fails and ThreadBound leaks the handle instead.
        let _ = self.close_inner();
    }
}

#[pymethods]
impl Renderer {
    #[new]
    #[pyo3(signature = (device = "auto", require_gpu = false, backend = "gl"))]
    fn new(device: &str, require_gpu: bool, backend: &str) -> PyResult<Self> {
        let gpu = Backend::open(device, require_gpu, backend)?;
        let renderer = Renderer {
            gpu: ThreadBound::new(Some(gpu)),
            pid: std::process::id(),
            device: device.to_string(),
        };
        Ok(renderer)
    }

    /// "gl" or "vulkan".
    #[getter]
    fn backend(&self) -> PyResult<&'static str> {
        Ok(match self.gpu()? {
            Backend::Gl(_) => "gl",
            Backend::Vulkan(..) => "vulkan",
        })
    }

    /// What the context runs on (vendor, renderer, GL version, EGL platform and device, limits).
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match self.gpu()? {
            Backend::Gl(gpu) => crate::info_dict(py, gpu.info()),
            Backend::Vulkan(_, info) => {
                let text = serde_json::to_string(info)
                    .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
                py.import("json")?.call_method1("loads", (text,))
            }
        }
    }

    /// The GL objects this Renderer's context holds now, by kind: {"textures", "framebuffers",
    /// "buffers", "programs", "vertex_arrays", "queries", "syncs"} -> count. Between calls only
    /// the readback pool (pixel-pack buffers, timer queries) stays, so a steady stream of
    /// same-sized calls leaves the counts unchanged; growth is a leak. Renderers on one thread
    /// share a context, hence these counts.
    fn gl_objects<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let Backend::Gl(gpu) = self.gpu()? else {
            return Err(errors::invalid(
                "backend",
                "gl_objects() counts GL objects; this Renderer runs on Vulkan",
            ));
        };
        let counts = gpu.live_objects();
        let text =
            serde_json::to_string(&counts).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// True after close().
    #[getter]
    fn closed(&self) -> PyResult<bool> {
        Ok(self.gpu.get()?.is_none())
    }

    /// Release the context now (it is also released when the Renderer is garbage-collected).
    fn close(&mut self) -> PyResult<()> {
        self.close_inner()
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_exc))]
    fn __exit__(&mut self, _exc: &Bound<'_, pyo3::types::PyTuple>) -> PyResult<bool> {
        self.close_inner()?;
        Ok(false)
    }

    /// A context cannot travel to another process: say what to do instead.
    fn __reduce__(&self) -> PyResult<()> {
        Err(pyo3::exceptions::PyTypeError::new_err(
            "cannot pickle a viewsynth.Renderer (it holds a GPU context of this process): create one \
             inside each worker instead, e.g. lazily on first use",
        ))
    }

    fn __repr__(&self) -> String {
        if !self.gpu.on_owner() {
            return format!("Renderer(device={:?}, owned by another thread)", self.device);
        }
        match (&*self.gpu.value, self.pid == std::process::id()) {
            (Some(Backend::Gl(gpu)), true) => {
                format!("Renderer(device={:?}, renderer={:?})", self.device, gpu.info().renderer)
            }
            (Some(Backend::Vulkan(_, info)), true) => {
                format!(
                    "Renderer(device={:?}, backend=\"vulkan\", renderer={:?})",
                    self.device, info.name
                )
            }
            (Some(_), false) => format!("Renderer(device={:?}, inherited through fork: unusable)", self.device),
            (None, _) => format!("Renderer(device={:?}, closed)", self.device),
        }
    }

    #[doc = include_str!("doc/refocus.txt")]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (rgb, depth, K, *, scales = None, K_out = None, size = None, principal = None,
                        outputs = None, tau_rel = 0.05, tau_abs = 0.2, method = "fullscreen", rgb_everywhere = false))]
    fn refocus<'py>(
        &mut self,
        py: Python<'py>,
        rgb: &Bound<'py, PyAny>,
        depth: &Bound<'py, PyAny>,
        K: &Bound<'py, PyAny>,
        scales: Option<Vec<f64>>,
        K_out: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = crate::ints::size)] size: Option<(u32, u32)>,
        principal: Option<(f64, f64)>,
        outputs: Option<&Bound<'py, PyAny>>,
        tau_rel: f64,
        tau_abs: f64,
        method: &str,
        rgb_everywhere: bool,
    ) -> PyResult<Bound<'py, PyList>> {
        if let Some(frames) = crate::stack::frames(rgb, depth, K)? {
            let views = PyList::empty(py);
            for (rgb, depth, k) in frames {
                let (s, o) = (scales.clone(), outputs);
                let one = self.refocus(
                    py,
                    &rgb,
                    &depth,
                    &k,
                    s,
                    K_out,
                    size,
                    principal,
                    o,
                    tau_rel,
                    tau_abs,
                    method,
                    rgb_everywhere,
                );
                views.append(one?)?;
            }
            return Ok(views);
        }
        let gpu = self.gpu()?.clone();
        crate::refocus::refocus(
            py,
            gpu,
            crate::refocus::RefocusArgs {
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
            },
        )
    }

    #[doc = include_str!("doc/cyclopean.txt")]
    #[allow(clippy::too_many_arguments, clippy::doc_lazy_continuation)] // the doc: Python text
    #[pyo3(signature = (left_rgb, right_rgb, left_disparity = None, right_disparity = None, position = None, *,
                        left_depth = None, right_depth = None, cameras = None, method = None,
                        refine_steps = None, blend = None, z_threshold = None, dominant = None,
                        focal = None, baseline = None, doffs = 0.0, outputs = None, fill = false,
                        max_disparity = None, min_confidence = None, confidence = false))]
    fn cyclopean<'py>(
        &mut self,
        py: Python<'py>,
        left_rgb: &Bound<'py, PyAny>,
        right_rgb: &Bound<'py, PyAny>,
        left_disparity: Option<&Bound<'py, PyAny>>,
        right_disparity: Option<&Bound<'py, PyAny>>,
        position: Option<f64>,
        left_depth: Option<&Bound<'py, PyAny>>,
        right_depth: Option<&Bound<'py, PyAny>>,
        cameras: Option<&Bound<'py, PyAny>>,
        method: Option<&str>,
        #[pyo3(from_py_with = crate::ints::refine_steps)] refine_steps: Option<u32>,
        blend: Option<&str>,
        z_threshold: Option<f64>,
        dominant: Option<String>,
        focal: Option<f64>,
        baseline: Option<f64>,
        doffs: f64,
        outputs: Option<&Bound<'py, PyAny>>,
        fill: bool,
        #[pyo3(from_py_with = crate::ints::max_disparity)] max_disparity: Option<u32>,
        min_confidence: Option<f64>,
        confidence: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let gpu = self.gpu()?.clone();
        // The settings as the library's request: it alone decides and checks them.
        let request = CyclopeanRequest {
            method: method.map(|m| choice("--method", m)).transpose()?,
            refine_steps,
            blend: blend.map(|b| choice("--blend", b)).transpose()?,
            z_threshold,
            dominant,
            position,
            focal,
            baseline,
            doffs,
            outputs: outputs_given(outputs)?,
            fill,
            max_disparity: max_disparity.map(|m| m.min(i32::MAX as u32) as i32),
            min_disparity: None,
            min_confidence,
            confidence,
        };
        crate::cyclopean::cyclopean(
            py,
            gpu,
            crate::cyclopean::CyclopeanArgs {
                left_rgb,
                right_rgb,
                left_disparity,
                right_disparity,
                left_depth,
                right_depth,
                cameras,
                request,
            },
        )
    }

    #[doc = include_str!("doc/reproject.txt")]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (rgb, depth, K, *, depth_kind = "view-z", baseline = None, focal = None, doffs = 0.0,
                        separation = None, convergence = None, near = None, far = None, source = "left",
                        target = "right", method = "shift-scan", steps = 3, tau_rel = 0.05, outputs = None))]
    fn reproject<'py>(
        &mut self,
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
        method: &str,
        #[pyo3(from_py_with = crate::ints::steps)] steps: u32,
        tau_rel: f64,
        outputs: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let gpu = self.gpu()?.clone();
        // The settings as the library's request: it alone decides and checks them.
        let request = ReprojectRequest {
            depth_kind: choice("--depth-kind", depth_kind)?,
            near,
            far,
            baseline,
            focal,
            doffs,
            separation,
            convergence,
            from: choice("--from", source)?,
            to: choice("--to", target)?,
            method: choice("--method", method)?,
            steps,
            tau_rel,
            outputs: outputs_given(outputs)?,
        };
        crate::reproject::reproject(
            py,
            gpu,
            crate::reproject::ReprojectArgs {
                rgb,
                depth,
                k: K,
                request,
            },
        )
    }
    #[doc = include_str!("doc/stitch.txt")]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (left_rgb, left_depth, right_rgb, right_depth, *, fov = None, overlap = None,
                        method = "reproject", width = 2048, height = 1024, ipd = 0.064, pole_fade = 45.0,
                        depth_kind = "view-z", near = None, far = None, ndc = "gl", reversed_z = false))]
    fn stitch<'py>(
        &mut self,
        py: Python<'py>,
        left_rgb: &Bound<'py, PyAny>,
        left_depth: &Bound<'py, PyAny>,
        right_rgb: &Bound<'py, PyAny>,
        right_depth: &Bound<'py, PyAny>,
        fov: Option<f64>,
        overlap: Option<f64>,
        method: &str,
        #[pyo3(from_py_with = crate::ints::width)] width: u32,
        #[pyo3(from_py_with = crate::ints::height)] height: u32,
        ipd: f64,
        pole_fade: f64,
        depth_kind: &str,
        near: Option<f64>,
        far: Option<f64>,
        ndc: &str,
        reversed_z: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let gpu = self.gpu()?.clone();
        crate::stitch::stitch(
            py,
            gpu,
            crate::stitch::StitchArgs {
                left_rgb,
                left_depth,
                right_rgb,
                right_depth,
                fov,
                overlap,
                method,
                width,
                height,
                ipd,
                pole_fade,
                depth_kind,
                near,
                far,
                ndc,
                reversed_z,
            },
        )
    }

    #[doc = include_str!("doc/refocus_batch.txt")]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (frames, out_dir, *, scales = None, size = None, principal = None,
                        outputs = None, tau_rel = 0.05, tau_abs = 0.2, method = "fullscreen", rgb_format = "png",
                        depth_format = None, depth_preview = false, png_compression = "fast",
                        exr_compression = "zip", depth_trunc = None, resume = true, jobs = None, shard = None,
                        rgb_everywhere = false, zoom_random = None, samples = None, seed = None, progress = None,
                        index = true))]
    fn refocus_batch<'py>(
        &mut self,
        py: Python<'py>,
        frames: &Bound<'py, PyAny>,
        out_dir: std::path::PathBuf,
        scales: Option<Vec<f64>>,
        #[pyo3(from_py_with = crate::ints::size)] size: Option<(u32, u32)>,
        principal: Option<(f64, f64)>,
        outputs: Option<&Bound<'py, PyAny>>,
        tau_rel: f64,
        tau_abs: f64,
        method: &str,
        rgb_format: &str,
        depth_format: Option<&Bound<'py, PyAny>>,
        depth_preview: bool,
        png_compression: &str,
        exr_compression: &str,
        depth_trunc: Option<f64>,
        resume: bool,
        #[pyo3(from_py_with = crate::ints::jobs)] jobs: Option<usize>,
        shard: Option<&str>,
        rgb_everywhere: bool,
        zoom_random: Option<(f64, f64)>,
        samples: Option<usize>,
        seed: Option<u64>,
        progress: Option<Bound<'py, PyAny>>,
        index: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let gpu = self.gpu()?.clone();
        crate::batch::refocus_batch(
            py,
            gpu,
            crate::batch::BatchArgs {
                frames,
                out_dir,
                scales,
                size,
                principal,
                outputs,
                tau_rel,
                tau_abs,
                method,
                rgb_format,
                depth_format,
                depth_preview,
                png_compression,
                exr_compression,
                depth_trunc,
                resume,
                jobs,
                shard,
                index,
                augment: crate::augment::Augment {
                    rgb_everywhere,
                    zoom_random,
                    samples,
                    seed,
                    progress,
                },
            },
        )
    }
}
