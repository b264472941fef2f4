//! Batch refocus for dataset work: many frames, one GL context, file encoding on writer threads
//! while the GPU renders the next frame, resume by skipping frames already finished, and a
//! summary that lists failed frames while the others complete.
//!
//! Manifest: CSV with a header naming the columns `rgb,depth,fx,fy,cx,cy` and optionally
//! `depth_scale`, `name` (no quoting: paths with commas need JSON), or a JSON array of objects
//! with the same fields (`sun_bit_rotate` too). Relative paths are relative to the manifest.
//! Each frame writes into `<out>/<name>/`; its `manifest.json` is written last, atomically, and
//! marks the frame finished.

use super::job::{self, DepthFormats, Manifest, RgbFormat, TargetSpec};
use super::{BreakRule, Method, OutputSet, RefocusOutput, RefocusSource, Refocuser};
use crate::camera::Intrinsics;
use crate::convention::Conventions;
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::io::{self, DepthDecode};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Instant;

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BatchFrame {
    #[serde(default)]
    pub name: Option<String>,
    pub rgb: PathBuf,
    pub depth: PathBuf,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    #[serde(default)]
    pub depth_scale: Option<f64>,
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

/// Read a CSV or JSON manifest; every frame gets a unique, filesystem-safe name.
pub fn load_manifest(path: &Path) -> Result<Vec<BatchFrame>> {
    // Spreadsheets save CSV with a UTF-8 byte-order mark: skipped.
    let text = crate::io::read_text(path, crate::io::MAX_JSON_BYTES)?;
    let mut frames: Vec<BatchFrame> = if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json")) {
        serde_json::from_str(&text).map_err(|e| Error::decode(path, e.to_string()))?
    } else {
        parse_csv(path, &text)?
    };
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
        if safe.is_empty() || safe.starts_with('.') || !seen.insert(safe.clone()) {
            return Err(Error::decode(
                path,
                format!("frame {i}: name '{name}' is empty, hidden or repeated"),
            ));
        }
        f.name = Some(safe);
    }
    Ok(frames)
}

fn parse_csv(path: &Path, text: &str) -> Result<Vec<BatchFrame>> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| Error::decode(path, "empty manifest"))?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |name: &str| cols.iter().position(|c| *c == name);
    let required = ["rgb", "depth", "fx", "fy", "cx", "cy"];
    for r in required {
        if col(r).is_none() {
            return Err(Error::decode(
                path,
                format!("header lacks column '{r}' (needs rgb,depth,fx,fy,cx,cy)"),
            ));
        }
    }
    let mut frames = Vec::new();
    for (n, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != cols.len() {
            return Err(Error::decode(
                path,
                format!("line {}: {} cells, header has {}", n + 1, cells.len(), cols.len()),
            ));
        }
        let get = |name: &str| col(name).map(|i| cells[i]);
        let num = |name: &str| -> Result<f64> {
            let v = get(name).unwrap_or_default();
            v.parse()
                .map_err(|_| Error::decode(path, format!("line {}: {name} = '{v}' is not a number", n + 1)))
        };
        frames.push(BatchFrame {
            name: get("name").filter(|s| !s.is_empty()).map(str::to_string),
            rgb: PathBuf::from(get("rgb").unwrap_or_default()),
            depth: PathBuf::from(get("depth").unwrap_or_default()),
            fx: num("fx")?,
            fy: num("fy")?,
            cx: num("cx")?,
            cy: num("cy")?,
            depth_scale: match get("depth_scale") {
                Some(v) if !v.is_empty() => Some(num("depth_scale")?),
                _ => None,
            },
            sun_bit_rotate: get("sun_bit_rotate").is_some_and(|v| v == "1" || v.eq_ignore_ascii_case("true")),
        });
    }
    Ok(frames)
}

/// Everything a batch applies to each frame.
#[derive(Debug, Clone)]
pub struct BatchOptions {
    pub scales: Vec<f64>,
    pub size: Option<(u32, u32)>,
    pub principal: Option<(f64, f64)>,
    pub rule: BreakRule,
    pub method: Method,
    pub outputs: OutputSet,
    pub conv: Conventions,
    pub rgb_format: RgbFormat,
    pub depth_formats: DepthFormats,
    /// Skip frames whose manifest.json already exists.
    pub resume: bool,
    /// Threads encoding files while the GPU renders; 0 writes on the render thread.
    pub writer_threads: usize,
}

#[derive(Debug, Clone, Default)]
pub struct BatchSummary {
    pub rendered: usize,
    pub skipped: usize,
    /// (frame name, error) for every frame that failed; the others completed.
    pub failed: Vec<(String, String)>,
    pub wall_s: f64,
}

struct WriteJob {
    name: String,
    dir: PathBuf,
    outputs: Vec<(f64, RefocusOutput)>,
    manifest: Manifest,
}

fn write_frame(job: WriteJob, opts: &BatchOptions) -> Result<()> {
    std::fs::create_dir_all(&job.dir).map_err(|e| Error::io(&job.dir, e))?;
    let mut manifest = job.manifest;
    for (scale, out) in &job.outputs {
        manifest.outputs.push(job::write_output(
            &job.dir,
            *scale,
            out,
            &opts.outputs,
            opts.rgb_format,
            opts.depth_formats,
        )?);
    }
    // Last: its presence marks the frame finished for resume.
    job::write_manifest(&job.dir, &manifest)?;
    Ok(())
}

/// An interrupted run (a signal cannot run cleanup) may leave `atomic_write` temporaries
/// (`.{file}.tmp-{pid}-{n}`) in an unfinished frame's folder; they are removed before it is
/// rendered again. Final names are never partial either way.
fn remove_stale_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') && name.contains(".tmp-") {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Render one frame's targets (errors name the frame's files).
fn render_frame(gpu: &Gpu, frame: &BatchFrame, opts: &BatchOptions) -> Result<(Vec<(f64, RefocusOutput)>, Manifest)> {
    let decode = DepthDecode {
        scale: frame.depth_scale,
        sun_rgbd_bit_rotate: frame.sun_bit_rotate,
        ..Default::default()
    };
    let src = RefocusSource::new(
        io::load_rgb(&frame.rgb)?,
        io::load_depth(&frame.depth, &decode)?,
        frame.intrinsics(),
    )?;
    let targets = TargetSpec {
        scales: opts.scales.clone(),
        size: opts.size,
        principal: opts.principal,
    }
    .targets(&src.camera())?;
    let mut r = Refocuser::new(gpu, &src, &opts.rule, opts.method, opts.outputs, opts.conv)?;
    let mut outs = Vec::new();
    for (s, t) in opts.scales.iter().zip(&targets) {
        outs.push((*s, r.render(t)?));
    }
    let manifest = Manifest {
        tool: format!("viewsynth {}", env!("CARGO_PKG_VERSION")),
        source: src.camera(),
        method: opts.method,
        break_rule: opts.rule,
        conventions: opts.conv,
        renderer: gpu.info().renderer.clone(),
        notes: job::MANIFEST_NOTES.to_string(),
        outputs: Vec::new(),
    };
    Ok((outs, manifest))
}

/// Run the batch. `progress` is called once per frame (rendered, skipped or failed).
pub fn run_batch(
    gpu: &Gpu,
    frames: &[BatchFrame],
    out_dir: &Path,
    opts: &BatchOptions,
    progress: impl Fn(),
) -> Result<BatchSummary> {
    if opts.scales.is_empty() {
        return Err(Error::param("scales", "no focal scale given"));
    }
    opts.rule.validate()?;
    std::fs::create_dir_all(out_dir).map_err(|e| Error::io(out_dir, e))?;
    let t0 = Instant::now();
    let mut summary = BatchSummary::default();
    let (result_tx, result_rx) = mpsc::channel::<(String, Result<()>)>();
    std::thread::scope(|scope| {
        // A bounded queue keeps memory flat: the renderer waits when writers fall behind.
        let (job_tx, job_rx) = mpsc::sync_channel::<WriteJob>(opts.writer_threads.max(1) * 2);
        let job_rx = std::sync::Arc::new(std::sync::Mutex::new(job_rx));
        for _ in 0..opts.writer_threads {
            let (rx, tx) = (job_rx.clone(), result_tx.clone());
            scope.spawn(move || loop {
                let next = rx.lock().map(|r| r.recv());
                let Ok(Ok(job)) = next else { break };
                let name = job.name.clone();
                let _ = tx.send((name, write_frame(job, opts)));
            });
        }
        for frame in frames {
            let name = frame.name.clone().unwrap_or_default();
            let dir = out_dir.join(&name);
            if opts.resume && dir.join("manifest.json").is_file() {
                summary.skipped += 1;
                progress();
                continue;
            }
            remove_stale_temporaries(&dir);
            match render_frame(gpu, frame, opts) {
                Ok((outputs, manifest)) => {
                    summary.rendered += 1;
                    let job = WriteJob {
                        name: name.clone(),
                        dir,
                        outputs,
                        manifest,
                    };
                    if opts.writer_threads == 0 {
                        let _ = result_tx.send((name, write_frame(job, opts)));
                    } else if let Err(mpsc::SendError(job)) = job_tx.send(job) {
                        let _ = result_tx.send((job.name, Err(Error::param("batch writer", "writer threads stopped"))));
                    }
                }
                Err(e) => summary.failed.push((name, e.to_string())),
            }
            progress();
        }
        drop(job_tx);
    });
    drop(result_tx);
    for (name, r) in result_rx {
        if let Err(e) = r {
            summary.rendered -= 1;
            summary.failed.push((name, e.to_string()));
        }
    }
    summary.wall_s = t0.elapsed().as_secs_f64();
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
        assert!(load_manifest(&p).unwrap_err().to_string().contains("line 2"));
        let j = dir.join("frames.json");
        std::fs::write(&j, r#"[{"name":"same","rgb":"a","depth":"b","fx":1,"fy":1,"cx":0,"cy":0},{"name":"same","rgb":"c","depth":"d","fx":1,"fy":1,"cx":0,"cy":0}]"#).unwrap();
        assert!(load_manifest(&j).unwrap_err().to_string().contains("repeated"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
