//! Dataset augmentation around `Renderer.refocus_batch`: `rgb_everywhere`, random zoom
//! (`zoom_random`, `samples`, `seed`: the CLI's `--zoom-random LO,HI --samples K --seed S`) and
//! `progress` (progress.rs), and `viewsynth.read_depth`: the depth files the CLI writes or
//! reads, as float32 metres under the library's rules.

use crate::errors;
use pyo3::prelude::*;
use std::path::PathBuf;
use viewsynth::job::{ArgError, DepthFileRequest};
use viewsynth::refocus::batch::BatchOptions;

/// The augmentation keyword arguments of one `refocus_batch` call.
pub struct Augment<'py> {
    pub rgb_everywhere: bool,
    pub zoom_random: Option<(f64, f64)>,
    pub samples: Option<usize>,
    pub seed: Option<u64>,
    pub progress: Option<Bound<'py, PyAny>>,
}

/// Frames of `total` this run's shard takes (progress counts each once: rendered, skipped or
/// failed).
pub fn frames_in_share(total: usize, opts: &BatchOptions) -> usize {
    match opts.shard {
        Some(s) => (0..total).filter(|i| i % s.count == s.index).count(),
        None => total,
    }
}

/// Read a depth file as the CLI writes it (or reads it): EXR, NPY, NPZ, PFM, 16-bit PNG/PGM.
/// Returns float32[H, W] view-space Z in metres, 0 where invalid. The library's rule, as the
/// CLI's inputs: integer samples need `depth_scale` (raw units per metre; the CLI's png16
/// output records its own in manifest.json and index.jsonl), device depth needs the `near` and
/// `far` planes it was written with.
///
/// Raises FileError for a missing or unreadable file, InvalidInputError for integer depth
/// without depth_scale, a bad depth_scale, or device depth without its planes.
#[pyfunction]
#[pyo3(signature = (path, *, depth_scale = None, depth_kind = "view-z", near = None, far = None))]
pub fn read_depth<'py>(
    py: Python<'py>,
    path: PathBuf,
    depth_scale: Option<f64>,
    depth_kind: &str,
    near: Option<f64>,
    far: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let reading = DepthFileRequest {
        depth_scale,
        depth_kind: crate::shared::choice(viewsynth::Field::DepthKind, depth_kind)?,
        near,
        far,
    }
    .check()
    .map_err(errors::from_request)?;
    let depth = py.detach(|| reading.read(&path)).map_err(|e| match e {
        // A missing scale is a bad argument, worded with the keyword: the library names the
        // parameter in its own words (`depth-scale`), which are the request field's key
        // (`depth_scale`) with dashes.
        viewsynth::Error::InvalidParameter { name, message } => {
            let key = name.to_string().replace('-', "_");
            match viewsynth::Field::ALL.iter().find(|f| f.key() == key) {
                Some(&field) => errors::from_request(ArgError::Invalid(viewsynth::Error::param(field, message))),
                None => errors::from_library(viewsynth::Error::InvalidParameter { name, message }),
            }
        }
        e => errors::from_library(e),
    })?;
    Ok(crate::arrays::depth_array(py, depth))
}
