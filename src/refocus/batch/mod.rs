//! Batch refocus for dataset work, pipelined: a pool decodes frames, the GL thread uploads
//! each into the same textures and queues its targets, the previous frame's outputs are
//! mapped while the GPU renders the next, and a pool encodes files. Queues between the stages
//! are bounded, so memory stays flat (see [`BatchSummary::frames_in_flight`]). Resume skips
//! frames whose manifest records the same settings and the same inputs (by identity, whatever
//! the path's spelling: see [`resume`]) and whose files are all there; `--shard`
//! takes a deterministic share of the manifest. A failed frame is listed while the others
//! complete.
//!
//! Manifest: CSV with a header naming the columns `rgb,depth,fx,fy,cx,cy` and optionally
//! `depth_scale`, `name`, `sun_bit_rotate` (read by the `csv` crate: quoted cells may hold
//! commas, `#` starts a comment line), or a JSON array of objects with the same fields. Relative paths are relative to the manifest.
//! Both are streamed from the file, never read whole: a CSV row is parsed into its frame one at
//! a time, at most [`MAX_MANIFEST_ROW_BYTES`] each, and a frame costs its paths and name until
//! it is rendered (the settings a resume compares are computed when they are needed).
//! Each frame writes into `<out>/<name>/`; its `manifest.json` is written last, atomically, and
//! marks the frame finished.
//!
//! The parts: [`manifest`] reads the frame list, [`resume`] decides which frames are finished,
//! [`pipeline`] runs the stages; [`tum`] makes a manifest from a TUM-style sequence's listings.

mod index;
mod index_names;
mod manifest;
mod pipeline;
mod resume;
mod tum;
mod zoom;

pub use index::{join_index, read_index, write_index, IndexRow};
pub use index_names::{is_index_name, INDEX_NAME};
pub use manifest::{
    frame_folder_name, is_frame_folder_name, load_manifest, load_manifest_with_defaults, BatchFrame,
    MAX_JSON_MANIFEST_BYTES, MAX_MANIFEST_BYTES, MAX_MANIFEST_ROWS, MAX_MANIFEST_ROW_BYTES,
};
pub use pipeline::{run_batch, BatchSummary, StageTimes};
pub use tum::{
    associate_tum, write_manifest_csv, TumAssociation, MAX_LISTING_BYTES, TUM_DEPTH_SCALE, TUM_MAX_DIFFERENCE,
};
pub use zoom::{ZoomRandom, MAX_SAMPLES};

use super::{BreakRule, Method};
use crate::convention::Conventions;
use crate::error::{Error, Result};
use crate::output::FileFormats;
use serde::Serialize;

/// Most threads either pool may have: each holds a frame in memory (VGA x 5 scales: 14 MB),
/// and beyond the cores a pool only adds frames in flight.
pub const MAX_JOBS: usize = 64;

/// A deterministic share of a manifest: frames whose index i has i % count == index.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Shard {
    /// 0-based (a Kubernetes indexed Job's JOB_COMPLETION_INDEX; a Slurm array from 0).
    pub index: usize,
    /// Number of shards, at least 1.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = Error;
    /// "K/N" with 0 <= K < N.
    fn from_str(s: &str) -> Result<Self> {
        let bad = || Error::param("shard", format!("'{s}': expected K/N with 0 <= K < N, e.g. 0/4"));
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        if k.trim().is_empty() || n.trim().is_empty() {
            // "/" or "3/" is what `--shard "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT"` gives
            // outside an array job: say so rather than only that the value is malformed.
            return Err(Error::param(
                "shard",
                format!(
                    "'{s}': K or N is empty (expected K/N with 0 <= K < N, e.g. 0/4); a variable \
                     it was built from is unset or empty, e.g. SLURM_ARRAY_TASK_ID / \
                     SLURM_ARRAY_TASK_COUNT outside a Slurm array job, or JOB_COMPLETION_INDEX \
                     outside a Kubernetes indexed Job"
                ),
            ));
        }
        let (index, count): (usize, usize) = (
            k.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

/// Everything a batch applies to each frame.
#[derive(Debug, Clone)]
pub struct BatchOptions {
    /// Focal scales of the targets: fx' = s fx (every frame; unused with `zoom_random`).
    pub scales: Vec<f64>,
    /// Random scales per frame instead of `scales` (`--zoom-random`).
    pub zoom_random: Option<ZoomRandom>,
    /// Colour every pixel inside the source frame (`--rgb-everywhere`).
    pub rgb_everywhere: bool,
    /// Output size (width, height) in pixels; None keeps each source's size.
    pub size: Option<(u32, u32)>,
    /// Output principal point, pixels; None keeps the source's offset from the image centre.
    pub principal: Option<(f64, f64)>,
    /// Depth-break rule that decides which source triangles are kept.
    pub rule: BreakRule,
    /// Refocus method (fullscreen or mesh).
    pub method: Method,
    /// NDC depth range, reversed-Z and row order of the rendering.
    pub conv: Conventions,
    /// What files each target produces and how they are encoded.
    pub files: FileFormats,
    /// Input depth beyond this many metres is treated as invalid (Open3D's depth_trunc).
    pub depth_trunc: Option<f64>,
    /// Skip frames already finished from the same inputs with the same settings.
    pub resume: bool,
    /// With `resume`: also check each finished file's CRC-32 and each input's content (by
    /// default a done frame costs its manifest read and a few `stat`s).
    pub verify: bool,
    /// Threads in each CPU pool (decode, encode); 0 runs every stage in turn on the GL thread
    /// (the synchronous baseline).
    pub jobs: usize,
    /// This process's share of the manifest; None renders every frame.
    pub shard: Option<Shard>,
    /// Write this run's index part and join the parts when all are there (the CLI always
    /// does). Off for a caller that hands each run an arbitrary subset of the manifest (Ray,
    /// Dask), which then writes the index once over the whole manifest with [`write_index`].
    pub index: bool,
}

impl BatchOptions {
    /// The frame's focal scales and their file tags: the fixed list (`s{s}`), or its random
    /// draw (`z{k}_s{s}`).
    pub fn frame_targets(&self, frame: &str) -> (Vec<f64>, Vec<String>) {
        match &self.zoom_random {
            Some(z) => {
                let scales = z.scales(frame);
                let tags = ZoomRandom::tags(&scales);
                (scales, tags)
            }
            None => (
                self.scales.clone(),
                self.scales.iter().map(|&s| super::manifest::scale_tag(s)).collect(),
            ),
        }
    }
}
