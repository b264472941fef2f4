//! `viewsynth cyclopean` on files written from the built-in scene renders the library's middle
//! view (the pass against its twin, with the tolerances derived, is `viewsynth_tests`'
//! `cyclopean::gather`).

use crate::common::{cyclopean_cli, gpu, write_cyclopean_files};
use viewsynth::convention::Conventions;
use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
use viewsynth::stereo::gather::CyclopeanParams;
use viewsynth::stereo::gather::Method;
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;

#[test]
fn cli_renders_the_same_middle_view_as_the_library_from_files() {
    let g = gpu();
    let rig = StereoRig::demo(96, 72);
    let conv = Conventions::all()[5];
    let (frame, mid, _) = scene_frame(&rig, conv, FrameDepth::Device);
    let dir = std::env::temp_dir().join(format!("viewsynth-cyclopean-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cams = write_cyclopean_files(&dir, &frame, &mid);
    // The binary on the files written above, with `cameras` and `--refine-steps 3`.
    let run = |cameras: &str, out: &std::path::Path| cyclopean_cli(&dir, cameras, &["--refine-steps", "3"], out);
    let out = dir.join("out");
    let o = run("cams.json", &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let params = CyclopeanParams {
        method: Method::Refine { steps: 3 },
        ..CyclopeanParams::seed(3.0)
    };
    let (lib, _) = CyclopeanRenderer::new(&g, &frame, params)
        .unwrap()
        .render(&mid)
        .unwrap();
    assert_eq!(
        viewsynth::io::load_rgb(&out.join("middle_rgb.png")).unwrap(),
        *lib.color().unwrap()
    );
    let z = viewsynth::io::load_depth(&out.join("middle_depth.exr"), &Default::default()).unwrap();
    assert_eq!(z, *lib.depth().unwrap());

    // Only the mask asked for: only the mask written, the same as the full run's.
    let only_mask = dir.join("only-mask");
    let o = cyclopean_cli(
        &dir,
        "cams.json",
        &["--refine-steps", "3", "--outputs", "mask"],
        &only_mask,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // (beside the hidden record of the run's set, which `files_in` leaves out)
    assert_eq!(crate::cli::files_in(&only_mask), ["middle_mask.png"]);
    assert_eq!(
        std::fs::read(only_mask.join("middle_mask.png")).unwrap(),
        std::fs::read(out.join("middle_mask.png")).unwrap()
    );

    // A camera file without fixation or gaze: a clear error naming what is missing.
    let mut bad = cams.clone();
    bad.as_object_mut().unwrap().remove("fixation_distance");
    std::fs::write(dir.join("bad.json"), serde_json::to_string(&bad).unwrap()).unwrap();
    let o = run("bad.json", &dir.join("out2"));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("fixation_distance") && !err.contains("panicked"), "{err}");
}
