//! Files in, files out: `viewsynth.load_manifest` and `Renderer.refocus_batch` (the method in its
//! own `#[pymethods]` block), the library's batch (`viewsynth refocus --batch`) on this
//! Renderer's context. The same code writes the same files, so a Ray Data (or any other) pipeline
//! that hands each worker a share of a manifest's frames gets exactly the CLI batch's output
//! folders. Scheduling frames is the caller's part.

use crate::augment::Augment;
use crate::backend::Backend;
use crate::errors;
use crate::renderer::Renderer;
use crate::shared::{choice, SameThread};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyMapping, PyString};
use std::path::PathBuf;
use viewsynth::convention::Conventions;
use viewsynth::job::refocus::RefocusRequest;
use viewsynth::refocus::batch::{
    is_frame_folder_name, load_manifest as read_manifest, run_batch, BatchFrame, BatchOptions,
};

/// The keys a frame may have (a manifest's columns).
const FRAME_KEYS: [&str; 9] = [
    "name",
    "rgb",
    "depth",
    "fx",
    "fy",
    "cx",
    "cy",
    "depth_scale",
    "sun_bit_rotate",
];

/// A frame as a dict of the manifest's columns (paths as strings).
fn frame_dict<'py>(py: Python<'py>, f: &BatchFrame) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", f.name.as_deref())?;
    d.set_item("rgb", f.rgb.to_string_lossy())?;
    d.set_item("depth", f.depth.to_string_lossy())?;
    d.set_item("fx", f.fx)?;
    d.set_item("fy", f.fy)?;
    d.set_item("cx", f.cx)?;
    d.set_item("cy", f.cy)?;
    d.set_item("depth_scale", f.depth_scale)?;
    d.set_item("sun_bit_rotate", f.sun_bit_rotate)?;
    Ok(d)
}

/// Read a refocus manifest as `viewsynth refocus --batch` does: CSV (header rgb,depth,fx,fy,cx,cy
/// and optional depth_scale,name) or JSON (also sun_bit_rotate); relative paths resolved against
/// the manifest's folder; every frame named ("00003_<rgb stem>" unless the manifest names it,
/// made filesystem-safe and unique). Returns a list of dicts with the keys "name", "rgb",
/// "depth", "fx", "fy", "cx", "cy", "depth_scale" (None when absent), "sun_bit_rotate": the
/// frames Renderer.refocus_batch takes, to hand out in shares (e.g. ray.data.from_items).
#[pyfunction]
pub fn load_manifest<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyList>> {
    let frames = read_manifest(&path).map_err(errors::from_library)?;
    let list = PyList::empty(py);
    for f in &frames {
        list.append(frame_dict(py, f)?)?;
    }
    Ok(list)
}

/// A frame name as the batch writes it (the library's rule): one safe folder name inside out_dir.
/// Refused, not renamed as a manifest's names are: the caller chose it and looks for it there.
fn check_name(name: &str, at: &str) -> PyResult<()> {
    if !is_frame_folder_name(name) {
        return Err(errors::invalid(
            at,
            format!("name '{name}': a frame's folder name must be non-empty, not start with '.', be at most 255 bytes and hold only ASCII letters, digits, '-', '_', '.'"),
        ));
    }
    Ok(())
}

/// `v` as a `T`, the conversion's own message in an error naming the frame and key.
fn convert<'py, T: FromPyObjectOwned<'py>>(v: &Bound<'py, PyAny>, key: &str, at: &str) -> PyResult<T> {
    v.extract::<T>().map_err(|e| {
        let e: PyErr = e.into();
        errors::invalid(at, format!("'{key}': {}", e.value(v.py())))
    })
}

fn required<'py, T: FromPyObjectOwned<'py>>(m: &Bound<'py, PyMapping>, key: &str, at: &str) -> PyResult<T> {
    let Ok(v) = m.get_item(key) else {
        return Err(errors::invalid(at, format!("missing key '{key}'")));
    };
    convert(&v, key, at)
}

fn optional<'py, T: FromPyObjectOwned<'py>>(m: &Bound<'py, PyMapping>, key: &str, at: &str) -> PyResult<Option<T>> {
    match m.get_item(key) {
        Ok(v) if v.is_none() => Ok(None),
        Ok(v) => convert(&v, key, at).map(Some),
        Err(_) => Ok(None),
    }
}

/// A frame from a mapping with the manifest's keys (paths as given, relative to the working
/// directory).
fn frame_from_mapping(obj: &Bound<'_, PyAny>, i: usize) -> PyResult<BatchFrame> {
    let at = format!("frames[{i}]");
    let m = obj
        .cast::<PyMapping>()
        .map_err(|_| errors::invalid(&at, "expected a dict with keys name, rgb, depth, fx, fy, cx, cy"))?;
    for key in m.keys()?.iter() {
        let key: String = key
            .extract()
            .map_err(|_| errors::invalid(&at, "keys must be strings"))?;
        if !FRAME_KEYS.contains(&key.as_str()) {
            return Err(errors::invalid(
                &at,
                format!("unknown key '{key}' (expected {})", FRAME_KEYS.join(", ")),
            ));
        }
    }
    let name: String = required(m, "name", &at)?;
    check_name(&name, &at)?;
    let depth_scale: Option<f64> = optional(m, "depth_scale", &at)?;
    Ok(BatchFrame {
        name: Some(name),
        rgb: required(m, "rgb", &at)?,
        depth: required(m, "depth", &at)?,
        fx: required(m, "fx", &at)?,
        fy: required(m, "fy", &at)?,
        cx: required(m, "cx", &at)?,
        cy: required(m, "cy", &at)?,
        // pandas writes a missing value as NaN: no scale, as an empty CSV cell.
        depth_scale: depth_scale.filter(|s| !s.is_nan()),
        sun_bit_rotate: optional(m, "sun_bit_rotate", &at)?.unwrap_or(false),
    })
}

/// The frames of a refocus_batch call: a manifest path, or a sequence of frame dicts.
pub fn frames(obj: &Bound<'_, PyAny>) -> PyResult<Vec<BatchFrame>> {
    if obj.cast::<PyString>().is_ok() || obj.hasattr("__fspath__")? {
        let path: PathBuf = obj
            .extract()
            .map_err(|_| errors::invalid("frames", "not a usable manifest path"))?;
        return read_manifest(&path).map_err(errors::from_library);
    }
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let items = obj
        .try_iter()
        .map_err(|_| errors::invalid("frames", "expected a manifest path or a sequence of frame dicts"))?;
    for (i, item) in items.enumerate() {
        let frame = frame_from_mapping(&item?, i)?;
        let name = frame.name.clone().unwrap_or_default();
        if !seen.insert(name.clone()) {
            return Err(errors::invalid(
                &format!("frames[{i}]"),
                format!("name '{name}' repeated: each frame writes its own folder"),
            ));
        }
        out.push(frame);
    }
    if out.is_empty() {
        return Err(errors::invalid("frames", "no frame given"));
    }
    Ok(out)
}

/// Depth file formats: any of "exr", "npy", "png16" (a comma-separated string or a sequence).
/// `depth_format=`: a name, a comma-separated list or a sequence of names, as the CLI's text.
fn depth_format_text(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(s.to_string());
    }
    let names: Vec<String> = obj
        .extract()
        .map_err(|_| errors::invalid("depth_format", "expected any of \"exr\", \"npy\", \"png16\""))?;
    Ok(names.join(","))
}

/// The arguments of one call, as Python gave them.
pub struct BatchArgs<'a, 'py> {
    pub frames: &'a Bound<'py, PyAny>,
    pub out_dir: PathBuf,
    pub scales: Option<Vec<f64>>,
    pub size: Option<(u32, u32)>,
    pub principal: Option<(f64, f64)>,
    pub outputs: Option<&'a Bound<'py, PyAny>>,
    pub tau_rel: f64,
    pub tau_abs: f64,
    pub method: &'a str,
    pub rgb_format: &'a str,
    pub depth_format: Option<&'a Bound<'py, PyAny>>,
    pub depth_png_scale: Option<f64>,
    pub depth_preview: bool,
    pub png_compression: &'a str,
    pub exr_compression: &'a str,
    pub depth_trunc: Option<f64>,
    pub resume: bool,
    /// With resume: also check every finished file's CRC-32 and every input's content.
    pub verify: bool,
    pub jobs: Option<usize>,
    pub shard: Option<&'a str>,
    /// Write the index part (and join it); False where the caller splits the manifest itself.
    pub index: bool,
    /// rgb_everywhere, random zoom and progress (augment.rs).
    pub augment: Augment<'py>,
}

#[pymethods]
impl Renderer {
    #[doc = include_str!("doc/refocus_batch.txt")]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (frames, out_dir, *, scales = None, size = None, principal = None,
                        outputs = None, tau_rel = 0.05, tau_abs = 0.2, method = "fullscreen", rgb_format = "png",
                        depth_format = None, depth_png_scale = None, depth_preview = false, png_compression = "fast",
                        exr_compression = "zip", depth_trunc = None, resume = true, verify = false, jobs = None, shard = None,
                        rgb_everywhere = false, zoom_random = None, samples = None, seed = None, progress = None,
                        index = true))]
    fn refocus_batch<'py>(
        &self,
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
        depth_png_scale: Option<f64>,
        depth_preview: bool,
        png_compression: &str,
        exr_compression: &str,
        depth_trunc: Option<f64>,
        resume: bool,
        verify: bool,
        #[pyo3(from_py_with = crate::ints::jobs)] jobs: Option<usize>,
        shard: Option<&str>,
        rgb_everywhere: bool,
        zoom_random: Option<(f64, f64)>,
        samples: Option<usize>,
        seed: Option<u64>,
        progress: Option<Bound<'py, PyAny>>,
        index: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (gpu, _busy) = self.enter()?;
        refocus_batch(
            py,
            gpu,
            BatchArgs {
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
                depth_png_scale,
                depth_preview,
                png_compression,
                exr_compression,
                depth_trunc,
                resume,
                verify,
                jobs,
                shard,
                index,
                augment: Augment {
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

/// The settings as the library's request, checked by it as the CLI's `refocus --batch`.
pub fn options(a: &BatchArgs<'_, '_>) -> PyResult<BatchOptions> {
    let request = RefocusRequest {
        scales: a.scales.clone(),
        focal_list: None,
        size: a.size,
        principal: a.principal,
        tau_rel: a.tau_rel,
        tau_abs: a.tau_abs,
        method: choice(viewsynth::Field::Method, a.method)?,
        outputs: crate::shared::outputs_given(a.outputs)?,
        rgb_format: choice(viewsynth::Field::RgbFormat, a.rgb_format)?,
        depth_format: a.depth_format.map(depth_format_text).transpose()?,
        depth_png_scale: a.depth_png_scale,
        depth_preview: a.depth_preview,
        png_compression: a.png_compression.to_string(),
        exr_compression: a.exr_compression.to_string(),
        depth_trunc: a.depth_trunc,
        resume: a.resume,
        verify: a.verify,
        jobs: a.jobs,
        shard: a.shard.map(str::to_string),
        rgb_everywhere: a.augment.rgb_everywhere,
        zoom_random: a.augment.zoom_random,
        samples: a.augment.samples,
        seed: a.augment.seed,
    };
    let mut opts = request.batch(Conventions::default()).map_err(errors::from_request)?;
    opts.index = a.index;
    Ok(opts)
}

/// Validates `a`, runs the batch with the GIL released, and returns its summary as a dict.
fn refocus_batch<'py>(py: Python<'py>, gpu: Backend, a: BatchArgs<'_, 'py>) -> PyResult<Bound<'py, PyAny>> {
    let opts = options(&a)?;
    let frames = frames(a.frames)?;
    let out_dir = a.out_dir;
    let progress =
        crate::progress::Progress::new(a.augment.progress, crate::augment::frames_in_share(frames.len(), &opts))?;
    // Paths and options were copied out of Python above; see SameThread for why the move is sound.
    let work = SameThread((gpu, frames, out_dir, opts, progress));
    let result = py.detach(move || {
        let work = work;
        let (gpu, frames, out_dir, opts, progress) = work.0;
        let summary = run_batch(&gpu, &frames, &out_dir, &opts, || progress.advance());
        SameThread((summary, progress))
    });
    let (summary, progress) = result.0;
    progress.finish()?;
    let summary = summary.map_err(errors::from_library)?;
    let text = serde_json::to_string(&summary).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}
