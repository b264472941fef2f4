//! `viewsynth.Renderer`: an EGL context (`context`) or Vulkan device (`backend`) held for its
//! thread (`thread_bound`), its lifetime (close, with-blocks, fork, pickling) and what it runs
//! on. Each capability's Python method is in that capability's own module, in a `#[pymethods]`
//! block of its own (pyo3's `multiple-pymethods`): `refocus`, `cyclopean`, `reproject`, `stitch`,
//! `batch` (`refocus_batch`); they reach the context through `Renderer::gpu`. Long docstrings are
//! in `doc/`.

use crate::backend::Backend;
use crate::context;
use crate::errors::{self, Kind};
use crate::thread_bound::ThreadBound;
use pyo3::prelude::*;
use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};

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
///
/// Re-entrant use: while a call renders (e.g. from refocus_batch's progress callback), rendering
/// or closing with the same Renderer raises RendererBusyError; its properties stay readable.
// Frozen: every method takes &self, so pyo3 never borrow-checks the object (its refusal was a
// bare RuntimeError("Already borrowed")); `busy` refuses re-entrant calls with our own class.
#[pyclass(module = "viewsynth", frozen)]
pub struct Renderer {
    gpu: ThreadBound<RefCell<Option<Backend>>>,
    /// A rendering call of this Renderer is running (see `Renderer::enter`).
    busy: AtomicBool,
    /// Process that opened the context: a forked child must not use (or free) it.
    pid: u32,
    device: String,
}

/// A rendering call in progress: the Renderer is busy until it is dropped.
pub(crate) struct Busy<'a>(&'a AtomicBool);

impl Drop for Busy<'_> {
    fn drop(&mut self) {
        self.0.store(false, Ordering::Release);
    }
}

impl Renderer {
    /// The backend for a rendering call, and the mark that the Renderer is busy until the call
    /// ends: a call made meanwhile (from a callback of this one) is refused.
    pub(crate) fn enter(&self) -> PyResult<(Backend, Busy<'_>)> {
        // Thread, process and closed first: those refusals say more than "busy".
        let backend = self.gpu()?;
        if self.busy.swap(true, Ordering::AcqRel) {
            return Err(busy("render with it"));
        }
        Ok((backend, Busy(&self.busy)))
    }

    /// This thread's and this process's backend.
    fn gpu(&self) -> PyResult<Backend> {
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
            .borrow()
            .clone()
            .ok_or_else(|| errors::raise(Kind::Closed, "this Renderer is closed", None))
    }

    fn close_inner(&self) -> PyResult<()> {
        let forked = self.pid != std::process::id();
        let taken = self.gpu.get()?.borrow_mut().take();
        if let Some(backend) = taken {
            match (backend, forked) {
                // The parent's context or device: never to be freed (or used) in the child.
                (backend, true) => std::mem::forget(backend),
                (Backend::Gl(gpu), false) => context::release(gpu),
                (Backend::Vulkan(..), false) => {}
            }
        }
        Ok(())
    }

    /// close(), refused while one of this Renderer's calls runs (its context is in use).
    fn close_busy_checked(&self) -> PyResult<()> {
        self.gpu.get()?; // another thread's call is refused as such first
        if self.busy.load(Ordering::Acquire) {
            return Err(busy("close it"));
        }
        self.close_inner()
    }
}

/// The refusal of a call made while another call of the same Renderer runs.
fn busy(what: &str) -> PyErr {
    errors::raise(
        Kind::Busy,
        format!(
            "this Renderer is busy: one of its calls is running (this call came from inside it, e.g. \
             from a progress callback); {what} after that call returns, or use another Renderer"
        ),
        None,
    )
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
            gpu: ThreadBound::new(RefCell::new(Some(gpu))),
            busy: AtomicBool::new(false),
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
        match &self.gpu()? {
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
        let Backend::Gl(gpu) = &self.gpu()? else {
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
        Ok(self.gpu.get()?.borrow().is_none())
    }

    /// Release the context now (it is also released when the Renderer is garbage-collected).
    fn close(&self) -> PyResult<()> {
        self.close_busy_checked()
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_exc))]
    fn __exit__(&self, _exc: &Bound<'_, pyo3::types::PyTuple>) -> PyResult<bool> {
        self.close_busy_checked()?;
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
        match (&*self.gpu.value.borrow(), self.pid == std::process::id()) {
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
}
