//! `--fill` (src/cyclopean/fill.rs): the GPU pass against its twin on both executors, and the
//! complete spectator frame on Middlebury Cones.
//!
//! Bounds, from the numerics: which candidates a hole walks to and which form its background
//! layer are comparisons of the same f32 depths on both sides, so the source bits must be
//! identical, and rendered pixels pass through exact. A filled pixel is a 1 / r^2-weighted mean of
//! its layer's texels in f32 on both sides; the GPU's division may be 2.5 ulp off (GLSL) and its
//! UNORM conversion rounds a value within ~1e-5 of a half level by its own rule while the twin
//! rounds half away from zero: one level at most. Depth: the same mean, a few ulp (bound 1e-5
//! relative). A 40-level error in any filled pixel fails.

use viewsynth::convention::Conventions;
use viewsynth::cyclopean::fill::{Filler, FILLED};
use viewsynth::cyclopean::fill_reference::fill_reference;
use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
use viewsynth::pass::Device;
use viewsynth::stereo::gather::CyclopeanOutput;
use viewsynth::stereo::gather::CyclopeanOutputs;
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;
use viewsynth_tests::gpu;

/// The built-in scene's middle view (disocclusions at every object edge) with extra holes: a
/// deterministic scatter of single pixels and runs, so both rules (background side, one surface)
/// and the column fallback (two emptied rows) are exercised.
fn view_with_holes() -> (CyclopeanOutput, u32, u32) {
    let (w, h) = (128, 96);
    let (frame, mid, _) = scene_frame(&StereoRig::demo(w, h), Conventions::default(), FrameDepth::Device);
    let device = Device::gl(&gpu()).unwrap();
    let (mut out, _) = SplatRenderer::new(&device, &frame, SplatParams::default(), CyclopeanOutputs::default())
        .unwrap()
        .render(&mid)
        .unwrap();
    let mut state = 12345u32;
    for i in 0..out.sources.len() {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let row = i / w as usize;
        if state >> 28 == 0 || row == 40 || row == 41 {
            out.sources[i] = 0;
        }
    }
    (out, w, h)
}

/// `view` is made before the device: a GL context made after another is current in its place.
fn check(input: (CyclopeanOutput, u32, u32), device: &Device, what: &str) {
    let (view, w, h) = input;
    let holes = view.sources.iter().filter(|s| **s == 0).count();
    assert!(holes > 900, "{what}: the input must have holes ({holes})");
    let gpu_out = Filler::new(device).unwrap().fill(&view, w, h).unwrap();
    let twin = fill_reference(&view, w, h).unwrap();
    assert_eq!(gpu_out.sources, twin.sources, "{what}: source bits differ");
    let (gc, tc) = (
        &gpu_out.color.as_ref().unwrap().data,
        &twin.color.as_ref().unwrap().data,
    );
    let (gz, tz) = (
        &gpu_out.depth.as_ref().unwrap().data,
        &twin.depth.as_ref().unwrap().data,
    );
    let (mut filled, mut off_by_one) = (0, 0);
    for i in 0..view.sources.len() {
        let d = (0..3)
            .map(|c| (gc[3 * i + c] as i32 - tc[3 * i + c] as i32).abs())
            .max()
            .unwrap();
        if view.sources[i] != 0 {
            assert_eq!(
                (d, gz[i].to_bits()),
                (0, tz[i].to_bits()),
                "{what}: rendered pixel {i} changed"
            );
            continue;
        }
        filled += (twin.sources[i] == FILLED) as usize;
        off_by_one += (d == 1) as usize;
        assert!(d <= 1, "{what}: filled pixel {i} colour differs by {d} levels");
        let rel = (gz[i] - tz[i]).abs() / tz[i].abs().max(f32::MIN_POSITIVE);
        assert!(
            rel <= 1e-5 || gz[i] == tz[i],
            "{what}: filled pixel {i} depth {} vs {}",
            gz[i],
            tz[i]
        );
    }
    assert_eq!(
        filled, holes,
        "{what}: every hole has a valid pixel along one of its 16 directions"
    );
    println!("{what}: {filled} pixels filled, {off_by_one} one level off the twin");
}

#[test]
fn fill_pass_matches_its_twin_on_gl() {
    let view = view_with_holes();
    check(view, &Device::gl(&gpu()).unwrap(), "GL");
}

#[cfg(feature = "vulkan")]
#[test]
fn fill_pass_matches_its_twin_on_vulkan() {
    let view = view_with_holes();
    let device = viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap();
    check(view, &device, "Vulkan");
}
