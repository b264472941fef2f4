//! Batch refocus for dataset work, pipelined: a pool decodes frames, the GL thread uploads
//! each into the same textures and queues its targets, the previous frame's outputs are
//! mapped while the GPU renders the next, and a pool encodes files. Queues between the stages
//! are bounded, so memory stays flat (see [`BatchSummary::frames_in_flight`]). Resume skips
//! frames whose manifest records the same settings and whose files are all there; `--shard`
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

use super::job::{self, FileFormats, Manifest, TargetSpec};
use super::{BreakRule, Method, PendingRefocus, RefocusOutput, RefocusSource, Refocuser};
use crate::camera::Intrinsics;
use crate::convention::Conventions;
use crate::error::{Error, Result};
use crate::io::{self, DepthDecode};
use crate::pass::ToDevice;
use serde::{Deserialize, Serialize};
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Instant;

/// One frame of a batch manifest (a CSV row or a JSON object).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BatchFrame {
    /// Output folder name; when absent, the row index and the colour file's stem.
    #[serde(default)]
    pub name: Option<String>,
    /// Colour image path, relative to the manifest.
    pub rgb: PathBuf,
    /// Depth map path, relative to the manifest.
    pub depth: PathBuf,
    /// Focal length x of the source, pixels.
    pub fx: f64,
    /// Focal length y of the source, pixels.
    pub fy: f64,
    /// Principal point x of the source, pixels (OpenCV: pixel centres at integers).
    pub cx: f64,
    /// Principal point y of the source, pixels.
    pub cy: f64,
    /// Divisor from stored depth to metres (see [`DepthDecode`]); required for integer depth.
    #[serde(default)]
    pub depth_scale: Option<f64>,
    /// SUN RGB-D's bit rotation of 16-bit PNG depth.
    #[serde(default)]
    pub sun_bit_rotate: bool,
}

impl BatchFrame {
    fn intrinsics(&self) -> Intrinsics {
        Intrinsics {
            fx: self.fx,
            fy: self.fy,
            cx: self.cx,
            cy: self.cy,
        }
    }
}

/// Largest CSV manifest: about 10^6 rows of absolute paths.
pub const MAX_MANIFEST_BYTES: u64 = 256 << 20;
/// Largest JSON manifest (the JSON inputs' cap).
pub const MAX_JSON_MANIFEST_BYTES: u64 = crate::io::MAX_JSON_BYTES;
/// Largest CSV row: two paths of PATH_MAX and the numbers fit; a longer row is refused before
/// more of it is buffered.
pub const MAX_MANIFEST_ROW_BYTES: u64 = 16 << 10;
/// Most frames one manifest lists (each costs its paths and name in memory until rendered).
pub const MAX_MANIFEST_ROWS: usize = 1_000_000;
/// The csv reader's buffer: what it may read ahead of the row being parsed.
const CSV_BUFFER: usize = 8 << 10;

/// Read a CSV or JSON manifest; every frame gets a unique, filesystem-safe name. The file is
/// streamed (see the module notes): memory is bounded per row, never the file's size twice.
pub fn load_manifest(path: &Path) -> Result<Vec<BatchFrame>> {
    let json = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let most = if json {
        MAX_JSON_MANIFEST_BYTES
    } else {
        MAX_MANIFEST_BYTES
    };
    let (file, len) = crate::io::open_regular(path)?;
    crate::io::check_file_len(path, len, most, "a batch manifest")?;
    // Spreadsheets save CSV (and editors JSON) with a UTF-8 byte-order mark: skipped.
    let mut file = std::io::BufReader::with_capacity(CSV_BUFFER, file.take(most));
    if file
        .fill_buf()
        .map_err(|e| Error::io(path, e))?
        .starts_with(b"\xef\xbb\xbf")
    {
        file.consume(3);
    }
    let mut frames: Vec<BatchFrame> = if json {
        serde_json::from_reader(file).map_err(|e| Error::decode(path, e.to_string()))?
    } else {
        parse_csv(path, file)?
    };
    if frames.len() > MAX_MANIFEST_ROWS {
        return Err(Error::decode(
            path,
            format!("{} frames: at most {MAX_MANIFEST_ROWS} per manifest", frames.len()),
        ));
    }
    if frames.is_empty() {
        return Err(Error::decode(path, "the manifest lists no frame"));
    }
    let base = path.parent().unwrap_or(Path::new("."));
    let mut seen = std::collections::HashSet::new();
    for (i, f) in frames.iter_mut().enumerate() {
        for p in [&mut f.rgb, &mut f.depth] {
            if p.is_relative() {
                *p = base.join(&*p);
            }
        }
        let stem = f
            .rgb
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let name = f.name.clone().unwrap_or_else(|| format!("{i:05}_{stem}"));
        let safe: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        // A folder name: at most 255 bytes (NAME_MAX), so a huge cell is refused here, quoted short.
        if safe.is_empty() || safe.starts_with('.') || safe.len() > 255 || !seen.insert(safe.clone()) {
            return Err(Error::decode(
                path,
                format!(
                    "frame {i}: name '{}' is empty, hidden, longer than 255 bytes or repeated",
                    crate::error::excerpt(&name)
                ),
            ));
        }
        f.name = Some(safe);
    }
    Ok(frames)
}

/// One manifest row as the CSV gives it: columns found by header name (others ignored),
/// empty optional cells absent.
#[derive(Deserialize)]
struct CsvFrame {
    #[serde(default)]
    name: Option<String>,
    rgb: PathBuf,
    depth: PathBuf,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    #[serde(default)]
    depth_scale: Option<f64>,
    #[serde(default)]
    sun_bit_rotate: Option<String>,
}

/// A reader that refuses to read more than `limit` bytes from the start (the parser moves the
/// limit on after each row), so a row without an end is refused after a bounded read.
struct RowBound<R> {
    inner: R,
    read: u64,
    limit: std::rc::Rc<std::cell::Cell<u64>>,
}

/// The error [`RowBound`] reads as, found again by [`csv_error`].
const ROW_TOO_LONG: &str = "row too long";

impl<R: Read> Read for RowBound<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let allowed = self.limit.get().saturating_sub(self.read);
        if allowed == 0 {
            // At the limit: only the end of the file is fine.
            let mut probe = [0u8; 1];
            return match self.inner.read(&mut probe)? {
                0 => Ok(0),
                _ => Err(std::io::Error::other(ROW_TOO_LONG)),
            };
        }
        let n = buf.len().min(usize::try_from(allowed).unwrap_or(usize::MAX));
        let n = self.inner.read(&mut buf[..n])?;
        self.read += n as u64;
        Ok(n)
    }
}

fn parse_csv(path: &Path, file: impl Read) -> Result<Vec<BatchFrame>> {
    // The reader may buffer ahead of the row it parses; the row itself gets MAX_MANIFEST_ROW_BYTES.
    let slack = MAX_MANIFEST_ROW_BYTES + CSV_BUFFER as u64;
    let limit = std::rc::Rc::new(std::cell::Cell::new(slack));
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .buffer_capacity(CSV_BUFFER)
        .from_reader(RowBound {
            inner: file,
            read: 0,
            limit: limit.clone(),
        });
    let header = reader
        .headers()
        .map_err(|e| csv_error(path, &csv::StringRecord::new(), None, e))?
        .clone();
    if header.iter().all(str::is_empty) {
        return Err(Error::decode(path, "empty manifest"));
    }
    for r in ["rgb", "depth", "fx", "fy", "cx", "cy"] {
        if !header.iter().any(|c| c == r) {
            return Err(Error::decode(
                path,
                format!("header lacks column '{r}' (needs rgb,depth,fx,fy,cx,cy)"),
            ));
        }
    }
    let mut frames = Vec::new();
    // One record buffer for every row: a row is parsed into its frame, then the buffer reused.
    let mut record = csv::StringRecord::new();
    loop {
        limit.set(reader.position().byte() + slack);
        if !reader
            .read_record(&mut record)
            .map_err(|e| csv_error(path, &header, None, e))?
        {
            break;
        }
        if frames.len() == MAX_MANIFEST_ROWS {
            return Err(Error::decode(
                path,
                format!("more than {MAX_MANIFEST_ROWS} frames: split the manifest (--shard runs share one)"),
            ));
        }
        let row: CsvFrame = record
            .deserialize(Some(&header))
            .map_err(|e| csv_error(path, &header, Some(&record), e))?;
        frames.push(BatchFrame {
            name: row.name.filter(|s| !s.is_empty()),
            rgb: row.rgb,
            depth: row.depth,
            fx: row.fx,
            fy: row.fy,
            cx: row.cx,
            cy: row.cy,
            depth_scale: row.depth_scale,
            sun_bit_rotate: row
                .sun_bit_rotate
                .is_some_and(|v| v == "1" || v.eq_ignore_ascii_case("true")),
        });
    }
    Ok(frames)
}

/// The decode error of a manifest line: "line 3: 5 cells, header has 6" or
/// "line 2: cy = 'abc': invalid float literal".
fn csv_error(path: &Path, header: &csv::StringRecord, record: Option<&csv::StringRecord>, e: csv::Error) -> Error {
    let line = record
        .and_then(|r| r.position())
        .or(e.position())
        .map_or(String::new(), |p| format!("line {}: ", p.line()));
    let what = match e.kind() {
        csv::ErrorKind::Io(io) if io.to_string() == ROW_TOO_LONG => {
            format!("a row longer than {MAX_MANIFEST_ROW_BYTES} bytes (or a quote never closed)")
        }
        csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
            format!("{len} cells, header has {expected_len}")
        }
        csv::ErrorKind::Deserialize { err, .. } => match err.field().map(|i| i as usize) {
            Some(i) => format!(
                "{} = '{}': {}",
                header.get(i).unwrap_or("?"),
                record.and_then(|r| r.get(i)).unwrap_or(""),
                err.kind()
            ),
            None => err.kind().to_string(),
        },
        _ => e.to_string(),
    };
    Error::decode(path, format!("{line}{what}"))
}

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
    /// Focal scales of the targets: fx' = s fx.
    pub scales: Vec<f64>,
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
    /// Skip frames already finished with the same settings.
    pub resume: bool,
    /// Threads in each CPU pool (decode, encode); 0 runs every stage in turn on the GL thread
    /// (the synchronous baseline).
    pub jobs: usize,
    /// This process's share of the manifest; None renders every frame.
    pub shard: Option<Shard>,
}

/// Per-frame milliseconds of each stage, in completion order.
#[derive(Debug, Clone, Default, Serialize)]
pub struct StageTimes {
    /// Reading and decoding colour and depth (a decode thread).
    pub decode: Vec<f64>,
    /// Break rule, coverage flags and texture uploads (GL thread).
    pub upload: Vec<f64>,
    /// Recording the draws and queueing the reads of every target (GL thread).
    pub render: Vec<f64>,
    /// Waiting for the GPU and mapping the outputs (GL thread; a software renderer rasterises
    /// here).
    pub readback: Vec<f64>,
    /// Encoding and writing the files and the manifest (an encode thread).
    pub encode: Vec<f64>,
    /// GL thread idle: waiting for a decoded frame or for room in the encode queue.
    pub wait: Vec<f64>,
    /// GPU time of the draws (timer queries read after the fence) where the driver's timers
    /// are meaningful.
    pub gpu_render: Vec<f64>,
}

/// What a batch did, printed and written as JSON at the end.
#[derive(Debug, Clone, Default, Serialize)]
pub struct BatchSummary {
    /// Frames rendered and written.
    pub rendered: usize,
    /// Frames skipped because they were already finished with the same settings.
    pub skipped: usize,
    /// Frames outside this shard.
    pub other_shards: usize,
    /// (frame name, error) for every frame that failed; the others completed.
    pub failed: Vec<(String, String)>,
    /// Wall time of the whole batch, seconds.
    pub wall_s: f64,
    /// Per-frame times of each pipeline stage.
    pub stages: StageTimes,
    /// Most frames held in memory at once: decoded and queued, on the GL thread, mapped and
    /// queued for encoding, being encoded.
    pub frames_in_flight: usize,
}

struct WriteJob {
    name: String,
    /// The batch's --out-dir; the frame's folder is `name` inside it.
    root: io::OutDir,
    outputs: Vec<(f64, RefocusOutput)>,
    manifest: Manifest,
}

/// What a frame's manifest records of the settings that produced it: a rerun with anything
/// different (inputs changed on disk, other scales, outputs, formats, conventions) redoes it.
fn frame_settings(frame: &BatchFrame, opts: &BatchOptions) -> serde_json::Value {
    let stamp = |p: &Path| -> serde_json::Value {
        match std::fs::metadata(p) {
            Ok(m) => {
                let mtime = m
                    .modified()
                    .ok()
                    .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                    .map(|d| d.as_nanos().to_string());
                serde_json::json!({ "path": p.to_string_lossy(), "bytes": m.len(), "mtime_ns": mtime })
            }
            Err(_) => serde_json::json!({ "path": p.to_string_lossy() }),
        }
    };
    let mut settings = serde_json::json!({
        "rgb": stamp(&frame.rgb),
        "depth": stamp(&frame.depth),
        "intrinsics": [frame.fx, frame.fy, frame.cx, frame.cy],
        "depth_scale": frame.depth_scale,
        "sun_bit_rotate": frame.sun_bit_rotate,
        "scales": opts.scales,
        "size": opts.size,
        "principal": opts.principal,
        "break_rule": opts.rule,
        "method": opts.method,
        "conventions": opts.conv,
        "files": opts.files,
    });
    // Only when given, so batches made before the option resume.
    if let Some(m) = opts.depth_trunc {
        settings["depth_trunc"] = m.into();
    }
    settings
}

/// A frame is finished when its folder is a plain folder (not a symlink: it would resolve
/// outside --out-dir; writing it again refuses it by name), its manifest was written with the
/// same settings, and every file it lists is there, regular, with the size and CRC-32 it
/// recorded (files of another run under the same names, left by a kill, make it unfinished).
fn frame_finished(dir: &Path, settings: &serde_json::Value) -> bool {
    if !std::fs::symlink_metadata(dir).is_ok_and(|m| m.is_dir()) {
        return false;
    }
    // A set a killed run had journalled is finished first (rolled forward), so what is judged
    // is what the folder will hold.
    crate::io::remove_orphan_temporaries(dir);
    let path = dir.join(crate::io::MANIFEST_NAME);
    // A manifest is a few kB; anything far larger, or not a regular file, is not ours.
    if std::fs::symlink_metadata(&path).map_or(true, |m| !m.is_file() || m.len() > 16 << 20) {
        return false;
    }
    let Ok(text) = crate::io::read_text(&path, 16 << 20) else {
        return false;
    };
    let Ok(m) = serde_json::from_str::<serde_json::Value>(&text) else {
        return false;
    };
    if m.get("settings") != Some(settings) {
        return false;
    }
    let Some(files) = m.get("files").and_then(|f| f.as_array()) else {
        return false;
    };
    !files.is_empty()
        && files.iter().all(|f| {
            let (Some(name), Some(bytes), Some(crc)) = (
                f.get("name").and_then(|v| v.as_str()),
                f.get("bytes").and_then(|v| v.as_u64()),
                f.get("crc32").and_then(|v| v.as_u64()),
            ) else {
                return false;
            };
            // Names are ours (scale tags); refuse anything that would leave the folder.
            !name.contains('/')
                && !name.starts_with('.')
                && std::fs::symlink_metadata(dir.join(name)).is_ok_and(|m| m.is_file() && m.len() == bytes)
                && job::file_crc32(&dir.join(name)).is_ok_and(|c| u64::from(c) == crc)
        })
}

/// Write a frame's files as one all-or-none set: staged, then renamed into the frame's folder
/// (a plain folder inside --out-dir, never a symlink) with `manifest.json` last. A failure
/// leaves the previous run's files of this frame untouched.
fn write_frame(job: WriteJob, files: &FileFormats) -> Result<()> {
    let dir = job.root.subdir(&job.name)?;
    let mut set = dir.file_set()?;
    let mut manifest = job.manifest;
    for (scale, out) in &job.outputs {
        let entry = job::write_output(set.staging(), *scale, out, files).map_err(|e| set.final_error(e))?;
        manifest.outputs.push(entry);
    }
    manifest.files = job::file_records(set.staging(), &manifest.outputs)?;
    let path = set.final_path("manifest.json");
    let text = serde_json::to_string_pretty(&manifest).map_err(|e| Error::encode(&path, e.to_string()))?;
    // Written last and renamed last: its presence marks the frame finished for resume.
    set.write("manifest.json", |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| Error::io(&path, e))
    })?;
    set.commit()?;
    Ok(())
}

/// Read and validate one frame's inputs (errors name the frame's files).
fn decode_frame(frame: &BatchFrame, depth_trunc: Option<f64>) -> Result<RefocusSource> {
    let decode = DepthDecode {
        scale: frame.depth_scale,
        sun_rgbd_bit_rotate: frame.sun_bit_rotate,
        ..Default::default()
    };
    let mut depth = io::load_depth(&frame.depth, &decode)?;
    if let Some(m) = depth_trunc {
        io::truncate_depth(&mut depth, m)?;
    }
    RefocusSource::new(io::load_rgb(&frame.rgb)?, depth, frame.intrinsics())
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// A frame on the GL thread: uploaded, its targets queued.
struct InFlight {
    name: String,
    root: io::OutDir,
    scales: Vec<f64>,
    pending: Vec<PendingRefocus>,
    manifest: Manifest,
}

/// Upload a decoded frame and queue all its targets.
fn submit_frame(
    refocuser: &mut Refocuser,
    name: String,
    root: io::OutDir,
    src: &RefocusSource,
    settings: serde_json::Value,
    opts: &BatchOptions,
    stages: &mut StageTimes,
) -> Result<InFlight> {
    let t0 = Instant::now();
    let targets = TargetSpec {
        scales: opts.scales.clone(),
        size: opts.size,
        principal: opts.principal,
    }
    .targets(&src.camera())?;
    refocuser.set_source(src)?;
    stages.upload.push(ms_since(t0));
    let t0 = Instant::now();
    let pending = targets
        .iter()
        .map(|t| refocuser.submit(t))
        .collect::<Result<Vec<_>>>()?;
    stages.render.push(ms_since(t0));
    let manifest = Manifest {
        tool: format!("viewsynth {}", env!("CARGO_PKG_VERSION")),
        source: src.camera(),
        method: opts.method,
        break_rule: opts.rule,
        conventions: opts.conv,
        renderer: refocuser.renderer(),
        notes: job::MANIFEST_NOTES.to_string(),
        settings: Some(settings),
        files: Vec::new(),
        outputs: Vec::new(),
    };
    Ok(InFlight {
        name,
        root,
        scales: opts.scales.clone(),
        pending,
        manifest,
    })
}

/// Wait for a frame's outputs (the GPU is by now busy with the next frame).
fn collect_frame(f: InFlight, stages: &mut StageTimes) -> std::result::Result<WriteJob, (String, Error)> {
    let t0 = Instant::now();
    let mut outputs = Vec::with_capacity(f.pending.len());
    let mut gpu_ms = None;
    for (s, p) in f.scales.iter().zip(f.pending) {
        match p.wait() {
            Ok(o) => {
                if let Some(g) = o.render.gpu_ms {
                    *gpu_ms.get_or_insert(0.0) += g;
                }
                outputs.push((*s, o));
            }
            Err(e) => return Err((f.name, e)),
        }
    }
    stages.readback.push(ms_since(t0));
    if let Some(g) = gpu_ms {
        stages.gpu_render.push(g);
    }
    Ok(WriteJob {
        name: f.name,
        root: f.root,
        outputs,
        manifest: f.manifest,
    })
}

/// Run the batch. `progress` is called once per frame (rendered, skipped or failed).
pub fn run_batch(
    device: impl ToDevice,
    frames: &[BatchFrame],
    out_dir: &Path,
    opts: &BatchOptions,
    progress: impl Fn(),
) -> Result<BatchSummary> {
    if opts.scales.is_empty() {
        return Err(Error::param("scales", "no focal scale given"));
    }
    if let Some(m) = opts.depth_trunc {
        io::check_depth_trunc(m)?;
    }
    if opts.jobs > MAX_JOBS {
        return Err(Error::param(
            "jobs",
            format!("{} exceeds the limit of {MAX_JOBS}", opts.jobs),
        ));
    }
    opts.rule.validate()?;
    // Creates and checks --out-dir and clears temporaries that killed runs left in it.
    let root = io::OutDir::prepare(out_dir)?;
    let t_start = Instant::now();
    let mut summary = BatchSummary::default();
    // The frames this run renders: its shard, less those finished with the same settings. Only
    // the frame is kept (a reference); its name and settings are made again when it is rendered,
    // so a long manifest costs nothing more per row here.
    let mut todo: Vec<&BatchFrame> = Vec::new();
    for (i, frame) in frames.iter().enumerate() {
        if opts.shard.is_some_and(|s| i % s.count != s.index) {
            summary.other_shards += 1;
            continue;
        }
        let name = frame.name.as_deref().unwrap_or_default();
        if opts.resume && frame_finished(&out_dir.join(name), &frame_settings(frame, opts)) {
            summary.skipped += 1;
            progress();
            continue;
        }
        todo.push(frame);
    }
    let mut refocuser = Refocuser::with_settings(device, &opts.rule, opts.method, opts.files.outputs, opts.conv)?;
    let files = opts.files;
    let mut stages = StageTimes::default();

    if opts.jobs == 0 {
        // The synchronous baseline: each stage in turn on this thread.
        for frame in todo {
            let (name, settings) = (frame.name.clone().unwrap_or_default(), frame_settings(frame, opts));
            let t0 = Instant::now();
            let result = decode_frame(frame, opts.depth_trunc).and_then(|src| {
                stages.decode.push(ms_since(t0));
                submit_frame(
                    &mut refocuser,
                    name.clone(),
                    root.clone(),
                    &src,
                    settings,
                    opts,
                    &mut stages,
                )
            });
            let result = result
                .map_err(|e| (name.clone(), e))
                .and_then(|f| collect_frame(f, &mut stages));
            match result.and_then(|job| {
                let t0 = Instant::now();
                let r = write_frame(job, &files).map_err(|e| (name.clone(), e));
                stages.encode.push(ms_since(t0));
                r
            }) {
                Ok(()) => summary.rendered += 1,
                Err((n, e)) => summary.failed.push((n, e.to_string())),
            }
            progress();
        }
        summary.frames_in_flight = 1;
        summary.stages = stages;
        summary.wall_s = t_start.elapsed().as_secs_f64();
        return Ok(summary);
    }

    let jobs = opts.jobs;
    // Decoded frames waiting for the GL thread, and frames waiting for an encoder: `jobs` each.
    summary.frames_in_flight = jobs + 2 + 2 * jobs;
    let next = AtomicUsize::new(0);
    let depth_trunc = opts.depth_trunc;
    let (result_tx, result_rx) = mpsc::channel::<(String, Result<()>, f64)>();
    std::thread::scope(|scope| {
        let (decoded_tx, decoded_rx) = mpsc::sync_channel::<(usize, Result<RefocusSource>, f64)>(jobs);
        for _ in 0..jobs {
            let (tx, next, todo) = (decoded_tx.clone(), &next, &todo);
            scope.spawn(move || loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(frame) = todo.get(i) else { break };
                let t0 = Instant::now();
                let src = decode_frame(frame, depth_trunc);
                if tx.send((i, src, ms_since(t0))).is_err() {
                    break;
                }
            });
        }
        drop(decoded_tx);
        let (job_tx, job_rx) = mpsc::sync_channel::<WriteJob>(jobs);
        let job_rx = Arc::new(Mutex::new(job_rx));
        for _ in 0..jobs {
            let (rx, tx) = (job_rx.clone(), result_tx.clone());
            scope.spawn(move || loop {
                let next = rx.lock().map(|r| r.recv());
                let Ok(Ok(job)) = next else { break };
                let name = job.name.clone();
                let t0 = Instant::now();
                let r = write_frame(job, &files);
                let _ = tx.send((name, r, ms_since(t0)));
            });
        }
        let mut in_flight: Option<InFlight> = None;
        let send = |job: std::result::Result<WriteJob, (String, Error)>, stages: &mut StageTimes| match job {
            Ok(job) => {
                let t0 = Instant::now();
                if let Err(mpsc::SendError(job)) = job_tx.send(job) {
                    let _ = result_tx.send((job.name, Err(Error::param("batch", "encode threads stopped")), 0.0));
                }
                stages.wait.push(ms_since(t0));
            }
            Err((name, e)) => {
                let _ = result_tx.send((name, Err(e), 0.0));
            }
        };
        let mut handle = |(name, r, encode_ms): (String, Result<()>, f64), stages: &mut StageTimes| {
            match r {
                Ok(()) => {
                    summary.rendered += 1;
                    stages.encode.push(encode_ms);
                }
                Err(e) => summary.failed.push((name, e.to_string())),
            }
            progress();
        };
        loop {
            while let Ok(done) = result_rx.try_recv() {
                handle(done, &mut stages);
            }
            let t0 = Instant::now();
            let Ok((i, src, decode_ms)) = decoded_rx.recv() else {
                break;
            };
            stages.wait.push(ms_since(t0));
            let (name, settings) = (todo[i].name.clone().unwrap_or_default(), frame_settings(todo[i], opts));
            let submitted = src.and_then(|src| {
                stages.decode.push(decode_ms);
                submit_frame(
                    &mut refocuser,
                    name.clone(),
                    root.clone(),
                    &src,
                    settings,
                    opts,
                    &mut stages,
                )
            });
            // The GPU now works on this frame while the previous one is mapped and handed on.
            if let Some(prev) = in_flight.take() {
                let job = collect_frame(prev, &mut stages);
                send(job, &mut stages);
            }
            match submitted {
                Ok(f) => in_flight = Some(f),
                Err(e) => {
                    let _ = result_tx.send((name.clone(), Err(e), 0.0));
                }
            }
        }
        if let Some(prev) = in_flight.take() {
            let job = collect_frame(prev, &mut stages);
            send(job, &mut stages);
        }
        drop(job_tx);
        drop(result_tx);
        // The last results arrive while the encoders finish; progress counts each frame once.
        for done in result_rx.iter() {
            handle(done, &mut stages);
        }
    });
    summary.stages = stages;
    summary.wall_s = t_start.elapsed().as_secs_f64();
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_manifest_resolves_paths_and_names_frames() {
        let dir = std::env::temp_dir().join(format!("viewsynth-batch-manifest-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("frames.csv");
        std::fs::write(&p, "rgb,depth,fx,fy,cx,cy,depth_scale\n# comment\na.png,a.png,525,525,319.5,239.5,5000\n/abs/b.png,b.npy,500,500,320,240,\n").unwrap();
        let f = load_manifest(&p).unwrap();
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].rgb, dir.join("a.png"));
        assert_eq!(f[1].rgb, PathBuf::from("/abs/b.png"));
        assert_eq!((f[0].depth_scale, f[1].depth_scale), (Some(5000.0), None));
        assert_eq!(f[0].name.as_deref(), Some("00000_a"));
        std::fs::write(&p, "rgb,depth,fx,fy,cx\nx,y,1,2,3\n").unwrap();
        assert!(load_manifest(&p).unwrap_err().to_string().contains("'cy'"));
        std::fs::write(&p, "rgb,depth,fx,fy,cx,cy\nx,y,1,2,3,abc\n").unwrap();
        let e = load_manifest(&p).unwrap_err().to_string();
        assert!(e.contains("line 2: cy = 'abc'"), "{e}");
        std::fs::write(&p, "rgb,depth,fx,fy,cx,cy\nx,y,1,2,3\n").unwrap();
        let e = load_manifest(&p).unwrap_err().to_string();
        assert!(e.contains("line 2: 5 cells, header has 6"), "{e}");
        // Quoted cells may hold the delimiter; a blank line and a comment are skipped.
        std::fs::write(
            &p,
            "rgb,depth,fx,fy,cx,cy,sun_bit_rotate,extra\n\n# c\n\"a,1.png\", b.png ,1,2,3,4,true,z\n",
        )
        .unwrap();
        let f = load_manifest(&p).unwrap();
        assert_eq!(
            (f[0].rgb.clone(), f[0].depth.clone()),
            (dir.join("a,1.png"), dir.join("b.png"))
        );
        assert!(f[0].sun_bit_rotate && f[0].cy == 4.0);
        let j = dir.join("frames.json");
        std::fs::write(&j, r#"[{"name":"same","rgb":"a","depth":"b","fx":1,"fy":1,"cx":0,"cy":0},{"name":"same","rgb":"c","depth":"d","fx":1,"fy":1,"cx":0,"cy":0}]"#).unwrap();
        assert!(load_manifest(&j).unwrap_err().to_string().contains("repeated"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Rows of `n` frames made on the fly, counting the bytes the parser has taken.
    struct Rows {
        head: Vec<u8>,
        next: usize,
        n: usize,
        row: Vec<u8>,
        taken: std::rc::Rc<std::cell::Cell<u64>>,
        /// After the rows: one endless cell (no newline, no end).
        endless: bool,
    }

    impl Read for Rows {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            if self.row.is_empty() {
                if !self.head.is_empty() {
                    self.row = std::mem::take(&mut self.head);
                } else if self.next < self.n {
                    self.row = format!("r{0}.png,d{0}.npy,{0},2,3,4\n", self.next).into_bytes();
                    self.next += 1;
                } else if self.endless {
                    self.row = vec![b'a'; 4096];
                } else {
                    return Ok(0);
                }
            }
            let k = buf.len().min(self.row.len());
            buf[..k].copy_from_slice(&self.row[..k]);
            self.row.drain(..k);
            self.taken.set(self.taken.get() + k as u64);
            Ok(k)
        }
    }

    fn rows(n: usize, endless: bool) -> (Rows, std::rc::Rc<std::cell::Cell<u64>>) {
        let taken = std::rc::Rc::new(std::cell::Cell::new(0));
        let r = Rows {
            head: b"rgb,depth,fx,fy,cx,cy\n".to_vec(),
            next: 0,
            n,
            row: Vec::new(),
            taken: taken.clone(),
            endless,
        };
        (r, taken)
    }

    #[test]
    fn csv_rows_are_streamed_and_a_row_without_end_is_refused_after_a_bounded_read() {
        // 10^5 rows parsed from a stream, one at a time, each into its frame.
        let (r, taken) = rows(100_000, false);
        let f = parse_csv(Path::new("m.csv"), r).unwrap();
        assert_eq!(f.len(), 100_000);
        assert_eq!(
            (f[99_999].rgb.clone(), f[99_999].fx),
            (PathBuf::from("r99999.png"), 99_999.0)
        );
        assert!(taken.get() > 2_000_000, "{}", taken.get());
        // One endless row after 10 good ones: refused by its length, having read at most the
        // rows before it, one row's bound and the reader's buffer (twice: a refill in flight).
        let (r, taken) = rows(10, true);
        let e = parse_csv(Path::new("m.csv"), r).unwrap_err().to_string();
        assert!(
            e.contains(&format!("longer than {MAX_MANIFEST_ROW_BYTES} bytes")),
            "{e}"
        );
        let bound = 400 + MAX_MANIFEST_ROW_BYTES + 2 * CSV_BUFFER as u64;
        assert!(taken.get() <= bound, "read {} bytes, bound {bound}", taken.get());
        // A quote never closed is one endless row too.
        let (mut r, _) = rows(3, false);
        r.head = b"rgb,depth,fx,fy,cx,cy\n\"".to_vec();
        r.endless = true;
        let e = parse_csv(Path::new("m.csv"), r).unwrap_err().to_string();
        assert!(e.contains("longer than"), "{e}");
    }

    #[test]
    fn a_manifest_with_a_byte_order_mark_and_an_oversized_file_are_handled() {
        let dir = std::env::temp_dir().join(format!("viewsynth-batch-bom-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("frames.csv");
        std::fs::write(&p, "\u{feff}rgb,depth,fx,fy,cx,cy\na.png,a.npy,1,2,3,4\n").unwrap();
        assert_eq!(load_manifest(&p).unwrap()[0].cy, 4.0);
        let j = dir.join("frames.json");
        std::fs::write(
            &j,
            "\u{feff}[{\"rgb\":\"a\",\"depth\":\"b\",\"fx\":1,\"fy\":1,\"cx\":0,\"cy\":0}]",
        )
        .unwrap();
        assert_eq!(load_manifest(&j).unwrap().len(), 1);
        // Larger than the JSON cap: refused from its size, before a byte is parsed.
        let f = std::fs::File::create(&j).unwrap();
        f.set_len(MAX_JSON_MANIFEST_BYTES + 1).unwrap();
        let e = load_manifest(&j).unwrap_err().to_string();
        assert!(e.contains("frames.json"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
