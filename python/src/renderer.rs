//! `viewsynth.Renderer`: one EGL context (shared per thread, see `context`), the refocus call and
//! the cyclopean, reproject, stitch and refocus_batch calls (their work in `cyclopean`,
//! `reproject`, `stitch`, `batch`).

use crate::arrays;
use crate::backend::Backend;
use crate::context;
use crate::errors::{self, Kind};
use crate::shared::{choice, outputs_given, SameThread};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use viewsynth::camera::PinholeCamera;
use viewsynth::convention::Conventions;
use viewsynth::job::cyclopean::CyclopeanRequest;
use viewsynth::job::refocus::RefocusRequest;
use viewsynth::job::reproject::ReprojectRequest;
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusOutput, RefocusSource, Refocuser};

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

/// Fraction of output pixels that hold a value (as the CLI's manifest: the mask's, else depth's).
fn coverage(out: &RefocusOutput) -> Option<f64> {
    if let Some(m) = &out.mask {
        return Some(m.data.iter().filter(|v| **v != 0).count() as f64 / m.data.len() as f64);
    }
    out.depth
        .as_ref()
        .map(|d| d.data.iter().filter(|z| **z > 0.0).count() as f64 / d.data.len() as f64)
}

/// A value usable only on the thread that made it: every access checks the thread and fails
/// with a catchable `WrongThreadError` elsewhere (pyo3's `unsendable` would raise a
/// `PanicException`, which `except Exception` does not catch). Dropped on another thread, the
/// value is leaked, never freed there.
struct ThreadBound<T> {
    owner: std::thread::ThreadId,
    value: std::mem::ManuallyDrop<T>,
}

// SAFETY: the value is reached only through `get`/`take`, which refuse every thread but the
// owner, and `Drop` frees it only on the owner: it never crosses threads.
unsafe impl<T> Send for ThreadBound<T> {}
// SAFETY: as above; a shared reference gives no access to the value off the owner thread.
unsafe impl<T> Sync for ThreadBound<T> {}

impl<T> ThreadBound<T> {
    fn new(value: T) -> Self {
        ThreadBound {
            owner: std::thread::current().id(),
            value: std::mem::ManuallyDrop::new(value),
        }
    }

    fn on_owner(&self) -> bool {
        std::thread::current().id() == self.owner
    }

    fn check(&self) -> PyResult<()> {
        if self.on_owner() {
            return Ok(());
        }
        Err(errors::raise(
            Kind::WrongThread,
            "this Renderer belongs to the thread that created it (its EGL context is current there \
             only); create one Renderer per thread, e.g. in threading.local()",
            None,
        ))
    }

    fn get(&self) -> PyResult<&T> {
        self.check()?;
        Ok(&self.value)
    }

    fn get_mut(&mut self) -> PyResult<&mut T> {
        self.check()?;
        Ok(&mut self.value)
    }
}

impl<T> Drop for ThreadBound<T> {
    fn drop(&mut self) {
        if self.on_owner() {
            // SAFETY: dropped once, here, on the owner thread.
            unsafe { std::mem::ManuallyDrop::drop(&mut self.value) }
        }
    }
}

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
        let choice = context::parse_device(device)?;
        let gpu = match backend {
            "gl" => Backend::Gl(context::acquire(choice)?),
            "vulkan" => {
                // The CLI's --backend vulkan: the same device choice and software policy.
                let request = viewsynth::job::GpuRequest {
                    device: choice,
                    policy: viewsynth::gpu::GpuPolicy {
                        require_hardware: require_gpu,
                    }
                    .with_env()
                    .map_err(errors::from_library)?,
                };
                let vk = request.open_vulkan().map_err(errors::from_library)?;
                let device = viewsynth::vulkan::VkExecutor::device(&vk).map_err(errors::from_library)?;
                Backend::Vulkan(device, vk.info().clone())
            }
            other => {
                return Err(errors::invalid(
                    "backend",
                    format!("'{other}': expected \"gl\" or \"vulkan\""),
                ))
            }
        };
        let renderer = Renderer {
            gpu: ThreadBound::new(Some(gpu)),
            pid: std::process::id(),
            device: device.to_string(),
        };
        if let (true, Backend::Gl(gpu)) = (require_gpu, renderer.gpu()?) {
            let info = gpu.info();
            if info.software {
                return Err(errors::raise(
                    Kind::GpuUnavailable,
                    format!(
                        "require_gpu=True but EGL device '{device}' gave the software renderer '{}' \
                         (no GPU driver with EGL visible to this process)",
                        info.renderer
                    ),
                    Some("require_gpu"),
                ));
            }
        }
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

    /// Re-render one RGB-D frame at other focal lengths from the same pose (no hole filling:
    /// what the source did not see stays invalid).
    ///
    /// rgb: uint8[H, W, 3], C-contiguous. depth: float32[H, W], C-contiguous, view-space Z in
    /// metres (0, NaN, inf or negative = no depth). K: 3x3 pinhole [[fx, 0, cx], [0, fy, cy],
    /// [0, 0, 1]] (any numeric dtype or nested lists; no skew), OpenCV pixel centres.
    /// Targets, one of: scales=[s, ...] (fx' = s fx, fy' = s fy) or K_out=[K', ...] (3x3 each);
    /// neither: the CLI's default scales (0.5, 0.75, 1, 1.5, 2).
    /// size: (width, height) of the outputs (default: the source's). principal: (cx', cy') with
    /// scales (default: the source's offset from the image centre).
    /// outputs: any of "rgb", "depth", "mask" (default all three); only those are rendered.
    /// tau_rel, tau_abs: an edge between neighbouring depths za, zb breaks when
    /// |za - zb| > tau_rel * min(za, zb) or > tau_abs metres (inf disables).
    /// method: "fullscreen" (fast, default) or "mesh"; both give the same images.
    /// rgb_everywhere: colour at every pixel inside the source frame (mask and depth unchanged).
    /// Stacks: rgb uint8[N, H, W, 3], depth float32[N, H, W], K 3x3 or [N, 3, 3] give a list of
    /// N lists, each what the single call gives. Strided arrays (slices, bgr[..., ::-1]) are
    /// copied once, as contiguous ones are.
    ///
    /// Returns one dict per target, in order: "scale" (fx'/fx), "K" (float64[3, 3]),
    /// "coverage" (fraction of valid pixels; None with rgb alone), "timings" (setup_ms: upload
    /// of this call's source, shared by its targets; render_ms; gpu_ms, None where GPU timers
    /// are not meaningful; readback_ms), and the requested arrays: "rgb" uint8[H', W', 3]
    /// (0 where invalid), "depth" float32[H', W'] (view-space Z, 0 where invalid), "mask"
    /// bool[H', W']. The arrays are new and owned by the caller (no copy on the way out).
    ///
    /// Raises InvalidInputError (a ValueError) naming the argument for a wrong dtype, shape,
    /// memory layout or value; GpuError if the GPU fails.
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
            method: choice("--method", method)?,
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
            d.set_item("coverage", coverage(&out))?;
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

    /// Synthesise an in-between view of a stereo pair: the library calls of `viewsynth
    /// cyclopean`, from disparities of a rectified pair (its --left-disparity mode), from each
    /// eye's depth placed by cameras (its --left-depth ... --cameras mode), or from a rectified
    /// pair alone (the disparities estimated by the census matcher over 0..=max_disparity px;
    /// default a sixth of the width, rounded up to 16, in 16..=256; min_confidence in [0, 1]
    /// drops the estimates the matcher trusts less, trading coverage for precision; confidence=True
    /// also returns each eye's confidence as "left_confidence" and "right_confidence",
    /// float32[H, W] in [0, 1], 0 where the disparity is unknown: the CLI's --confidence).
    ///
    /// left_rgb, right_rgb: uint8[H, W, 3], C-contiguous. Then one of:
    /// - left_disparity, right_disparity: float32[H, W], pixels, x_right = x_left - d (left) and
    ///   x_left = x_right + d (right; an array of zeros if the right eye has none); 0, negative
    ///   or non-finite = unknown. Scale integer disparities to pixels first (Middlebury 2003
    ///   PGMs: / 4). position: where the view sits, 0 = left eye, 0.5 (default) = middle, 1 =
    ///   right eye. focal (pixels) and baseline (metres): both or neither; with them the view's
    ///   metric depth can be asked for (without them only f B matters, and nominal values are
    ///   used). doffs: right principal point minus left, pixels (Middlebury 2014): depth =
    ///   f B / (d + doffs).
    /// - left_depth, right_depth: float32[H, W] holding cameras["depth_kind"]: "view-z" (view-space
    ///   Z in metres; 0, NaN, inf or negative = none) or "device" (window depth in [0, 1] written
    ///   with each eye's near/far under cameras["conventions"]), and cameras: a path to a
    ///   cameras.json as `viewsynth cyclopean --cameras` reads (`viewsynth scene` writes one), or
    ///   a dict with its keys: "depth_kind"; "left", "right", "middle", each either
    ///   {"K": 3x3 [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (pixels, OpenCV pixel centres), "R": 3x3
    ///   rotation and "t": 3 (world -> camera, x_cam = R x_world + t, OpenCV axes: x right, y
    ///   down, z forward), "width", "height", "near", "far"} or GL matrices {"view": 4x4, "proj":
    ///   4x4} (the middle needs "width"/"height" and may leave its pose to "gaze"); "fixation_distance"
    ///   (metres along the view axis, where seed/refine start) or "gaze" ({"left"/"right":
    ///   {"origin", "direction"}}); optionally "conventions", "head_rotation", "fixation_range".
    ///   Values may be numbers, lists, tuples or numpy arrays. The view is the middle camera's
    ///   (its size); position, focal, baseline and doffs do not apply.
    /// method: "splat-gather" (the default, the best on real stereo), "seed", "refine" or
    /// "forward"; refine_steps (0..=16; alone it picks seed for 0, else refine; default 3),
    /// blend ("hard" or "soft"), z_threshold (metres) and dominant ("left:W" or "right:W") tune
    /// seed and refine only. All as the CLI's options of the same names, decided by the same
    /// library request (viewsynth.job.cyclopean.CyclopeanRequest).
    /// outputs: any of "rgb", "depth", "mask" (default rgb and mask, plus depth with focal or
    /// with depth input).
    /// fill: the CLI's --fill: holes (pixels no eye saw) take the nearest rendered pixel on their
    /// background side along the row (both sides one surface: their mix by distance; an empty
    /// row: the column), so the frame is complete; "filled" bool[H, W] says where.
    ///
    /// Returns a dict: "coverage" (fraction of pixels some eye saw), "timings" (setup_ms:
    /// uploads and set-up; render_ms; gpu_ms, None where GPU timers are not meaningful), and the
    /// requested arrays: "rgb" uint8[H, W, 3], "depth" float32[H, W] (the view's Z in metres, 0
    /// where invalid), "mask" bool[H, W] (True where some eye saw the surface).
    ///
    /// Raises InvalidInputError (a ValueError) naming the argument for a wrong dtype, shape,
    /// layout or value (for cameras the message names the field, e.g. left.R); FileError for an
    /// unreadable cameras file; GpuError if the GPU fails.
    #[allow(clippy::too_many_arguments)]
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

    /// Reproject one view of a parallel stereo rig (left eye, centre view or right eye) to the
    /// other eye(s) from colour + depth: the library calls of `viewsynth reproject` with a rig
    /// (--baseline or --separation/--convergence). Disocclusions stay invalid (no hole filling).
    ///
    /// rgb: uint8[H, W, 3]; depth: float32[H, W] holding depth_kind: "view-z" (metres; 0, NaN,
    /// inf or negative = none), "device" (window depth in [0, 1] written with near and far,
    /// OpenGL conventions; the far value is background) or "disparity" (pixels; Z = baseline *
    /// focal / (d + doffs), d <= 0 unknown). K: 3x3 pinhole of the source, as for refocus.
    /// The rig: baseline (metres; x_right = x_left + doffs - f B / Z) with focal (pixels,
    /// default K's fx) and doffs (cx_right - cx_left), or a game-engine separation and
    /// convergence (metres).
    /// source: "left", "centre" or "right"; target: "left", "right" or "both" (from the centre).
    /// method: "shift-scan" (exact, default), "shift" or "gather3d" (both with steps, 1..=16).
    /// tau_rel: a row segment breaks where |Za - Zb| > tau_rel * min(Za, Zb).
    /// outputs: any of "rgb", "depth", "mask" (a sequence, or one comma-separated string; default
    /// all three).
    ///
    /// Returns {"left": view, "right": view} for the targets rendered, each view a dict:
    /// "coverage", "timings" (setup_ms, render_ms, gpu_ms) and the requested arrays "rgb"
    /// uint8[H, W, 3], "depth" float32[H, W] (the target's Z in metres, 0 where invalid),
    /// "mask" bool[H, W].
    ///
    /// Raises InvalidInputError (a ValueError) naming the argument for a wrong dtype, shape,
    /// layout or value; GpuError if the GPU fails.
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
    /// Stitch an omni-directional stereo (ODS) 360 from each eye's six over-wide cube faces:
    /// the library calls of `viewsynth stitch --faces DIR`, the faces given as arrays.
    ///
    /// left_rgb, right_rgb: uint8[6, N, N, 3]; left_depth, right_depth: float32[6, N, N], the
    /// faces in viewsynth.FACE_ORDER ("pz" front +Z, "nz" back, "up", "down", "px" right +X,
    /// "nx" left), each an N x N pinhole with horizontal and vertical FOV fov (> 90 degrees),
    /// centred principal point, OpenCV axes (the README's stitch section gives the poses: each
    /// side face of an eye rendered from IPD/2 along the face's right axis, left eye -IPD/2;
    /// up and down from the centre). Depth is view-space Z in metres (0, NaN or inf =
    /// background), or with depth_kind="device" window depth written with near and far under
    /// ndc ("gl" or "vulkan") and reversed_z (converted to view Z in float64 first).
    /// fov, overlap (degrees): as the CLI's --fov/--overlap: default 110 and 10; either alone
    /// sets the other (overlap = (fov - 90) / 2); overlap is the seam band's half-width.
    /// method: "reproject" (default, depth-aware along the ODS ray), "blend" or "border-weight".
    /// width, height: each eye's equirect. ipd: metres (the faces' units). pole_fade: latitude
    /// (degrees) above which the stereo fades to mono at the poles.
    ///
    /// Returns a dict: "rgb" uint8[2 height, width, 3] (top-bottom, left eye on top: the CLI's
    /// ods_top_bottom.png), "left" and "right" (uint8[height, width, 3] views of "rgb", no copy:
    /// ods_left.png, ods_right.png), "fov" and "overlap" (degrees, as resolved), "timings"
    /// (setup_ms: face uploads and shader set-up; render_ms; gpu_ms, None where GPU timers are
    /// not meaningful). The stitch has no depth output.
    ///
    /// Raises InvalidInputError (a ValueError) naming the argument for a wrong dtype, shape,
    /// layout or value; GpuError if the GPU fails.
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

    /// Refocus frames from files into files: `viewsynth refocus --batch` on this Renderer's
    /// context (the library's batch: the same decoders, targets, writers, folder layout,
    /// manifest.json per frame, resume and all-or-none frame folders), with the GIL released.
    /// For data pipelines that hand each worker a share of the frames (see
    /// python/examples/ray_refocus.py); frames in memory go through refocus() instead.
    ///
    /// frames: a manifest path (CSV or JSON, as the CLI's --batch), or a sequence of dicts with
    /// the manifest's keys "name", "rgb", "depth", "fx", "fy", "cx", "cy" and optionally
    /// "depth_scale", "sun_bit_rotate" (viewsynth.load_manifest returns them; paths relative
    /// to the working directory). Each frame writes out_dir/<name>/.
    /// scales, size, principal, outputs, tau_rel, tau_abs, method: as refocus().
    /// rgb_format: "png", "jpeg" or "exr"; depth_format: any of "exr", "npy", "png16";
    /// depth_preview, png_compression ("fast", "default", "best"), exr_compression ("none",
    /// "rle", "zip", "piz"), depth_trunc (metres), resume (skip frames finished with the same
    /// settings; False = the CLI's --force), jobs (decode and encode threads around the GL
    /// thread, default the core count; 0 = every stage in turn on this thread), shard ("K/N"):
    /// the CLI's options of the same names; so are rgb_everywhere, zoom_random=(lo, hi), samples
    /// and seed (--zoom-random, log-uniform draws). progress: f(done, total) per frame, or True.
    /// index: write out_dir/index.jsonl (the CLI's, joined over shards); pass False when frames
    /// is a share of a manifest you split yourself (Ray, Dask), then call viewsynth.write_index
    /// once over the whole manifest. Either way a call that rewrites frames first removes the
    /// index (and the parts that could list them), so an interrupted call leaves none stale.
    ///
    /// Returns the batch summary: "rendered", "skipped", "other_shards", "failed" (a list of
    /// [frame name, error message]: a failed frame leaves no folder and does not stop the
    /// others), "wall_s", "frames_in_flight", "stages" (per-frame milliseconds of each stage).
    ///
    /// Raises InvalidInputError for a bad argument or frame entry, FileError for an unreadable
    /// manifest or an unusable out_dir.
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
