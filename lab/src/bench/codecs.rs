//! `bench --batch`'s per-codec table: what each file kind costs to encode (one frame's targets,
//! rendered once) and each input kind to decode, in process CPU milliseconds on one thread,
//! with the bytes. The batch's stages say how long a frame takes; this says where its encode
//! and decode time goes, and what each format and compression choice would cost instead.
//! Timed on a one-thread pool, so a codec that splits its work (EXR ZIP blocks) is charged all
//! of it; medians over the repeats. Nothing here asserts a time.

use serde::Serialize;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;
use viewsynth::convention::Conventions;
use viewsynth::error::{Error, Result};
use viewsynth::io::{self, DepthDecode, DepthMap, Encoding, ExrCompression, PngCompression, RgbImage};
use viewsynth::output::OutputSet;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::{BreakRule, Method, RefocusOutput, RefocusSource, Refocuser};

/// One codec measured.
#[derive(Debug, Clone, Serialize)]
pub struct CodecRow {
    /// "encode" (one frame's targets) or "decode" (one input file).
    pub stage: String,
    /// What the file holds: colour, depth or mask.
    pub kind: String,
    /// Format and its setting.
    pub codec: String,
    /// Encode: what the batch writes by default; decode: the format of the benchmark's frames.
    pub default: bool,
    /// Median process CPU ms: per frame (all its targets) for encode, per file for decode.
    pub cpu_ms: f64,
    /// Bytes written: per frame (all its targets) for encode, of the file for decode.
    pub bytes: u64,
}

type Encoder = Box<dyn Fn(&Path, &mut BufWriter<File>, &RefocusOutput) -> Result<()> + Sync>;

fn missing(what: &str) -> Error {
    Error::param("outputs", format!("codec benchmark: the render has no {what}"))
}

fn rgb(o: &RefocusOutput) -> Result<&RgbImage> {
    o.rgb.as_ref().ok_or_else(|| missing("colour"))
}

fn depth(o: &RefocusOutput) -> Result<&DepthMap> {
    o.depth.as_ref().ok_or_else(|| missing("depth"))
}

/// The encoders of every output kind and setting the batch offers.
fn encoders() -> Vec<(&'static str, &'static str, bool, Encoder)> {
    let fast = Encoding::default();
    let exr = |c: ExrCompression| -> Encoder { Box::new(move |p, out, o| io::encode_depth_exr(p, out, depth(o)?, c)) };
    vec![
        (
            "colour",
            "PNG fast (Paeth, fdeflate)",
            true,
            Box::new(move |p, out, o| io::encode_rgb(p, out, rgb(o)?, "png", &fast)),
        ),
        (
            "colour",
            "JPEG q95",
            false,
            Box::new(move |p, out, o| io::encode_rgb(p, out, rgb(o)?, "jpg", &fast)),
        ),
        (
            "mask",
            "PNG fast (Up, fdeflate)",
            true,
            Box::new(|p, out, o| {
                let mask = o.mask.as_ref().ok_or_else(|| missing("mask"))?;
                io::encode_mask_png(p, out, mask, PngCompression::Fast)
            }),
        ),
        ("depth", "EXR ZIP (libdeflate level 1)", true, exr(ExrCompression::Zip)),
        ("depth", "EXR PIZ", false, exr(ExrCompression::Piz)),
        ("depth", "EXR RLE", false, exr(ExrCompression::Rle)),
        ("depth", "EXR uncompressed", false, exr(ExrCompression::None)),
        (
            "depth",
            "NPY f32",
            false,
            Box::new(move |p, out, o| io::encode_depth_npy(p, out, depth(o)?)),
        ),
        (
            "depth",
            "PNG16 mm (fast)",
            false,
            Box::new(move |p, out, o| {
                io::encode_depth_png16(p, out, depth(o)?, io::Png16Units::default(), PngCompression::Fast).map(|_| ())
            }),
        ),
    ]
}

/// Median of `repeats` runs of `f`, in process CPU ms, on the one-thread `pool`.
fn cpu_median(pool: &rayon_core::ThreadPool, repeats: usize, mut f: impl FnMut() -> Result<()> + Send) -> Result<f64> {
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats.max(1) {
        let c0 = viewsynth::cpu_time::process_cpu_ms();
        pool.install(&mut f)?;
        let c1 = viewsynth::cpu_time::process_cpu_ms();
        times.push(c0.zip(c1).map_or(0.0, |(a, b)| b - a));
    }
    Ok(crate::stats::median(&times))
}

fn file_len(path: &Path) -> Result<u64> {
    Ok(std::fs::metadata(path).map_err(|e| Error::io(path, e))?.len())
}

/// Encodes `outputs` (one frame's targets) with every encoder, into `scratch`.
fn encode_rows(
    pool: &rayon_core::ThreadPool,
    outputs: &[RefocusOutput],
    scratch: &Path,
    repeats: usize,
) -> Result<Vec<CodecRow>> {
    let path = scratch.join("codec-bench.out");
    let mut rows = Vec::new();
    for (kind, codec, default, encode) in encoders() {
        let mut bytes = 0;
        let cpu_ms = cpu_median(pool, repeats, || {
            bytes = 0;
            for o in outputs {
                let file = File::create(&path).map_err(|e| Error::io(&path, e))?;
                let mut out = BufWriter::new(file);
                encode(&path, &mut out, o)?;
                out.flush().map_err(|e| Error::io(&path, e))?;
                drop(out);
                bytes += file_len(&path)?;
            }
            Ok(())
        })?;
        rows.push(CodecRow {
            stage: "encode".into(),
            kind: kind.into(),
            codec: codec.into(),
            default,
            cpu_ms,
            bytes,
        });
    }
    let _ = std::fs::remove_file(&path);
    Ok(rows)
}

/// Writes the frame's colour and depth in every input format the batch reads and times their
/// loaders.
fn decode_rows(
    pool: &rayon_core::ThreadPool,
    frame_inputs: (&Path, &Path),
    rgb: &RgbImage,
    depth: &DepthMap,
    scratch: &Path,
    repeats: usize,
) -> Result<Vec<CodecRow>> {
    let mut rows = Vec::new();
    let mm = DepthDecode {
        scale: Some(io::PNG16_UNITS_PER_METRE),
        ..Default::default()
    };
    let metres = DepthDecode::default();
    let inputs: [(&str, &str, &str); 5] = [
        ("colour", "PNG", "in_rgb.png"),
        ("colour", "JPEG q95", "in_rgb.jpg"),
        ("depth", "EXR ZIP", "in_depth.exr"),
        ("depth", "PNG16 mm", "in_depth.png"),
        ("depth", "NPY f32", "in_depth.npy"),
    ];
    for (kind, codec, name) in inputs {
        let ext = |p: &Path| p.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        let input = if kind == "colour" {
            frame_inputs.0
        } else {
            frame_inputs.1
        };
        let this = ext(Path::new(name));
        // The format the benchmark's own frames come in (jpeg read as jpg).
        let default = ext(input).map(|e| if e == "jpeg" { "jpg".into() } else { e }) == this;
        let path = scratch.join(name);
        match name {
            "in_rgb.png" | "in_rgb.jpg" => io::save_rgb(&path, rgb)?,
            "in_depth.exr" => io::save_depth_exr(&path, depth)?,
            "in_depth.png" => {
                io::save_depth_png16(&path, depth, io::Png16Units::default(), PngCompression::Fast)?;
            }
            _ => io::save_depth_npy(&path, depth)?,
        }
        let cpu_ms = cpu_median(pool, repeats, || {
            match kind {
                "colour" => drop(io::load_rgb(&path)?),
                _ => drop(io::load_depth(
                    &path,
                    if name.ends_with(".png") { &mm } else { &metres },
                )?),
            }
            Ok(())
        })?;
        rows.push(CodecRow {
            stage: "decode".into(),
            kind: kind.into(),
            codec: codec.into(),
            default,
            cpu_ms,
            bytes: file_len(&path)?,
        });
        let _ = std::fs::remove_file(&path);
    }
    Ok(rows)
}

/// The per-codec rows for one frame (`rgb`, `depth`, `k`, read from `frame_inputs`: colour and
/// depth files) rendered at `scales` on `device`.
#[allow(clippy::too_many_arguments)]
pub fn codec_rows(
    device: &viewsynth::pass::Device,
    frame_inputs: (&Path, &Path),
    rgb: RgbImage,
    depth: DepthMap,
    k: viewsynth::camera::Intrinsics,
    scales: &[f64],
    scratch: &Path,
    repeats: usize,
) -> Result<Vec<CodecRow>> {
    let pool = rayon_core::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| Error::param("jobs", format!("codec benchmark: no thread pool: {e}")))?;
    let mut rows = decode_rows(&pool, frame_inputs, &rgb, &depth, scratch, repeats)?;
    let src = RefocusSource::new(rgb, depth, k)?;
    let mut refocuser = Refocuser::with_settings(
        device,
        &BreakRule::default(),
        Method::Fullscreen,
        OutputSet::default(),
        Conventions::default(),
    )?;
    refocuser.set_source(&src)?;
    let targets = TargetSpec {
        scales: scales.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&src.camera())?;
    let outputs = targets
        .iter()
        .map(|t| refocuser.submit(t)?.wait())
        .collect::<Result<Vec<_>>>()?;
    rows.extend(encode_rows(&pool, &outputs, scratch, repeats)?);
    Ok(rows)
}
