//! `viewsynth cyclopean --backend vulkan` writes the gather view GL writes, and refuses by name
//! the methods Vulkan does not run (GL against Vulkan per convention, bounds derived, is
//! `viewsynth_tests`' `vulkan::cyclopean`).

use crate::cli::scratch;
use crate::common::vulkan;
use crate::common::{cyclopean_cli, write_cyclopean_files};
use viewsynth::convention::Conventions;
use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
use viewsynth::stereo::gather::CyclopeanParams;
use viewsynth::stereo::gather::Method;
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;
use viewsynth::vulkan::VkExecutor;

/// Derivation above.
const DEPTH_REL_BOUND: f64 = 4e-5;

/// `viewsynth cyclopean --backend vulkan` on files writes the Vulkan library's view, which
/// agrees with the GL run of the same command within the bounds above; splat-gather and forward
/// are refused by name (exit 1, as the binary's other option checks) with nothing written.
#[test]
fn cli_backend_vulkan_writes_the_gather_view() {
    let v = vulkan();
    let rig = StereoRig::demo(96, 72);
    let conv = Conventions::all()[5];
    let (frame, mid, _) = scene_frame(&rig, conv, FrameDepth::Device);
    let dir = scratch("vulkan-cyclopean-cli");
    write_cyclopean_files(&dir, &frame, &mid);
    let run = |extra: &[&str], out: &std::path::Path| cyclopean_cli(&dir, "cams.json", extra, out);
    let vk_out = dir.join("vulkan");
    let o = run(
        &["--backend", "vulkan", "--method", "refine", "--refine-steps", "3"],
        &vk_out,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let params = CyclopeanParams {
        method: Method::Refine { steps: 3 },
        ..CyclopeanParams::seed(3.0)
    };
    let (lib, _) = CyclopeanRenderer::new(&VkExecutor::device(&v).unwrap(), &frame, params)
        .unwrap()
        .render(&mid)
        .unwrap();
    let rgb = viewsynth::io::load_rgb(&vk_out.join("middle_rgb.png")).unwrap();
    assert_eq!(rgb, *lib.color().unwrap());
    let z = viewsynth::io::load_depth(&vk_out.join("middle_depth.exr"), &Default::default()).unwrap();
    assert_eq!(z, *lib.depth().unwrap());

    // The GL run of the same command: same mask file, colour and depth within the bounds.
    let gl_out = dir.join("gl");
    let o = run(&["--method", "refine", "--refine-steps", "3"], &gl_out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(gl_out.join("middle_mask.png")).unwrap(),
        std::fs::read(vk_out.join("middle_mask.png")).unwrap()
    );
    let gl_rgb = viewsynth::io::load_rgb(&gl_out.join("middle_rgb.png")).unwrap();
    let worst = gl_rgb
        .data
        .iter()
        .zip(&rgb.data)
        .map(|(a, b)| (*a as i32 - *b as i32).abs())
        .max()
        .unwrap();
    assert!(worst <= 1, "colour differs by {worst} levels");
    let gl_z = viewsynth::io::load_depth(&gl_out.join("middle_depth.exr"), &Default::default()).unwrap();
    for (a, b) in gl_z.data.iter().zip(&z.data) {
        if *a > 0.0 {
            let rel = (*a as f64 - *b as f64).abs() / *a as f64;
            assert!(rel <= DEPTH_REL_BOUND, "depth {a} vs {b}");
        } else {
            assert_eq!(*b, 0.0);
        }
    }
}
