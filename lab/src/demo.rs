//! `viewsynth demo`: the built-in scene end to end. Renders the source RGB-D view, refocuses it
//! at five focal scales with both GPU paths, writes every output, and reports each against the
//! exact ray-traced target view and against the f64 reference, next to its run time.

use crate::report::WrittenReport;
use std::fmt::Write as _;
use std::path::Path;
use viewsynth::convention::Conventions;
use viewsynth::error::{Error, Result};
use viewsynth::metrics;
use viewsynth::output::FileFormats;
use viewsynth::pass::Device;
use viewsynth::refocus::manifest as job;
use viewsynth::refocus::{reference, BreakRule, Method, OutputSet, RefocusSource, Refocuser};
use viewsynth::{io, world};

/// The focal scales the demo refocuses at.
pub const DEMO_SCALES: [f64; 5] = viewsynth::refocus::manifest::DEFAULT_SCALES;

/// Run the demo into `out_dir`; returns the report, its files and, last, refocus_check.md.
pub fn run(device: &Device, out_dir: &Path) -> Result<WrittenReport> {
    run_with_progress(device, out_dir, &crate::progress::Silent)
}

/// [`run`] with each stage reported to `progress` as it starts: the two refocus methods, the
/// cyclopean, reprojection and stitching outputs, then the report's stages.
pub fn run_with_progress(
    device: &Device,
    out_dir: &Path,
    progress: &dyn crate::progress::Progress,
) -> Result<WrittenReport> {
    let stages = crate::progress::Stages::new(progress, 5 + crate::eval::report_stage_count(None, &[]));
    // Subfolders through OutDir::subdir: a symlinked one is refused, never written through.
    // All of them first, so a refused one fails the run before any rendering.
    let out = io::OutDir::prepare(out_dir)?;
    let sub = |name: &str| out.subdir(name).map(|d| d.path().to_path_buf());
    let (cyclopean_dir, reproject_dir, stitch_dir) = (sub("cyclopean")?, sub("reproject")?, sub("stitch")?);
    let method_dirs = [sub("fullscreen")?, sub("mesh")?];
    let cam = world::demo_camera(640, 480);
    let (rgb, depth) = world::render(&cam);
    io::save_rgb(&out_dir.join("source_rgb.png"), &rgb)?;
    io::save_depth_exr(&out_dir.join("source_depth.exr"), &depth)?;
    let src = RefocusSource::new(rgb, depth, cam.k)?;
    let rule = BreakRule::default();
    let outputs = OutputSet::default();
    let targets = job::TargetSpec {
        scales: DEMO_SCALES.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&cam)?;

    let mut table = String::from(
        "| method | scale | coverage % | PSNR vs scene (dB) | depth MAE vs scene (mm) | PSNR vs f64 ref (dB) | max depth err vs ref (m) | mask IoU vs ref | render ms (wall) |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for (method, dir) in [Method::Fullscreen, Method::Mesh].into_iter().zip(method_dirs) {
        let name = match method {
            Method::Mesh => "mesh",
            Method::Fullscreen => "fullscreen",
        };
        stages.start(&format!("demo: refocus ({name}) at {} scales", DEMO_SCALES.len()));
        let mut r = Refocuser::new(device, &src, &rule, method, outputs, Conventions::default())?;
        for (scale, target) in DEMO_SCALES.iter().zip(&targets) {
            let out = r.render(target)?;
            job::write_output(
                &dir,
                *scale,
                &out,
                &FileFormats {
                    outputs,
                    ..Default::default()
                },
            )?;
            let (gt_rgb, gt_depth) = world::render(target);
            let mask: Vec<bool> = out
                .mask
                .as_ref()
                .map(|m| m.data.iter().map(|v| *v != 0).collect())
                .unwrap_or_default();
            let rgb = &out.rgb.as_ref().expect("rgb requested").data;
            let z = &out.depth.as_ref().expect("depth requested").data;
            // Against the scene: pixels our output covers and the scene has a surface at.
            let (mut sq, mut n, mut dz) = (0.0, 0usize, 0.0);
            for i in 0..mask.len() {
                if mask[i] && gt_depth.data[i] > 0.0 {
                    n += 1;
                    for c in 0..3 {
                        let d = rgb[i * 3 + c] as f64 - gt_rgb.data[i * 3 + c] as f64;
                        sq += d * d;
                    }
                    dz += (z[i] as f64 - gt_depth.data[i] as f64).abs();
                }
            }
            let reference = reference::refocus_reference(&src, &rule, target);
            let a = metrics::agreement(
                Some(rgb),
                Some(z),
                &mask,
                &reference.rgb,
                &reference.depth,
                &reference.mask,
            );
            let coverage = viewsynth::metrics::valid_fraction(&mask, |m| *m);
            writeln!(
                table,
                "| {name} | {scale} | {:.1} | {:.2} | {:.2} | {:.1} | {:.2e} | {:.5} | {:.1} |",
                coverage * 100.0,
                metrics::psnr_from_mse(sq / (3 * n.max(1)) as f64),
                dz / n.max(1) as f64 * 1e3,
                a.psnr_db,
                a.max_abs_depth,
                a.mask_iou,
                out.render.wall_ms
            )
            .expect("write to String");
        }
    }
    let report = format!(
        "# viewsynth demo: refocus of the built-in scene\n\nRenderer: {}\n\n{table}\n\
         PSNR vs scene measures the method (resampling a 640x480 source cannot recreate detail a \
         longer lens would see); PSNR/IoU vs the f64 reference measure the GPU implementation.\n",
        device.renderer()
    ) + "\nGL against Vulkan on these passes and every other: gl_vs_vulkan.md.\n";
    let path = out_dir.join("refocus_check.md");
    io::atomic_write(&path, |w| {
        use std::io::Write;
        w.write_all(report.as_bytes()).map_err(|e| Error::io(&path, e))
    })?;
    stages.start("demo: cyclopean middle views");
    cyclopean_outputs(device, &cyclopean_dir)?;
    stages.start("demo: reprojection left -> right");
    reproject_outputs(device, &reproject_dir)?;
    stages.start("demo: stitched stereo panoramas");
    stitch_outputs(device, &stitch_dir)?;
    let mut written = crate::eval::report_stages(device, out_dir, None, &[], &[], 3, &stages)?;
    written.files.push(path);
    Ok(written)
}

/// The built-in stereo pair (64 mm IPD, device depth, GL conventions), its ray-traced middle
/// view, and the middle view of each cyclopean method.
fn cyclopean_outputs(device: &Device, dir: &Path) -> Result<()> {
    use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
    use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
    use viewsynth::stereo::FrameDepth;
    let rig = StereoRig::demo(640, 480);
    let (frame, mid, truth) = scene_frame(&rig, Conventions::default(), FrameDepth::Device);
    io::save_rgb(&dir.join("left_rgb.png"), &frame.left.color)?;
    io::save_rgb(&dir.join("right_rgb.png"), &frame.right.color)?;
    io::save_depth_exr(&dir.join("left_device_depth.exr"), &frame.left.depth)?;
    io::save_depth_exr(&dir.join("right_device_depth.exr"), &frame.right.depth)?;
    io::save_rgb(&dir.join("middle_truth_rgb.png"), &truth.color)?;
    let mut outputs = Vec::new();
    for (name, params) in crate::eval::cyclopean::cyclopean_methods(3.0) {
        outputs.push((name, CyclopeanRenderer::new(device, &frame, params)?.render(&mid)?.0));
    }
    let mut warp =
        viewsynth::cyclopean::forward::ForwardWarp::new(device, &frame, &viewsynth::refocus::BreakRule::default())?;
    outputs.push((crate::eval::cyclopean::FORWARD_NAME, warp.render(&mid)?.0));
    for (name, out) in outputs {
        let stem: String = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        let stem = stem.split('_').filter(|s| !s.is_empty()).collect::<Vec<_>>().join("_");
        io::save_rgb(&dir.join(format!("middle_{stem}_rgb.png")), out.color()?)?;
        io::save_depth_exr(&dir.join(format!("middle_{stem}_depth.exr")), out.depth()?)?;
        let mask = io::Mask::new(
            mid.width,
            mid.height,
            out.sources.iter().map(|s| (*s != 0) as u8).collect(),
        )?;
        io::save_mask_png(&dir.join(format!("middle_{stem}_mask.png")), &mask)?;
    }
    Ok(())
}

/// Left eye -> right eye of the built-in stereo pair with each reprojection method, beside the
/// ray-traced right eye.
fn reproject_outputs(device: &Device, dir: &Path) -> Result<()> {
    use crate::eval::reproject::scene_cases;
    use viewsynth::reproject::render::Reprojector;
    use viewsynth::reproject::{Method, ReprojectParams};
    let case = scene_cases(
        640,
        480,
        0.064,
        Conventions::default(),
        viewsynth::stereo::FrameDepth::Device,
    )?
    .into_iter()
    .next()
    .ok_or_else(|| Error::param("reproject demo", "no scene case"))?;
    io::save_rgb(&dir.join("right_truth_rgb.png"), &case.truth)?;
    for (name, method) in [
        ("shift_walk", Method::Shift { steps: 3 }),
        ("shift_scan", Method::ShiftScan),
        ("gather3d", Method::Gather3d { steps: 3 }),
    ] {
        let (out, _) =
            Reprojector::new(device, &case.source, &case.geometry, ReprojectParams::new(method))?.render()?;
        let (color, depth) = (
            out.color.as_ref().expect("colour requested"),
            out.depth.as_ref().expect("depth requested"),
        );
        io::save_rgb(&dir.join(format!("right_{name}_rgb.png")), color)?;
        io::save_depth_exr(&dir.join(format!("right_{name}_depth.exr")), depth)?;
        let mask = io::Mask::new(
            color.width,
            color.height,
            out.mask.iter().map(|m| (*m != 0) as u8).collect(),
        )?;
        io::save_mask_png(&dir.join(format!("right_{name}_mask.png")), &mask)?;
    }
    Ok(())
}

/// Top-bottom stereo equirect (left eye on top) of the built-in scene from 6 over-wide faces
/// per eye, with each stitching method.
fn stitch_outputs(device: &Device, dir: &Path) -> Result<()> {
    use viewsynth::stitch::faces::scene_faces;
    use viewsynth::stitch::render::StitchRenderer;
    use viewsynth::stitch::{Method, OdsRig, Side, StitchParams};
    let rig = OdsRig::demo();
    let overlap = 10.0;
    let (left, right) = (
        scene_faces(&rig, Side::Left, 256, 90.0 + 2.0 * overlap)?,
        scene_faces(&rig, Side::Right, 256, 90.0 + 2.0 * overlap)?,
    );
    let mut r = StitchRenderer::new(device, &left, &right)?;
    for method in Method::ALL {
        let (img, _) = r.render(&StitchParams {
            method,
            overlap_deg: overlap,
            width: 1024,
            height: 512,
        })?;
        let stem: String = method
            .label()
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        io::save_rgb(&dir.join(format!("ods_{stem}_top_bottom.png")), &img)?;
    }
    Ok(())
}
