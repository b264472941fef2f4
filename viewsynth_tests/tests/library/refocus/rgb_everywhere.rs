//! `--rgb-everywhere`: colour at every target pixel inside the source frame, mask and depth
//! unchanged.
//!
//! Bounds, from the numerics:
//! - mask and depth: the option only adds a colour write (the full-screen pass, before the
//!   coverage test) or a colour draw at the far depth before the mesh draws (which pass the depth
//!   test over it and write what they wrote before), so both are bit-identical to a render
//!   without it, on every backend and convention.
//! - colour: the same f32 bilinear over the same gathered texels as the covered pixels, whose
//!   bound `refocus_accuracy` derives: within one level of the f64 twin's exact value, with
//!   either neighbour of a rounding tie counted right ([`metrics::quantization_error`]). Which
//!   pixels are inside the frame is decided in f64 by the same span on both sides
//!   ([`viewsynth::refocus::frame_span`]), so outside it both are exactly 0.

use viewsynth::camera::PinholeCamera;
use viewsynth::convention::Conventions;
use viewsynth::metrics;
use viewsynth::pass::Device;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::reference::{bilinear_rgb, refocus_reference_with, ReferenceImage};
use viewsynth::refocus::{source_point, BreakRule, Method, OutputSet, RefocusOutput, RefocusSource, Refocuser};
use viewsynth_tests::*;

const SCALES: [f64; 3] = [0.5, 1.0, 2.0];

fn targets(src: &RefocusSource) -> Vec<PinholeCamera> {
    TargetSpec {
        scales: SCALES.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&src.camera())
    .unwrap()
}

/// Largest level difference of `out`'s colour from the twin's exact colour, over every pixel.
fn worst_colour(out: &RefocusOutput, twin: &ReferenceImage) -> u32 {
    let c = &out.rgb.as_ref().unwrap().data;
    twin.rgb
        .iter()
        .enumerate()
        .flat_map(|(i, px)| (0..3).map(move |k| (i * 3 + k, px[k])))
        .map(|(o, exact)| metrics::quantization_error(c[o], exact))
        .max()
        .unwrap_or(0)
}

/// On `device`, under every convention and both methods: with the option, mask and depth are
/// bit-identical to the render without it, covered colour too, and every pixel's colour is
/// within one level of the twin's (which is 0 outside the frame).
fn matches_the_twin_on(api: &str, device: &Device) {
    for (name, src) in [("TUM", real_frame("TUM")), ("synthetic", synthetic(160, 120))] {
        let targets = targets(&src);
        let twins: Vec<ReferenceImage> = targets
            .iter()
            .map(|t| refocus_reference_with(&src, &BreakRule::default(), t, true))
            .collect();
        for method in [Method::Fullscreen, Method::Mesh] {
            for conv in Conventions::all() {
                let rule = BreakRule::default();
                let mut plain = Refocuser::new(device, &src, &rule, method, OutputSet::default(), conv).unwrap();
                let mut every = Refocuser::new(device, &src, &rule, method, OutputSet::default(), conv).unwrap();
                every.set_rgb_everywhere(true);
                for ((s, t), twin) in SCALES.iter().zip(&targets).zip(&twins) {
                    let tag = format!("{api} {name} {method:?} {} s{s}", conv.label());
                    let (a, b) = (plain.render(t).unwrap(), every.render(t).unwrap());
                    let (ma, mb) = (&a.mask.as_ref().unwrap().data, &b.mask.as_ref().unwrap().data);
                    assert_eq!(ma, mb, "{tag}: mask changed");
                    let bits = |o: &RefocusOutput| -> Vec<u32> {
                        o.depth.as_ref().unwrap().data.iter().map(|z| z.to_bits()).collect()
                    };
                    assert_eq!(bits(&a), bits(&b), "{tag}: depth changed");
                    let (ca, cb) = (&a.rgb.as_ref().unwrap().data, &b.rgb.as_ref().unwrap().data);
                    let covered_differs =
                        (0..ma.len()).filter(|&i| ma[i] != 0 && ca[3 * i..3 * i + 3] != cb[3 * i..3 * i + 3]);
                    assert_eq!(covered_differs.count(), 0, "{tag}: covered colour changed");
                    let worst = worst_colour(&b, twin);
                    assert!(worst <= 1, "{tag}: colour {worst} levels from the f64 twin");
                    let outside =
                        (0..ma.len()).filter(|&i| twin.rgb[i] == [0.0; 3] && cb[3 * i..3 * i + 3] != [0, 0, 0]);
                    assert_eq!(outside.count(), 0, "{tag}: colour outside the frame");
                }
            }
        }
    }
}

#[test]
fn rgb_everywhere_matches_the_twin_and_keeps_mask_and_depth_under_every_convention_on_gl() {
    matches_the_twin_on("GL", &Device::gl(&gpu()).unwrap());
}

#[cfg(feature = "vulkan")]
#[test]
fn rgb_everywhere_matches_the_twin_and_keeps_mask_and_depth_under_every_convention_on_vulkan() {
    let v = viewsynth_tests::vulkan();
    matches_the_twin_on("Vulkan", &viewsynth::vulkan::VkExecutor::device(&v).unwrap());
}

#[test]
fn the_twin_colours_the_frame_and_nothing_else() {
    // A step the break rule cuts: without the option the cut cells are black; with it, every
    // pixel whose source point is inside the frame has the bilinear colour, and depth and mask
    // are the same.
    let src = synthetic(64, 48);
    let mut wide = src.camera();
    wide.k.fx *= 0.5;
    wide.k.fy *= 0.5;
    let rule = BreakRule::default();
    let (a, b) = (
        refocus_reference_with(&src, &rule, &wide, false),
        refocus_reference_with(&src, &rule, &wide, true),
    );
    assert_eq!(a.mask, b.mask);
    assert_eq!(a.depth, b.depth);
    let span = |n: u32| viewsynth::refocus::frame_span(n);
    let (su, sv) = (span(src.rgb.width), span(src.rgb.height));
    let mut inside = 0;
    for y in 0..wide.height {
        for x in 0..wide.width {
            let i = (y * wide.width + x) as usize;
            let [u, v] = source_point(&src.k, &wide.k, x as f64, y as f64);
            if (su.0..=su.1).contains(&u) && (sv.0..=sv.1).contains(&v) {
                inside += 1;
                assert_eq!(b.rgb[i], bilinear_rgb(&src, u, v), "pixel {x},{y}");
            } else {
                assert_eq!(b.rgb[i], [0.0; 3], "pixel {x},{y} outside the frame");
            }
        }
    }
    // At s = 0.5 the frame is the middle half: about a quarter of the pixels.
    assert!(inside > 600 && inside < 900, "{inside} inside");
    assert!(a.mask.iter().filter(|m| **m).count() < inside);
}
