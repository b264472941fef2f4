//! `viewsynth bench --batch`: the pipelined refocus batch against the synchronous one (every
//! stage in turn on one thread) in the same run, on the built-in scene or a manifest, with the
//! per-stage medians and the stage that bounds the throughput. Nothing here asserts a time.

use super::codecs::{codec_rows, CodecRow};
use crate::stats::median;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use viewsynth::error::{Error, Result};
use viewsynth::output::FileFormats;
use viewsynth::pass::Device;
use viewsynth::refocus::batch::{load_manifest, run_batch, BatchFrame, BatchOptions, BatchSummary, StageTimes};
use viewsynth::refocus::{BreakRule, Method};
use viewsynth::{convention::Conventions, io, world};

/// Where the frames come from.
#[derive(Debug, Clone)]
pub enum BatchInput {
    /// `frames` copies of a 640x480 frame of the built-in scene (PNG colour, EXR depth).
    /// Frames to render.
    Scene {
        /// How many.
        frames: usize,
    },
    /// A CSV/JSON manifest, as `refocus --batch` reads it.
    Manifest(PathBuf),
}

/// Medians of the stages, ms per frame.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct StageMedians {
    /// Reading and decoding the inputs.
    pub decode: f64,
    /// Break rule, coverage flags and texture uploads.
    pub upload: f64,
    /// Recording the draws and queueing the reads.
    pub render: f64,
    /// Waiting for the GPU and mapping the outputs.
    pub readback: f64,
    /// Encoding and writing the files.
    pub encode: f64,
    /// GL thread idle: waiting for a decoded frame or for room in the encode queue.
    pub wait: f64,
    /// GPU time of a frame's draws, where the driver's timer queries are meaningful.
    pub gpu_render: Option<f64>,
    /// Process CPU ms of decode (synchronous run only: its pool threads included).
    pub decode_cpu: Option<f64>,
    /// Process CPU ms of encode (synchronous run only: its pool threads included).
    pub encode_cpu: Option<f64>,
}

/// One batch run.
#[derive(Debug, Clone, Serialize)]
pub struct BatchRun {
    /// Threads per CPU pool (0: the synchronous baseline).
    pub jobs: usize,
    /// Frames rendered.
    pub frames: usize,
    /// Frames that failed.
    pub failed: usize,
    /// Wall time of the run, seconds.
    pub wall_s: f64,
    /// Throughput.
    pub frames_per_s: f64,
    /// Stage medians.
    pub stages_ms: StageMedians,
    /// Per-frame ms of each stage as the pipeline sees it: a pool's stage divided by its
    /// threads, the GL thread's stages summed (they run in turn on one thread).
    pub effective_ms: Vec<(String, f64)>,
    /// The stage with the largest effective time: what bounds the throughput.
    pub bound_by: String,
    /// frames/s against 1 / (bounding stage's effective ms): 1.0 = the pipeline hides all else.
    pub efficiency: f64,
    /// Most frames held in memory at once.
    pub frames_in_flight: usize,
    /// Host CPU per frame: decode + upload + readback + encode medians (the stages a GPU
    /// server's host runs; render is left out, on llvmpipe it is the rasteriser's, and so is
    /// part of readback here).
    pub host_cpu_ms: f64,
    /// The frames/s that host CPU allows on `cores` cores: cores x 1000 / host_cpu_ms.
    pub host_cpu_frames_per_s: f64,
}

/// The report: pipelined and synchronous on the same input.
#[derive(Debug, Clone, Serialize)]
pub struct BatchBench {
    /// The renderer measured (GL_RENDERER).
    pub renderer: String,
    /// The input: built-in frames or the manifest.
    pub input: String,
    /// Source frame size.
    pub frame_size: (u32, u32),
    /// Focal scales rendered per frame.
    pub scales: Vec<f64>,
    /// Bytes one frame holds in memory (source + all outputs).
    pub bytes_per_frame: usize,
    /// PNG compression of the colour and mask files.
    pub png_compression: io::PngCompression,
    /// Fields of the pipelined run, flat, for scripts.
    pub frames_per_s: f64,
    /// The pipelined run's frames.
    pub frames: usize,
    /// The pipelined run's stage medians.
    pub stages_ms: StageMedians,
    /// The pipelined run's bounding stage.
    pub bound_by: String,
    /// The run with `jobs` threads per pool.
    pub pipelined: BatchRun,
    /// The run with every stage in turn on the GL thread.
    pub synchronous: BatchRun,
    /// pipelined frames/s over synchronous frames/s.
    pub speedup: f64,
    /// `--with-vulkan`: the device's name and the same pipelined run on it.
    pub vulkan: Option<(String, BatchRun)>,
    /// Cores this process may use: the N of `host_cpu_frames_per_s`.
    pub cores: usize,
    /// The synchronous run's host CPU per frame (ms), flat for scripts.
    pub host_cpu_ms: f64,
    /// Per file kind and codec: encode CPU of the first frame's targets, decode CPU of each
    /// input kind (`bench::codecs`).
    pub codecs: Vec<CodecRow>,
}

fn medians(s: &StageTimes) -> StageMedians {
    StageMedians {
        decode: median(&s.decode),
        upload: median(&s.upload),
        render: median(&s.render),
        readback: median(&s.readback),
        encode: median(&s.encode),
        wait: median(&s.wait),
        gpu_render: (!s.gpu_render.is_empty()).then(|| median(&s.gpu_render)),
        decode_cpu: (!s.decode_cpu.is_empty()).then(|| median(&s.decode_cpu)),
        encode_cpu: (!s.encode_cpu.is_empty()).then(|| median(&s.encode_cpu)),
    }
}

/// The cores this process may use (the N of the host-CPU frame rate).
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

fn summarise(jobs: usize, s: &BatchSummary) -> BatchRun {
    let m = medians(&s.stages);
    let fps = s.rendered as f64 / s.wall_s.max(1e-9);
    let gl = m.upload + m.render + m.readback;
    let host_cpu = m.decode + m.upload + m.readback + m.encode;
    let effective = if jobs == 0 {
        vec![("one thread (all stages)".to_string(), m.decode + gl + m.encode)]
    } else {
        let threads = jobs as f64;
        vec![
            ("decode".to_string(), m.decode / threads),
            (
                format!(
                    "GL thread (upload {:.1} + render {:.1} + readback {:.1})",
                    m.upload, m.render, m.readback
                ),
                gl,
            ),
            ("encode".to_string(), m.encode / threads),
        ]
    };
    let (bound_by, bound_ms) = effective
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .cloned()
        .unwrap_or_default();
    BatchRun {
        jobs,
        frames: s.rendered,
        failed: s.failed.len(),
        wall_s: s.wall_s,
        frames_per_s: fps,
        stages_ms: m,
        effective_ms: effective,
        bound_by,
        efficiency: fps * bound_ms / 1e3,
        frames_in_flight: s.frames_in_flight,
        host_cpu_ms: host_cpu,
        host_cpu_frames_per_s: cores() as f64 * 1e3 / host_cpu.max(1e-9),
    }
}

/// Repeats of each codec measurement (medians).
const CODEC_REPEATS: usize = 5;

/// Write the built-in scene's frame and a manifest of `n` copies of it under `dir`.
fn scene_manifest(dir: &Path, n: usize) -> Result<PathBuf> {
    let cam = world::demo_camera(640, 480);
    let (rgb, depth) = world::render(&cam);
    io::save_rgb(&dir.join("rgb.png"), &rgb)?;
    io::save_depth_exr(&dir.join("depth.exr"), &depth)?;
    let k = cam.k;
    let mut csv = String::from("rgb,depth,fx,fy,cx,cy,name\n");
    for i in 0..n {
        let _ = writeln!(csv, "rgb.png,depth.exr,{},{},{},{},f{i:05}", k.fx, k.fy, k.cx, k.cy);
    }
    let path = dir.join("frames.csv");
    std::fs::write(&path, csv).map_err(|e| Error::io(&path, e))?;
    Ok(path)
}

/// Run the batch twice on the same input (synchronous, then pipelined with `jobs` threads per
/// pool), and a third time pipelined on `vulkan` when given, into scratch folders that are
/// removed afterwards.
pub fn batch_bench(
    device: &Device,
    input: &BatchInput,
    jobs: usize,
    files: FileFormats,
    vulkan: Option<&viewsynth::pass::Device>,
) -> Result<BatchBench> {
    let scratch = tempfile::Builder::new()
        .prefix("viewsynth-bench-batch-")
        .tempdir()
        .map_err(|e| Error::io(Path::new("temporary folder"), e))?;
    let (manifest, label) = match input {
        BatchInput::Scene { frames } => (
            scene_manifest(scratch.path(), (*frames).max(1))?,
            format!("built-in scene 640x480 x {frames}"),
        ),
        BatchInput::Manifest(p) => (p.clone(), p.display().to_string()),
    };
    let frames: Vec<BatchFrame> = load_manifest(&manifest)?;
    let first = &frames[0];
    let (w, h) = io::load_rgb(&first.rgb).map(|i| (i.width, i.height))?;
    let scales = viewsynth::refocus::manifest::DEFAULT_SCALES.to_vec();
    let opts = |jobs: usize| BatchOptions {
        zoom_random: None,
        rgb_everywhere: false,
        scales: scales.clone(),
        size: None,
        principal: None,
        rule: BreakRule::default(),
        method: Method::Fullscreen,
        conv: Conventions::default(),
        files,
        depth_trunc: None,
        resume: false,
        verify: false,
        jobs,
        shard: None,
        index: true,
    };
    let run = |device: viewsynth::pass::Device, jobs: usize, name: &str| -> Result<BatchRun> {
        let out = scratch.path().join(name);
        let s = run_batch(&device, &frames, &out, &opts(jobs), || ())?;
        let _ = std::fs::remove_dir_all(&out);
        // A frame rate over the frames that happened to load measures another input: every
        // frame of the manifest renders, or the benchmark is refused, naming the first failure.
        if let Some((frame, error)) = s.failed.first() {
            return Err(Error::decode(
                &manifest,
                format!(
                    "{} of {} frames failed, so no frame rate is reported; first: frame {frame}: {error}",
                    s.failed.len(),
                    frames.len()
                ),
            ));
        }
        Ok(summarise(jobs, &s))
    };
    let gl = device.clone();
    let synchronous = run(gl.clone(), 0, "sync")?;
    let pipelined = run(gl.clone(), jobs.max(1), "pipelined")?;
    let vulkan = match vulkan {
        Some(d) => Some((d.renderer(), run(d.clone(), jobs.max(1), "vulkan")?)),
        None => None,
    };
    // After the runs: a manifest with a frame that does not load is refused by them, naming it.
    let codecs = {
        let decode = io::DepthDecode {
            scale: first.depth_scale,
            sun_rgbd_bit_rotate: first.sun_bit_rotate,
            ..Default::default()
        };
        let k = viewsynth::camera::Intrinsics {
            fx: first.fx,
            fy: first.fy,
            cx: first.cx,
            cy: first.cy,
        };
        let (rgb, depth) = (io::load_rgb(&first.rgb)?, io::load_depth(&first.depth, &decode)?);
        codec_rows(
            &gl,
            (&first.rgb, &first.depth),
            rgb,
            depth,
            k,
            &scales,
            scratch.path(),
            CODEC_REPEATS,
        )?
    };
    let px = w as usize * h as usize;
    let out_px: usize = scales.len() * px;
    let bytes_per_frame = px * (3 + 4)
        + out_px * (3 * files.outputs.rgb as usize + 4 * files.outputs.depth as usize + files.outputs.mask as usize);
    Ok(BatchBench {
        renderer: device.renderer(),
        input: label,
        frame_size: (w, h),
        scales,
        bytes_per_frame,
        png_compression: files.encoding.png,
        frames_per_s: pipelined.frames_per_s,
        frames: pipelined.frames,
        stages_ms: pipelined.stages_ms,
        bound_by: pipelined.bound_by.clone(),
        speedup: pipelined.frames_per_s / synchronous.frames_per_s.max(1e-9),
        cores: cores(),
        host_cpu_ms: synchronous.host_cpu_ms,
        pipelined,
        synchronous,
        vulkan,
        codecs,
    })
}

impl BatchBench {
    /// Markdown tables: throughput of both runs and the stage medians.
    pub fn table(&self) -> String {
        let mut t = format!(
            "batch refocus benchmark on {} — {}, {} scales, PNG {:?}; {:.1} MB per frame in memory\n\n\
             | run | jobs | frames | frames/s | decode | upload | render | readback | encode | wait | GPU render | bound by | efficiency |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
            self.renderer,
            self.input,
            self.scales.len(),
            self.png_compression,
            self.bytes_per_frame as f64 / 1e6
        );
        let mut runs = vec![("synchronous", &self.synchronous), ("pipelined", &self.pipelined)];
        if let Some((_, r)) = &self.vulkan {
            runs.push(("pipelined, Vulkan", r));
        }
        for (name, r) in runs {
            let m = &r.stages_ms;
            let _ = writeln!(
                t,
                "| {name} | {} | {} | {:.2} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {} | {} | {:.2} |",
                r.jobs,
                r.frames,
                r.frames_per_s,
                m.decode,
                m.upload,
                m.render,
                m.readback,
                m.encode,
                m.wait,
                m.gpu_render.map_or("-".to_string(), |g| format!("{g:.2}")),
                r.bound_by,
                r.efficiency
            );
        }
        let _ = writeln!(
            t,
            "\nstage columns: median ms per frame; pipelined / synchronous = {:.2}x; at most {} frames in memory \
             (~{:.0} MB)",
            self.speedup,
            self.pipelined.frames_in_flight,
            (self.pipelined.frames_in_flight * self.bytes_per_frame) as f64 / 1e6
        );
        if let Some((device, r)) = &self.vulkan {
            let _ = writeln!(
                t,
                "Vulkan row: {device}, the same pipeline and files; Vulkan / GL frames/s = {:.2}",
                r.frames_per_s / self.pipelined.frames_per_s.max(1e-9)
            );
        }
        let _ = writeln!(
            t,
            "\nhost CPU per frame (decode + upload + readback + encode medians; render left out):\n\n\
             | run | host CPU ms / frame | frames/s it allows on {n} cores | measured frames/s | decode CPU ms | encode CPU ms |\n\
             |---|---|---|---|---|---|",
            n = self.cores
        );
        let cpu = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
        for (name, r) in [("synchronous", &self.synchronous), ("pipelined", &self.pipelined)] {
            let _ = writeln!(
                t,
                "| {name} | {:.1} | {:.1} | {:.2} | {} | {} |",
                r.host_cpu_ms,
                r.host_cpu_frames_per_s,
                r.frames_per_s,
                cpu(r.stages_ms.decode_cpu),
                cpu(r.stages_ms.encode_cpu)
            );
        }
        let _ = writeln!(
            t,
            "\nper codec (process CPU ms on one thread, medians; encode: the first frame's {} targets, \
             decode: one file; * = the default output, or the format of the frames read):\n\n| stage | kind | codec | CPU ms | bytes |\n|---|---|---|---|---|",
            self.scales.len()
        );
        for c in &self.codecs {
            let _ = writeln!(
                t,
                "| {} | {} | {}{} | {:.2} | {} |",
                c.stage,
                c.kind,
                c.codec,
                if c.default { " *" } else { "" },
                c.cpu_ms,
                c.bytes
            );
        }
        t
    }
}
