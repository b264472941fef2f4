//! Python bindings of the viewsynth library (not the CLI): numpy arrays in, numpy arrays out.
//! The package `viewsynth` (python/viewsynth/) re-exports this module `viewsynth._viewsynth`.
//! `renderer`: the class `Renderer`, its context and lifetime. Each capability's module holds its
//! method (a `#[pymethods]` block of its own, pyo3's `multiple-pymethods`) and its work; arrays in
//! memory: `refocus`, `cyclopean`, `reproject`, `stitch`; files in and out (the CLI batch's
//! writers): `batch`.

mod arrays;
mod augment;
mod backend;
mod batch;
mod context;
mod cyclopean;
mod errors;
mod index;
mod ints;
mod progress;
mod refocus;
mod renderer;
mod reproject;
mod shared;
mod stack;
mod stitch;
mod thread_bound;

use pyo3::prelude::*;
use viewsynth::gpu::GpuInfo;

/// GpuInfo as a plain dict (through its serde form, so new fields appear without a change here;
/// "software" is the library's own `GpuInfo.software`, the only software check).
pub(crate) fn info_dict<'py>(py: Python<'py>, info: &GpuInfo) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(info).map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Describe the EGL/OpenGL context viewsynth renders with (opening one, or reusing this thread's):
/// vendor, renderer, GL and EGL versions, platform, device index and count, limits, whether GPU
/// timers are meaningful, "software" (True on llvmpipe) and "viewsynth_version".
#[pyfunction]
#[pyo3(signature = (device = "auto"))]
fn info<'py>(py: Python<'py>, device: &str) -> PyResult<Bound<'py, PyAny>> {
    let gpu = context::acquire(context::parse_device(device)?)?;
    let dict = info_dict(py, gpu.info());
    context::release(gpu);
    let dict = dict?;
    dict.set_item("viewsynth_version", env!("CARGO_PKG_VERSION"))?;
    Ok(dict)
}

/// The library's request for `command` at its defaults, as JSON text (None for a command with
/// none): what tests/test_front_ends.py holds each keyword argument's default to.
#[pyfunction]
fn _request_defaults(command: &str) -> Option<String> {
    viewsynth::job::request_defaults(command).map(|v| v.to_string())
}

/// The keyword argument error messages name for a CLI option (`--tau-rel` -> "tau_rel"): the
/// library's field table, which spells each field both ways (None for an option it lacks).
#[pyfunction]
fn _keyword(option: &str) -> Option<&'static str> {
    viewsynth::Field::ALL
        .iter()
        .find(|f| f.cli() == option)
        .map(|f| f.python())
}

#[pymodule]
fn _viewsynth(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<renderer::Renderer>()?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(batch::load_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(augment::read_depth, m)?)?;
    m.add_function(wrap_pyfunction!(index::write_index, m)?)?;
    m.add_function(wrap_pyfunction!(index::_index_rows, m)?)?;
    m.add_function(wrap_pyfunction!(_request_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(_keyword, m)?)?;
    m.add("_REQUEST_COMMANDS", viewsynth::job::REQUEST_COMMANDS.to_vec())?;
    m.add(
        "FACE_ORDER",
        pyo3::types::PyTuple::new(m.py(), viewsynth::stitch::faces::FACE_TAGS)?,
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
