//! `viewsynth scene`: ray-trace a ground-truth stereo frame and write it with its cameras.json.

use super::*;

pub(crate) fn render_scene(
    name: &str,
    width: u32,
    height: u32,
    ipd: f64,
    conv: Conventions,
    out_dir: &Path,
    gpu: &GpuArgs,
) -> Result<()> {
    use viewsynth::camera::gl_projection;
    use viewsynth::cyclopean::scene_frame::StereoRig;
    use viewsynth::scene::gpu::{GlCamera, SceneRenderer};
    use viewsynth::scene::{builtin, Scene};
    let scene = if Path::new(name).extension().is_some_and(|e| e == "json") {
        Scene::load(Path::new(name))?
    } else {
        builtin(name)?
    };
    if !(ipd.is_finite() && ipd >= 0.0) {
        bail!("invalid ipd {ipd}: must be finite and >= 0");
    }
    io::check_output_pixels("--width/--height", width, height)?;
    let mut rig = StereoRig::demo(width, height);
    rig.camera.validate("scene camera")?;
    rig.ipd = ipd;
    let out = prepare_out_dir(out_dir)?;
    // Every file or none: a failing rerun leaves the previous scene intact.
    let mut set = out.file_set()?;
    let staged = set.staging().to_path_buf();
    let gpu = gpu.open()?;
    let mut renderer = SceneRenderer::new(&gpu, &scene)?;
    let proj = gl_projection(&rig.camera, &rig.planes, &conv);
    let mut cams = serde_json::Map::new();
    for (eye, side) in [("left", -1.0), ("right", 1.0), ("middle", 0.0)] {
        let view = rig.eye_pose(side).gl_view();
        let (img, timing) = renderer.render(&GlCamera {
            view,
            proj,
            width,
            height,
            conv,
        })?;
        let saved = io::save_rgb(&staged.join(format!("{eye}_rgb.png")), &img.color)
            .and_then(|()| io::save_depth_exr(&staged.join(format!("{eye}_view_z.exr")), &img.view_z))
            .and_then(|()| io::save_depth_exr(&staged.join(format!("{eye}_device_depth.exr")), &img.device_depth));
        saved.map_err(|e| set.final_error(e))?;
        let entry = if eye == "middle" {
            serde_json::json!({ "view": view, "proj": proj, "width": width, "height": height })
        } else {
            serde_json::json!({ "view": view, "proj": proj })
        };
        cams.insert(eye.to_string(), entry);
        println!("{eye}: {width}x{height} in {:.1} ms", timing.wall_ms);
    }
    cams.insert("conventions".into(), serde_json::to_value(conv)?);
    cams.insert("depth_kind".into(), "device".into());
    cams.insert("fixation_distance".into(), 3.0.into());
    let text = serde_json::to_string_pretty(&cams)?;
    set.write("cameras.json", |w| {
        use std::io::Write;
        w.write_all(text.as_bytes())
            .map_err(|e| viewsynth::Error::io(out_dir.join("cameras.json"), e))
    })?;
    set.commit()?;
    println!(
        "scene '{}' written to {} (cameras.json feeds `viewsynth cyclopean`)",
        scene.name,
        out_dir.display()
    );
    Ok(())
}
