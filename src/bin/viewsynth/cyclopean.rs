//! `viewsynth cyclopean`: arguments and the call into viewsynth::cyclopean.

use super::*;

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum BlendArg {
    Hard,
    Soft,
}

#[derive(Args)]
pub(crate) struct CyclopeanArgs {
    #[arg(long)]
    left_rgb: PathBuf,
    /// Left depth: device (window) depth or view distance, as `depth_kind` in the camera file.
    #[arg(long)]
    left_depth: PathBuf,
    #[arg(long)]
    right_rgb: PathBuf,
    #[arg(long)]
    right_depth: PathBuf,
    /// Camera JSON: per-eye view/projection, middle projection and size, gaze or fixation,
    /// conventions, depth kind (see src/cyclopean/camera_file.rs).
    #[arg(long)]
    cameras: PathBuf,
    /// Raw units per unit of depth for integer depth files.
    #[arg(long, value_parser = finite_value)]
    depth_scale: Option<f64>,
    /// 0 = the seed's single step; k >= 1 = k-step refinement with projection check.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(0..=16))]
    refine_steps: u32,
    #[arg(long, value_enum, default_value = "hard")]
    blend: BlendArg,
    /// Middle-space depth disagreement (metres) treated as different surfaces (default: the
    /// seed's clamp(0.02 * fixation, 0.02, 0.25)).
    #[arg(long, value_parser = finite_value)]
    z_threshold: Option<f64>,
    /// Dominant eye and its blend weight, e.g. `left:0.7`.
    #[arg(long)]
    dominant: Option<String>,
    /// Outputs to write: any of rgb (or color), depth, mask. Colour and depth not listed are
    /// neither rendered into an attachment nor read back.
    #[arg(long, default_value = "rgb,depth,mask")]
    outputs: String,
    /// Writes middle_rgb.png, middle_depth.exr, middle_mask.png (those in --outputs).
    #[arg(long)]
    out_dir: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub(crate) fn cyclopean(a: CyclopeanArgs) -> Result<()> {
    use viewsynth::cyclopean::camera_file::CameraFile;
    use viewsynth::cyclopean::render::CyclopeanRenderer;
    use viewsynth::cyclopean::{
        Blend, CyclopeanOutputs, CyclopeanParams, Eye, EyeInput, Method as CMethod, StereoFrame,
    };
    let outputs = OutputSet::parse(&a.outputs)?;
    let cams = CameraFile::load(&a.cameras)?;
    let (mid, fixation) = cams.middle_and_fixation()?;
    let mut params = CyclopeanParams::seed(fixation);
    if a.refine_steps > 0 {
        params.method = CMethod::Refine { steps: a.refine_steps };
    }
    params.blend = match a.blend {
        BlendArg::Hard => Blend::Hard,
        BlendArg::Soft => Blend::Soft,
    };
    if let Some(t) = a.z_threshold {
        params.z_threshold = t;
    }
    if let Some(d) = &a.dominant {
        let (eye, w) = d
            .split_once(':')
            .with_context(|| format!("--dominant '{d}': expected left:W or right:W"))?;
        let eye = match eye {
            "left" => Eye::Left,
            "right" => Eye::Right,
            _ => bail!("--dominant '{d}': eye must be left or right"),
        };
        params.dominant = Some((eye, w.parse().with_context(|| format!("--dominant '{d}': weight"))?));
    }
    params.validate()?;
    let decode = DepthDecode {
        scale: a.depth_scale,
        ..Default::default()
    };
    let eye = |rgb: &Path, depth: &Path, cam: &viewsynth::cyclopean::camera_file::EyeCameras| -> Result<EyeInput> {
        // Sizes and the pixel budget from the headers before either file is decoded.
        io::check_rgbd_sizes(rgb, depth)?;
        Ok(EyeInput {
            color: io::load_rgb(rgb)?,
            depth: io::load_depth(depth, &decode)?,
            view: cam.view,
            proj: cam.proj,
        })
    };
    let frame = StereoFrame {
        left: eye(&a.left_rgb, &a.left_depth, &cams.left)?,
        right: eye(&a.right_rgb, &a.right_depth, &cams.right)?,
        depth_kind: cams.depth_kind,
        conv: cams.conventions,
    };
    frame.validate()?;
    let out_dir = prepare_out_dir(&a.out_dir)?;
    let gpu = a.gpu.open()?;
    let wanted = CyclopeanOutputs {
        color: outputs.rgb,
        depth: outputs.depth,
    };
    let (out, timing) = CyclopeanRenderer::with_outputs(&gpu, &frame, params, wanted)?.render(&mid)?;
    let mask = io::Mask::new(
        mid.width,
        mid.height,
        out.sources.iter().map(|s| (*s != 0) as u8).collect(),
    )?;
    let mut jobs: Vec<WriteJob> = Vec::new();
    if let Some(color) = &out.color {
        jobs.push((
            "middle_rgb.png".into(),
            Box::new(move |p: &Path| io::save_rgb(p, color)),
        ));
    }
    if let Some(depth) = &out.depth {
        jobs.push((
            "middle_depth.exr".into(),
            Box::new(move |p: &Path| io::save_depth_exr(p, depth)),
        ));
    }
    if outputs.mask {
        jobs.push((
            "middle_mask.png".into(),
            Box::new(|p: &Path| io::save_mask_png(p, &mask)),
        ));
    }
    let written = write_all_or_none(&out_dir, jobs)?;
    let valid = out.sources.iter().filter(|s| **s != 0).count();
    println!(
        "middle view {}x{}: fixation {:.3} m, {:.1} % valid, render {:.1} ms; wrote {} in {}",
        mid.width,
        mid.height,
        fixation,
        valid as f64 / out.sources.len() as f64 * 100.0,
        timing.wall_ms,
        file_names(&written),
        a.out_dir.display()
    );
    Ok(())
}
