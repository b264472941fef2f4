//! The dataset index: `index.jsonl` at the batch's out-dir root, one JSON row per target (frame,
//! scale, K', size, coverage, file paths relative to the out-dir), so a data loader reads one
//! file instead of walking every frame folder.
//!
//! Rows are made from the frames' own `manifest.json` files (the frames as they are on disk),
//! never from what a run meant to write. Each sharded run writes its part,
//! `index.part-K-of-N.jsonl` (K/N its shard): the rows of every frame of its share whose
//! manifest records this run's settings. Then, when all N parts of that N are there, it joins
//! them into `index.jsonl` (so the last shard to finish joins; `viewsynth index OUT` joins by
//! hand). A run without a shard writes `index.jsonl` alone: its part would be the whole index.
//! Parts and the index are written atomically.
//!
//! A run that rewrites frames removes what could list them ([`Invalidation`]): the joined
//! index, its own part and the parts of other shard counts, just before its first frame's set
//! is committed (never earlier: a run whose every frame fails leaves the index as it was). A
//! frame redone with other settings loses its previous files, so an index kept from an earlier
//! run would name files that are gone once such a run is killed. The parts of the other shards
//! of its own count stay: they list frames this run does not touch. The resumed run writes its
//! part again and joins. Only the index's exact names ([`super::index_names`]) are touched, and
//! only regular files.

use super::index_names::{parse_part_name, part_name, INDEX_NAME};
use super::resume::made_from;
use super::{BatchFrame, BatchOptions};
use crate::camera::Intrinsics;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Missing parts named at most in `viewsynth index`'s refusal (the rest are counted).
const MISSING_NAMED: usize = 8;

/// One target of one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IndexRow {
    /// The frame's name (its folder under the out-dir).
    pub frame: String,
    /// The frame's row in the batch manifest (0-based): the index's order.
    pub frame_index: usize,
    /// The target's place among the frame's targets.
    pub target: usize,
    /// Focal scale s: fx' = s fx.
    pub scale: f64,
    /// The target intrinsics K' (pixels, OpenCV centres).
    pub intrinsics: Intrinsics,
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Fraction of pixels with valid geometry (mask 1), when a mask or depth was written.
    pub coverage: Option<f64>,
    /// Colour file, relative to the out-dir.
    pub rgb: Option<String>,
    /// Depth file (the first of EXR, NPY, 16-bit PNG written), relative to the out-dir.
    pub depth: Option<String>,
    /// Raw units per metre of `depth` when it is the 16-bit PNG (metres = raw / this; pass it
    /// as `read_depth(..., depth_scale=)`); absent for float files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_scale: Option<f64>,
    /// Mask file, relative to the out-dir.
    pub mask: Option<String>,
    /// The frame's manifest, relative to the out-dir.
    pub manifest: String,
}

/// The rows of one finished frame: its manifest, when it was made from `frame` with `opts`.
fn frame_rows(
    root: &Path,
    name: &str,
    frame_index: usize,
    frame: &BatchFrame,
    opts: &BatchOptions,
) -> Option<Vec<IndexRow>> {
    let manifest_path = root.join(name).join(crate::io::MANIFEST_NAME);
    if std::fs::symlink_metadata(&manifest_path).map_or(true, |m| !m.is_file() || m.len() > 16 << 20) {
        return None;
    }
    let text = crate::io::read_text(&manifest_path, 16 << 20).ok()?;
    let m: serde_json::Value = serde_json::from_str(&text).ok()?;
    if !made_from(&m, frame, opts) {
        return None;
    }
    let rel = |v: &serde_json::Value| v.as_str().map(|f| format!("{name}/{f}"));
    let outputs = m.get("outputs")?.as_array()?;
    outputs
        .iter()
        .enumerate()
        .map(|(target, o)| {
            let depth_key = ["depth_exr", "depth_npy", "depth_png16"]
                .into_iter()
                .find(|k| o.get(*k).and_then(rel).is_some());
            let depth = depth_key.and_then(|k| o.get(k).and_then(rel));
            // Manifests from before the units were recorded wrote millimetres.
            let depth_scale = (depth_key == Some("depth_png16")).then(|| {
                o.get("depth_png16_units_per_metre")
                    .and_then(|u| u.as_f64())
                    .unwrap_or(crate::io::PNG16_UNITS_PER_METRE)
            });
            Some(IndexRow {
                frame: name.to_string(),
                frame_index,
                target,
                scale: o.get("scale")?.as_f64()?,
                intrinsics: serde_json::from_value(o.get("intrinsics")?.clone()).ok()?,
                width: o.get("width")?.as_u64()? as u32,
                height: o.get("height")?.as_u64()? as u32,
                coverage: o.get("coverage").and_then(|c| c.as_f64()),
                rgb: o.get("rgb").and_then(rel),
                depth,
                depth_scale,
                mask: o.get("mask").and_then(rel),
                manifest: format!("{name}/{}", crate::io::MANIFEST_NAME),
            })
        })
        .collect()
}

/// The rows of the manifest rows `take` picks, in manifest order.
fn rows_of(root: &Path, frames: &[BatchFrame], opts: &BatchOptions, take: impl Fn(usize) -> bool) -> Vec<IndexRow> {
    let mut rows = Vec::new();
    for (i, frame) in frames.iter().enumerate().filter(|(i, _)| take(*i)) {
        let name = frame.name.as_deref().unwrap_or_default();
        if let Some(r) = frame_rows(root, name, i, frame, opts) {
            rows.extend(r);
        }
    }
    rows
}

fn write_rows(path: &Path, rows: &[IndexRow]) -> Result<()> {
    crate::io::atomic_write(path, |w| {
        use std::io::Write;
        for r in rows {
            let line = serde_json::to_string(r).map_err(|e| Error::encode(path, e.to_string()))?;
            writeln!(w, "{line}").map_err(|e| Error::io(path, e))?;
        }
        Ok(())
    })
}

fn read_rows(path: &Path) -> Result<Vec<IndexRow>> {
    let text = crate::io::read_text(path, 1 << 30)?;
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .enumerate()
        .map(|(i, l)| serde_json::from_str(l).map_err(|e| Error::decode(path, format!("line {}: {e}", i + 1))))
        .collect()
}

/// Write this run's part (its share of `frames` as they are on disk under `root`) and, when
/// every part of its N is there, join them; returns the joined index's path if it joined. A
/// run without a shard writes the index itself, leaving no part.
pub fn write_part(root: &Path, frames: &[BatchFrame], opts: &BatchOptions) -> Result<Option<PathBuf>> {
    let Some(shard) = opts.shard else {
        let path = root.join(INDEX_NAME);
        write_rows(&path, &rows_of(root, frames, opts, |_| true))?;
        return Ok(Some(path));
    };
    let (k, n) = (shard.index, shard.count);
    let rows = rows_of(root, frames, opts, |i| i % n == k);
    write_rows(&root.join(part_name(k, n)), &rows)?;
    if (0..n).all(|j| root.join(part_name(j, n)).is_file()) {
        return join_parts(root, n).map(Some);
    }
    Ok(None)
}

/// The removal of the index files that could list a frame this run rewrites ([`invalidate`]),
/// done once, by whichever frame is committed first (encoders commit on several threads).
pub(super) struct Invalidation<'a> {
    root: &'a Path,
    opts: &'a BatchOptions,
    done: std::sync::Mutex<bool>,
}

impl<'a> Invalidation<'a> {
    pub(super) fn new(root: &'a Path, opts: &'a BatchOptions) -> Self {
        Invalidation {
            root,
            opts,
            done: std::sync::Mutex::new(false),
        }
    }

    /// Called with a frame's set staged, before its commit: the first call removes the files.
    pub(super) fn before_commit(&self) -> Result<()> {
        let mut done = self.done.lock().unwrap_or_else(|e| e.into_inner());
        if !*done {
            invalidate(self.root, self.opts)?;
            *done = true;
        }
        Ok(())
    }

    /// Whether the index files were removed (a frame was committed, or about to be).
    pub(super) fn happened(&self) -> bool {
        *self.done.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Before a run replaces any frame: remove `index.jsonl`, this run's part (K/N its shard, 0/1
/// unsharded) and every part of another shard count, which may list the frames it rewrites. Done
/// before the first frame is committed, so a run killed at any point leaves no row naming a file
/// it replaced; the parts of the other shards of N list only their own frames and stay.
fn invalidate(root: &Path, opts: &BatchOptions) -> Result<()> {
    let (k, n) = opts.shard.map_or((0, 1), |s| (s.index, s.count));
    let entries = std::fs::read_dir(root).map_err(|e| Error::io(root, e))?;
    for e in entries {
        let e = e.map_err(|e| Error::io(root, e))?;
        let name = e.file_name().to_string_lossy().to_string();
        let stale = match parse_part_name(&name) {
            Some((j, m)) => m != n || j == k,
            None => name == INDEX_NAME,
        };
        if stale {
            remove(&e.path())?;
        }
    }
    Ok(())
}

/// Remove one index file, if a regular file (gone already is fine: another shard may have
/// removed it).
fn remove(path: &Path) -> Result<()> {
    crate::io::remove_own_file(path).map_err(|e| Error::io(path, e))
}

/// Write `index.jsonl` over the whole of `frames` (the full manifest, shards ignored) as they
/// are on disk under `root`, for callers that rendered the manifest in subsets of their own
/// choosing with [`BatchOptions::index`] off. Returns its path and row count.
pub fn write_index(root: &Path, frames: &[BatchFrame], opts: &BatchOptions) -> Result<(PathBuf, usize)> {
    let rows = rows_of(root, frames, opts, |_| true);
    let path = root.join(INDEX_NAME);
    write_rows(&path, &rows)?;
    Ok((path, rows.len()))
}

/// Join the N parts under `root` into `index.jsonl` (rows by manifest row, then target).
fn join_parts(root: &Path, n: usize) -> Result<PathBuf> {
    let mut rows = Vec::new();
    for j in 0..n {
        rows.extend(read_rows(&root.join(part_name(j, n)))?);
    }
    rows.sort_by_key(|r| (r.frame_index, r.target));
    let path = root.join(INDEX_NAME);
    write_rows(&path, &rows)?;
    Ok(path)
}

/// `viewsynth index OUT`: join the parts a batch's runs left under `root`. Where parts of
/// several shard counts are there, the count whose newest part is newest; an incomplete set
/// is an error naming the missing parts.
pub fn join_index(root: &Path) -> Result<(PathBuf, usize)> {
    let entries = std::fs::read_dir(root).map_err(|e| Error::io(root, e))?;
    // Per shard count N: the parts found and the newest modification time.
    let mut counts: std::collections::BTreeMap<usize, (Vec<usize>, std::time::SystemTime)> = Default::default();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        let Some((k, n)) = parse_part_name(&name) else { continue };
        let modified = e.metadata().and_then(|m| m.modified()).unwrap_or(std::time::UNIX_EPOCH);
        let entry = counts.entry(n).or_insert((Vec::new(), std::time::UNIX_EPOCH));
        entry.0.push(k);
        entry.1 = entry.1.max(modified);
    }
    let Some((&n, (found, _))) = counts.iter().max_by_key(|(_, (_, t))| *t) else {
        // An unsharded run writes the index itself, with no part: nothing to join.
        let index = root.join(INDEX_NAME);
        if index.is_file() {
            let rows = read_rows(&index)?.len();
            return Ok((index, rows));
        }
        return Err(Error::param(
            "index",
            format!(
                "{}: no index part (index.part-K-of-N.jsonl); run refocus --batch into it first",
                root.display()
            ),
        ));
    };
    // N comes from a file name: the missing parts are counted, and only the first few named,
    // so that `--shard 0/100000000` costs no list of a hundred million names.
    let found: std::collections::BTreeSet<usize> = found.iter().copied().collect();
    let missing = n - found.len();
    if missing > 0 {
        let first: Vec<String> = (0..n)
            .filter(|j| !found.contains(j))
            .take(MISSING_NAMED)
            .map(|j| part_name(j, n))
            .collect();
        let more = match missing - first.len() {
            0 => String::new(),
            rest => format!(" and {rest} more"),
        };
        return Err(Error::param(
            "index",
            format!(
                "{}: shards still to run: {missing} of {n} parts missing ({}{more})",
                root.display(),
                first.join(", ")
            ),
        ));
    }
    let path = join_parts(root, n)?;
    let rows = read_rows(&path)?.len();
    Ok((path, rows))
}

/// Read `index.jsonl` (or a part).
pub fn read_index(path: &Path) -> Result<Vec<IndexRow>> {
    read_rows(path)
}
