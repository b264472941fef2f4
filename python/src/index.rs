//! `viewsynth.write_index`: the dataset index over a whole manifest, for pipelines that hand
//! each worker a share of it (`Renderer.refocus_batch(..., index=False)` per share), so
//! `out_dir/index.jsonl` equals the CLI batch's. No GPU: the rows come from the frames' own
//! manifests on disk, kept only where they record these settings. `viewsynth.read_index` reads
//! the index through the library's reader (`_index_rows`).

use crate::batch::{options, BatchArgs};
use crate::errors;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Write out_dir/index.jsonl over every frame of `frames` (a manifest path or frame dicts, the
/// whole manifest in its order) as refocus_batch left them: a frame whose folder was not
/// written with these settings (failed, not yet rendered, or made with other settings) has no
/// rows. The settings are refocus_batch's keywords of the same names and must be the ones the
/// frames were rendered with. Returns (path, rows).
// The keyword list is refocus_batch's settings (python/src/batch.rs), written again because
// pyo3 takes a signature only as a literal; test_refocus_batch.py holds the two equal.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (frames, out_dir, *, scales = None, size = None, principal = None,
                    outputs = None, tau_rel = 0.05, tau_abs = 0.2, method = "fullscreen", rgb_format = "png",
                    depth_format = None, depth_png_scale = None, depth_preview = false, png_compression = "fast",
                    exr_compression = "zip", depth_trunc = None, rgb_everywhere = false, zoom_random = None,
                    samples = None, seed = None))]
pub fn write_index<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    out_dir: PathBuf,
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
    rgb_everywhere: bool,
    zoom_random: Option<(f64, f64)>,
    samples: Option<usize>,
    seed: Option<u64>,
) -> PyResult<(String, usize)> {
    let args = BatchArgs {
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
        resume: true,
        verify: false,
        jobs: None,
        shard: None,
        index: true,
        augment: crate::augment::Augment {
            rgb_everywhere,
            zoom_random,
            samples,
            seed,
            progress: None,
        },
    };
    let opts = options(&args)?;
    let frames = crate::batch::frames(args.frames)?;
    let root = args.out_dir;
    let (path, rows) = py
        .detach(|| viewsynth::refocus::batch::write_index(&root, &frames, &opts))
        .map_err(errors::from_library)?;
    Ok((path.to_string_lossy().into_owned(), rows))
}

/// The rows of out_dir/index.jsonl, each as its JSON text, for `viewsynth.read_index`: read by
/// the library's rules (a regular file, never a FIFO or device, of bounded size, UTF-8, each
/// line a row), so its errors are the library's (FileError).
#[pyfunction]
pub fn _index_rows(py: Python<'_>, out_dir: PathBuf) -> PyResult<Vec<String>> {
    let path = out_dir.join(viewsynth::refocus::batch::INDEX_NAME);
    let rows = py
        .detach(|| viewsynth::refocus::batch::read_index(&path))
        .map_err(errors::from_library)?;
    rows.iter()
        .map(|row| {
            serde_json::to_string(row).map_err(|e| errors::from_library(viewsynth::Error::decode(&path, e.to_string())))
        })
        .collect()
}
