//! The pipelined batch: decode pool -> GL thread (upload, queue the targets, map the previous
//! frame's outputs) -> encode pool, with bounded queues; or every stage in turn on one thread
//! (`jobs` = 0, the synchronous baseline).

use super::index::Invalidation;
use super::resume::{frame_finished, frame_inputs, frame_settings};
use super::{BatchFrame, BatchOptions, MAX_JOBS};
use crate::error::{Error, Result};
use crate::io::{self, DepthDecode};
use crate::output::FileFormats;
use crate::pass::ToDevice;
use crate::refocus::manifest::{self, Manifest, TargetSpec};
use crate::refocus::{PendingRefocus, RefocusOutput, RefocusSource, Refocuser};
use serde::Serialize;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Instant;

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
    /// Process CPU ms of decode, synchronous batch only (nothing else runs then, so the
    /// process's clock is the stage's own, pool threads included); empty when pipelined.
    pub decode_cpu: Vec<f64>,
    /// Process CPU ms of encode, as `decode_cpu`.
    pub encode_cpu: Vec<f64>,
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
    /// (frame name, warning) for every sign of a wrongly decoded depth map (the single-frame
    /// command's input checks: a wrong depth_scale, disparity read as metres, ...), in manifest
    /// order, each frame's once.
    pub depth_warnings: Vec<(String, String)>,
    /// Wall time of the whole batch, seconds.
    pub wall_s: f64,
    /// Per-frame times of each pipeline stage.
    pub stages: StageTimes,
    /// Most frames held in memory at once: decoded and queued, on the GL thread, mapped and
    /// queued for encoding, being encoded.
    pub frames_in_flight: usize,
    /// `index.jsonl`, when this run joined it (it was the last of its shards, or unsharded).
    pub index: Option<std::path::PathBuf>,
}

struct WriteJob {
    name: String,
    /// The batch's --out-dir; the frame's folder is `name` inside it.
    root: io::OutDir,
    /// (file tag, scale, outputs) per target.
    outputs: Vec<(String, f64, RefocusOutput)>,
    manifest: Manifest,
}

/// Write a frame's files as one all-or-none set: staged, then renamed into the frame's folder
/// (a plain folder inside --out-dir, never a symlink) with `manifest.json` last. A failure
/// leaves the previous run's files of this frame untouched.
fn write_frame(job: WriteJob, files: &FileFormats, index: &Invalidation<'_>) -> Result<()> {
    let dir = job.root.subdir(&job.name)?;
    // A frame redone (other settings: fewer scales, other outputs) leaves only its new set.
    let set = dir.file_set()?.replacing(manifest::replaced());
    let targets = job.outputs.into_iter().map(Ok);
    manifest::write_frame(set, job.manifest, targets, files, || {}, || index.before_commit())?;
    Ok(())
}

/// Each frame's depth warnings as (index in the frames rendered, name, warning).
type Warnings = Mutex<Vec<(usize, String, String)>>;

/// Read and validate one frame's inputs (errors name the frame's files); the decoded depth is
/// checked as the single-frame command checks it, its warnings added to `warnings`.
fn decode_frame(frame: &BatchFrame, i: usize, depth_trunc: Option<f64>, warnings: &Warnings) -> Result<RefocusSource> {
    let decode = DepthDecode {
        scale: frame.depth_scale,
        sun_rgbd_bit_rotate: frame.sun_bit_rotate,
        ..Default::default()
    };
    let mut depth = io::load_depth(&frame.depth, &decode)?;
    let found = io::DepthSummary::of(&depth).warnings();
    if !found.is_empty() {
        let name = frame.name.clone().unwrap_or_default();
        let mut w = warnings.lock().unwrap_or_else(|e| e.into_inner());
        w.extend(found.into_iter().map(|f| (i, name.clone(), f.to_string())));
    }
    if let Some(m) = depth_trunc {
        io::truncate_depth(&mut depth, m)?;
    }
    RefocusSource::new(io::load_rgb(&frame.rgb)?, depth, frame.intrinsics())
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn cpu_ms_since(c0: Option<f64>) -> Option<f64> {
    Some(crate::cpu_time::process_cpu_ms()? - c0?)
}

/// A frame on the GL thread: uploaded, its targets queued.
struct InFlight {
    name: String,
    root: io::OutDir,
    scales: Vec<f64>,
    tags: Vec<String>,
    pending: Vec<PendingRefocus>,
    manifest: Manifest,
}

/// A frame's inputs' identities (colour, depth), as the manifest records them.
type Inputs = [serde_json::Value; 2];

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
    let (scales, tags) = opts.frame_targets(&name);
    let targets = TargetSpec {
        scales: scales.clone(),
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
    let manifest = Manifest::of_frame(
        src.camera(),
        opts.method,
        opts.rule,
        opts.conv,
        refocuser.renderer(),
        opts.rgb_everywhere,
        Some(settings),
    );
    Ok(InFlight {
        name,
        root,
        scales,
        tags,
        pending,
        manifest,
    })
}

/// Wait for a frame's outputs (the GPU is by now busy with the next frame).
fn collect_frame(f: InFlight, stages: &mut StageTimes) -> std::result::Result<WriteJob, (String, Error)> {
    let t0 = Instant::now();
    let mut outputs = Vec::with_capacity(f.pending.len());
    let mut gpu_ms = None;
    for ((s, tag), p) in f.scales.iter().zip(f.tags).zip(f.pending) {
        match p.wait() {
            Ok(o) => {
                if let Some(g) = o.render.gpu_ms {
                    *gpu_ms.get_or_insert(0.0) += g;
                }
                outputs.push((tag, *s, o));
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
    if opts.scales.is_empty() && opts.zoom_random.is_none() {
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
    if let Some(s) = opts.shard.filter(|s| s.count > frames.len().max(1)) {
        // Shards K >= the frame count would have nothing to do, yet the index waits for every
        // part of N: refused before any folder or part is written.
        return Err(Error::param(
            "shard",
            format!(
                "{}/{}: the manifest lists {} frames, so shards {}..{} would have none; give N <= {}",
                s.index,
                s.count,
                frames.len(),
                frames.len(),
                s.count - 1,
                frames.len().max(1)
            ),
        ));
    }
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
        if opts.resume && frame_finished(&out_dir.join(name), frame, opts) {
            summary.skipped += 1;
            progress();
            continue;
        }
        todo.push(frame);
    }
    // Whatever could list a frame this run rewrites goes just before the first frame is
    // committed (the end of the run writes the index again); a run whose frames all fail
    // removes nothing.
    let invalidation = Invalidation::new(root.real_path(), opts);
    // The index is written again unless every frame this run tried failed before its commit:
    // then the folder stays as it was, index included.
    let index_again = |summary: &BatchSummary| opts.index && (summary.failed.is_empty() || invalidation.happened());
    let mut refocuser = Refocuser::with_settings(device, &opts.rule, opts.method, opts.files.outputs, opts.conv)?;
    refocuser.set_rgb_everywhere(opts.rgb_everywhere);
    let files = opts.files;
    let mut stages = StageTimes::default();
    let warnings = Warnings::default();
    let warned = |summary: &mut BatchSummary, warnings: Warnings| {
        let mut w = warnings.into_inner().unwrap_or_else(|e| e.into_inner());
        w.sort_by_key(|(i, _, _)| *i);
        summary.depth_warnings = w.into_iter().map(|(_, name, text)| (name, text)).collect();
    };

    if opts.jobs == 0 {
        // The synchronous baseline: each stage in turn on this thread.
        for (i, frame) in todo.iter().enumerate() {
            let name = frame.name.clone().unwrap_or_default();
            let (t0, c0) = (Instant::now(), crate::cpu_time::process_cpu_ms());
            let result = decode_frame(frame, i, opts.depth_trunc, &warnings).and_then(|src| {
                let settings = frame_settings(frame, opts, frame_inputs(frame));
                stages.decode.push(ms_since(t0));
                stages.decode_cpu.extend(cpu_ms_since(c0));
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
                let (t0, c0) = (Instant::now(), crate::cpu_time::process_cpu_ms());
                let r = write_frame(job, &files, &invalidation).map_err(|e| (name.clone(), e));
                stages.encode.push(ms_since(t0));
                stages.encode_cpu.extend(cpu_ms_since(c0));
                r
            }) {
                Ok(()) => summary.rendered += 1,
                Err((n, e)) => summary.failed.push((n, e.to_string())),
            }
            progress();
        }
        summary.frames_in_flight = 1;
        summary.stages = stages;
        if index_again(&summary) {
            summary.index = super::index::write_part(root.real_path(), frames, opts)?;
        }
        warned(&mut summary, warnings);
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
        let (decoded_tx, decoded_rx) = mpsc::sync_channel::<(usize, Result<(RefocusSource, Inputs)>, f64)>(jobs);
        for _ in 0..jobs {
            let (tx, next, todo, warnings) = (decoded_tx.clone(), &next, &todo, &warnings);
            scope.spawn(move || loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(frame) = todo.get(i) else { break };
                let t0 = Instant::now();
                // The inputs' identities are hashed here, off the GL thread, just after the
                // decoder read them.
                let src = decode_frame(frame, i, depth_trunc, warnings).map(|s| (s, frame_inputs(frame)));
                if tx.send((i, src, ms_since(t0))).is_err() {
                    break;
                }
            });
        }
        drop(decoded_tx);
        let (job_tx, job_rx) = mpsc::sync_channel::<WriteJob>(jobs);
        let job_rx = Arc::new(Mutex::new(job_rx));
        for _ in 0..jobs {
            let (rx, tx, invalidation) = (job_rx.clone(), result_tx.clone(), &invalidation);
            scope.spawn(move || loop {
                let next = rx.lock().map(|r| r.recv());
                let Ok(Ok(job)) = next else { break };
                let name = job.name.clone();
                let t0 = Instant::now();
                let r = write_frame(job, &files, invalidation);
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
            let name = todo[i].name.clone().unwrap_or_default();
            let submitted = src.and_then(|(src, inputs)| {
                let settings = frame_settings(todo[i], opts, inputs);
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
    if index_again(&summary) {
        summary.index = super::index::write_part(root.real_path(), frames, opts)?;
    }
    warned(&mut summary, warnings);
    summary.wall_s = t_start.elapsed().as_secs_f64();
    Ok(summary)
}
