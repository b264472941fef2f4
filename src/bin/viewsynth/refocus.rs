//! `viewsynth refocus` (one frame or --batch): arguments and the call into viewsynth::refocus.

use super::*;

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum MethodArg {
    Mesh,
    Fullscreen,
}

#[derive(Args)]
pub(crate) struct RefocusArgs {
    /// Source colour (PNG, JPEG, PPM, EXR).
    #[arg(long, required_unless_present = "batch")]
    rgb: Option<PathBuf>,
    /// Source metric depth, view-space Z (EXR, NPY f32/f64/u16, 16-bit PNG/PGM with --depth-scale, PFM).
    #[arg(long, required_unless_present = "batch")]
    depth: Option<PathBuf>,
    /// Refocus every frame of a CSV/JSON manifest (columns rgb,depth,fx,fy,cx,cy[,depth_scale,name];
    /// see src/refocus/batch.rs) into <out-dir>/<name>/, with one GL context, files encoded on
    /// writer threads, and resume.
    #[arg(long, conflicts_with_all = ["rgb", "depth"])]
    batch: Option<PathBuf>,
    /// With --batch: render frames that already have a manifest.json again.
    #[arg(long)]
    no_resume: bool,
    /// With --batch: threads encoding files while the GPU renders (0 = none).
    #[arg(long, default_value_t = 1, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=MAX_WRITER_THREADS))]
    writer_threads: usize,
    /// Raw units per metre for integer depth (5000 for TUM, 1000 for NYU/SUN); divides float depth too when given.
    #[arg(long, value_parser = finite_value)]
    depth_scale: Option<f64>,
    /// SUN RGB-D PNG depth: rotate the 16-bit value right by 3 bits before scaling.
    #[arg(long)]
    sun_bit_rotate: bool,
    #[arg(long, required_unless_present = "batch", value_parser = finite_value)]
    fx: Option<f64>,
    #[arg(long, required_unless_present = "batch", value_parser = finite_value)]
    fy: Option<f64>,
    #[arg(long, required_unless_present = "batch", value_parser = finite_value)]
    cx: Option<f64>,
    #[arg(long, required_unless_present = "batch", value_parser = finite_value)]
    cy: Option<f64>,
    #[arg(long)]
    out_dir: PathBuf,
    /// Target focal lengths fx' in pixels (fy' keeps the source fy/fx).
    #[arg(long, value_delimiter = ',', conflicts_with = "zoom_range", value_parser = finite_value)]
    focal_list: Option<Vec<f64>>,
    /// Target focal scales s (fx' = s fx).
    #[arg(long, value_delimiter = ',', default_value = "0.5,0.75,1,1.5,2", value_parser = finite_value)]
    zoom_range: Vec<f64>,
    /// Break an edge when |za - zb| > tau_rel * min(za, zb).
    #[arg(long, default_value_t = BreakRule::default().tau_rel, value_parser = finite_value)]
    tau_rel: f64,
    /// Break an edge when |za - zb| > tau_abs (metres; "inf" disables).
    #[arg(long, default_value_t = BreakRule::default().tau_abs, value_parser = finite_or_inf)]
    tau_abs: f64,
    #[arg(long, requires = "height_out", value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    width_out: Option<u32>,
    #[arg(long, requires = "width_out", value_parser = clap::value_parser!(u32).range(1..=i64::from(io::MAX_DIMENSION)))]
    height_out: Option<u32>,
    /// Output principal point (default: the source's offset from the image centre).
    #[arg(long, requires = "cy_out", value_parser = finite_value)]
    cx_out: Option<f64>,
    #[arg(long, requires = "cx_out", value_parser = finite_value)]
    cy_out: Option<f64>,
    #[command(flatten)]
    files: FileOutputArgs,
    #[arg(long, value_enum, default_value = "fullscreen")]
    method: MethodArg,
    #[command(flatten)]
    conv: ConventionArgs,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub(crate) fn refocus(a: RefocusArgs) -> Result<()> {
    if let Some(manifest) = a.batch.clone() {
        return refocus_batch(&manifest, a);
    }
    // Everything that can be checked before touching the GPU or the output directory is.
    // (clap requires these without --batch.)
    let (Some(rgb_path), Some(depth_path), Some(fx), Some(fy), Some(cx), Some(cy)) =
        (a.rgb.clone(), a.depth.clone(), a.fx, a.fy, a.cx, a.cy)
    else {
        bail!("--rgb, --depth, --fx, --fy, --cx and --cy are required without --batch");
    };
    let k = Intrinsics { fx, fy, cx, cy };
    k.validate("source intrinsics")?;
    let rule = BreakRule {
        tau_rel: a.tau_rel,
        tau_abs: a.tau_abs,
    };
    rule.validate()?;
    let (outputs, rgb_format, depth_formats) = a.files.parse()?;
    let conv = a.conv.conventions();
    let method = match a.method {
        MethodArg::Mesh => Method::Mesh,
        MethodArg::Fullscreen => Method::Fullscreen,
    };
    if let (Some(w), Some(h)) = (a.width_out, a.height_out) {
        io::check_output_pixels("--width-out/--height-out", w, h)?;
    }
    // Sizes and the pixel budget from the headers before either file is decoded.
    io::check_rgbd_sizes(&rgb_path, &depth_path)?;
    let rgb = io::load_rgb(&rgb_path)?;
    let decode = DepthDecode {
        scale: a.depth_scale,
        sun_rgbd_bit_rotate: a.sun_bit_rotate,
        ..Default::default()
    };
    let depth = io::load_depth(&depth_path, &decode)?;
    let src = RefocusSource::new(rgb, depth, k)
        .with_context(|| format!("{} and {}", rgb_path.display(), depth_path.display()))?;
    let scales = match &a.focal_list {
        Some(list) => TargetSpec::scales_from_focal_list(&k, list),
        None => a.zoom_range.clone(),
    };
    let spec = TargetSpec {
        scales: scales.clone(),
        size: a.width_out.zip(a.height_out),
        principal: a.cx_out.zip(a.cy_out),
    };
    let targets = spec.targets(&src.camera())?;
    let out_dir = prepare_out_dir(&a.out_dir)?;

    let gpu = a.gpu.open()?;
    let mut refocuser = Refocuser::new(&gpu, &src, &rule, method, outputs, conv)?;
    let bar = indicatif::ProgressBar::new(targets.len() as u64);
    let mut entries = Vec::new();
    // All targets and the manifest, or (on any failure) none: earlier runs' files stay.
    let set = out_dir.file_set()?;
    for (scale, target) in scales.iter().zip(&targets) {
        let out = refocuser.render(target)?;
        entries.push(
            job::write_output(set.staging(), *scale, &out, &outputs, rgb_format, depth_formats)
                .map_err(|e| set.final_error(e))?,
        );
        bar.inc(1);
    }
    bar.finish_and_clear();
    let manifest = Manifest {
        tool: format!("viewsynth {}", env!("CARGO_PKG_VERSION")),
        source: src.camera(),
        method,
        break_rule: rule,
        conventions: conv,
        renderer: gpu.info().renderer.clone(),
        notes: job::MANIFEST_NOTES.to_string(),
        outputs: entries,
    };
    job::write_manifest(set.staging(), &manifest).map_err(|e| set.final_error(e))?;
    set.commit()?;
    let path = out_dir.path().join("manifest.json");
    for e in &manifest.outputs {
        println!(
            "s={:<6} fx'={:<9.3} {}x{} coverage {:>6.2}%  render {:>7.2} ms",
            e.scale,
            e.intrinsics.fx,
            e.width,
            e.height,
            e.coverage.unwrap_or(f64::NAN) * 100.0,
            e.render_ms
        );
    }
    println!("wrote {} targets; manifest {}", manifest.outputs.len(), path.display());
    Ok(())
}

pub(crate) fn refocus_batch(manifest: &Path, a: RefocusArgs) -> Result<()> {
    use viewsynth::refocus::batch::{load_manifest, run_batch, BatchOptions};
    if a.focal_list.is_some() {
        bail!("--focal-list is per frame; with --batch give --zoom-range scales");
    }
    let frames = load_manifest(manifest)?;
    let (outputs, rgb_format, depth_formats) = a.files.parse()?;
    let opts = BatchOptions {
        scales: a.zoom_range.clone(),
        size: a.width_out.zip(a.height_out),
        principal: a.cx_out.zip(a.cy_out),
        rule: BreakRule {
            tau_rel: a.tau_rel,
            tau_abs: a.tau_abs,
        },
        method: match a.method {
            MethodArg::Mesh => Method::Mesh,
            MethodArg::Fullscreen => Method::Fullscreen,
        },
        outputs,
        conv: a.conv.conventions(),
        rgb_format,
        depth_formats,
        resume: !a.no_resume,
        writer_threads: a.writer_threads,
    };
    opts.rule.validate()?;
    prepare_out_dir(&a.out_dir)?;
    let gpu = a.gpu.open()?;
    let bar = indicatif::ProgressBar::new(frames.len() as u64);
    let summary = run_batch(&gpu, &frames, &a.out_dir, &opts, || bar.inc(1))?;
    bar.finish_and_clear();
    println!(
        "{} frames: {} rendered, {} already done (resume), {} failed; {:.1} s, {:.2} frames/s",
        frames.len(),
        summary.rendered,
        summary.skipped,
        summary.failed.len(),
        summary.wall_s,
        summary.rendered as f64 / summary.wall_s.max(1e-9)
    );
    if !summary.failed.is_empty() {
        for (name, e) in &summary.failed {
            eprintln!("failed: {name}: {e}");
        }
        bail!(
            "{} of {} frames failed (listed above); the others completed",
            summary.failed.len(),
            frames.len()
        );
    }
    Ok(())
}
