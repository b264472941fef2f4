//! Dataset augmentation around `Renderer.refocus_batch`: `rgb_everywhere`, random zoom
//! (`zoom_random`, `samples`, `seed`: the CLI's `--zoom-random LO,HI --samples K --seed S`) and
//! `progress` (a callable, or True for a line on stderr), and `viewsynth.read_depth`: the depth
//! files the CLI writes (EXR, NPY, 16-bit PNG in millimetres) read back as float32 metres.

use crate::errors;
use pyo3::prelude::*;
use pyo3::types::PyBool;
use std::cell::{Cell, RefCell};
use std::path::PathBuf;
use viewsynth::io::DepthDecode;
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

enum Report {
    None,
    Stderr,
    Call(Py<PyAny>),
}

/// Progress of a batch: called once per frame on the thread that runs it (with the GIL
/// released, so a callable call takes it back for the call). The first exception a callable
/// raises is kept, later calls are skipped, and `finish` raises it once the batch is over (the
/// frames already written stay).
pub struct Progress {
    report: Report,
    total: usize,
    done: Cell<usize>,
    error: RefCell<Option<PyErr>>,
}

impl Progress {
    /// `progress=`: None or False (silent), True (stderr), or a callable `f(done, total)`.
    pub fn new(progress: Option<Bound<'_, PyAny>>, total: usize) -> PyResult<Self> {
        let report = match progress {
            None => Report::None,
            Some(p) if p.is_instance_of::<PyBool>() => match p.extract::<bool>()? {
                true => Report::Stderr,
                false => Report::None,
            },
            Some(p) if p.is_callable() => Report::Call(p.unbind()),
            Some(_) => {
                return Err(errors::invalid(
                    "progress",
                    "expected a callable f(done, total), True or None",
                ))
            }
        };
        Ok(Progress {
            report,
            total,
            done: Cell::new(0),
            error: RefCell::new(None),
        })
    }

    /// One more frame finished.
    pub fn advance(&self) {
        let done = self.done.get() + 1;
        self.done.set(done);
        match &self.report {
            Report::None => {}
            Report::Stderr => eprint!("\rrefocus_batch: {done}/{} frames", self.total),
            Report::Call(f) => {
                if self.error.borrow().is_some() {
                    return;
                }
                if let Err(e) = Python::attach(|py| f.call1(py, (done, self.total)).map(drop)) {
                    *self.error.borrow_mut() = Some(e);
                }
            }
        }
    }

    /// End the stderr line; raise what a callable raised.
    pub fn finish(self) -> PyResult<()> {
        if let Report::Stderr = self.report {
            eprintln!();
        }
        match self.error.into_inner() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// Read a depth file as the CLI writes it (or reads it): EXR, NPY, 16-bit PNG (millimetres,
/// or `depth_scale` raw units per metre), PFM, NPZ. Returns float32[H, W] view-space Z in
/// metres, 0 where invalid.
///
/// Raises FileError for a missing or unreadable file, InvalidInputError for a bad depth_scale.
#[pyfunction]
#[pyo3(signature = (path, *, depth_scale = None))]
pub fn read_depth<'py>(py: Python<'py>, path: PathBuf, depth_scale: Option<f64>) -> PyResult<Bound<'py, PyAny>> {
    let png16 = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    // The CLI's png16 output holds millimetres.
    let scale = depth_scale.or(png16.then_some(1000.0));
    let decode = DepthDecode {
        scale,
        ..Default::default()
    };
    let depth = py
        .detach(|| viewsynth::io::load_depth(&path, &decode))
        .map_err(errors::from_library)?;
    Ok(crate::arrays::depth_array(py, depth))
}
