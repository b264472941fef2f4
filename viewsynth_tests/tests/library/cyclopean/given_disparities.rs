//! Given disparities made dense before rendering (issue 48 item 3): a hole in a given map (ground
//! truth's unknown pixels, a sensor's dropouts) is densified like the matcher's, so the view
//! renders it from geometry; only true disocclusions reach the colour fill. The densify pass on
//! given disparities against its twin on both executors, bit for bit as for the matcher's maps.

use viewsynth::cyclopean::pipeline::{InputName, StereoInput, StereoKind};
use viewsynth::io::{load_depth_with_key, load_rgb, DepthMap, RgbImage, MASK_FILLED};
use viewsynth::job::cyclopean::CyclopeanRequest;
use viewsynth::pass::Device;
use viewsynth::stereo::densify::{Densifier, OtherEye, FILLED};
use viewsynth::stereo::densify_reference::densify_reference;
use viewsynth_tests::{data_dir, gpu};

/// A textured plane at disparity 4 (texture `t(x, y)` in the middle view's columns): the middle
/// view is `t`, the left image `t(x - 2)`, the right `t(x + 2)`. Both maps are 4 but for a square
/// hole that covers the same middle pixels from either eye (middle columns 18..26, rows 8..16),
/// which no eye's known disparity reaches: without densify it is the 2-D fill's.
const W: u32 = 48;
const H: u32 = 24;
const HOLE_ROWS: std::ops::Range<u32> = 8..16;
const HOLE_MIDDLE: std::ops::Range<i64> = 18..26;

/// Levels that change from pixel to pixel (a fill from the sides cannot guess them).
fn texture(x: i64, y: u32) -> [u8; 3] {
    let h = (x.wrapping_mul(73_856_093) ^ i64::from(y).wrapping_mul(19_349_663)) as u64;
    let h = h.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    [(h >> 40) as u8, (h >> 48) as u8, (h >> 56) as u8]
}

fn image(shift: i64) -> RgbImage {
    let data = (0..H)
        .flat_map(|y| (0..W as i64).flat_map(move |x| texture(x + shift, y)))
        .collect();
    RgbImage::new(W, H, data).unwrap()
}

/// The map of an eye whose pixel x shows middle column x + `to_middle`: 4, 0 in the hole.
fn disparity(to_middle: i64) -> DepthMap {
    let data = (0..H)
        .flat_map(|y| {
            (0..W as i64).map(
                move |x| match HOLE_ROWS.contains(&y) && HOLE_MIDDLE.contains(&(x + to_middle)) {
                    true => 0.0,
                    false => 4.0,
                },
            )
        })
        .collect();
    DepthMap::new(W, H, data).unwrap()
}

#[test]
fn a_hole_in_given_disparities_is_densified_not_filled() {
    let device = Device::gl(&gpu()).unwrap();
    let plan = CyclopeanRequest {
        fill: true,
        ..Default::default()
    }
    .plan(StereoKind::Disparity)
    .unwrap();
    // Left pixel x shows middle x - 2, right pixel x middle x + 2.
    let input = StereoInput::Disparity {
        left: (image(-2), disparity(-2)),
        right: (image(2), disparity(2)),
    };
    let names = ["left_rgb", "right_rgb", "left_disparity", "cameras"].map(InputName::Argument);
    let framed = plan.frame(&device, input, names, None).unwrap();
    assert!(framed.dense.is_some(), "--fill densifies given disparities");
    let done = plan
        .synthesise(
            &device,
            &framed.frame,
            &framed.mid,
            framed.fixation,
            framed.dense.as_ref(),
            None,
        )
        .unwrap();
    let (color, mask) = (done.view.color.unwrap(), done.view.mask.unwrap());
    let truth = image(0);
    let (mut worst, mut hole) = (0u8, 0);
    for y in HOLE_ROWS {
        for x in HOLE_MIDDLE {
            let i = (y * W) as usize + x as usize;
            hole += 1;
            assert_eq!(
                mask.data[i], MASK_FILLED,
                "({x}, {y}): densified pixels are not 'rendered'"
            );
            for c in 0..3 {
                worst = worst.max(color.data[3 * i + c].abs_diff(truth.data[3 * i + c]));
            }
        }
    }
    // The fill would average the sides' random levels (off by tens of levels); the plane's own
    // geometry shifts the texture by whole pixels: exact but for rounding.
    assert!(
        worst <= 1,
        "the hole's {hole} pixels are off by up to {worst} levels: filled, not rendered"
    );
    // Away from the hole every pixel is rendered from a given disparity.
    let given = (0..(W * H) as usize)
        .filter(|i| {
            let (x, y) = ((i % W as usize) as i64, (i / W as usize) as u32);
            !(HOLE_ROWS.contains(&y) && HOLE_MIDDLE.contains(&x))
        })
        .all(|i| mask.data[i] == 1);
    assert!(given, "pixels of given disparities stay 255 in the mask");
    assert!((done.coverage - 1.0 + (hole as f64) / f64::from(W * H)).abs() < 1e-9);
}

/// Cones' left image and its ground-truth disparity (3.2 % unknown: occlusions, borders).
fn cones_truth() -> (RgbImage, DepthMap) {
    let dir = data_dir().join("middlebury2003_cones");
    let decode = viewsynth::io::DepthDecode {
        scale: Some(4.0),
        ..Default::default()
    };
    let d = load_depth_with_key(&dir.join("disp2.pgm"), None, &decode).unwrap();
    (load_rgb(&dir.join("im2.png")).unwrap(), d)
}

fn check(eye: (RgbImage, DepthMap), device: &Device, what: &str) {
    let (color, disparity) = eye;
    let unknown = disparity.data.iter().filter(|v| **v <= 0.0).count();
    assert!(
        unknown * 50 > disparity.data.len(),
        "{what}: the ground truth has holes ({unknown})"
    );
    let gpu_out = Densifier::new(device)
        .unwrap()
        .densify(&disparity, &color, OtherEye::LEFT)
        .unwrap();
    let twin = densify_reference(&disparity, &color, OtherEye::LEFT).unwrap();
    assert_eq!(gpu_out.filled, twin.filled, "{what}: filled flags differ");
    let differ = (0..twin.filled.len())
        .filter(|&i| gpu_out.disparity.data[i].to_bits() != twin.disparity.data[i].to_bits())
        .count();
    assert_eq!(differ, 0, "{what}: disparities differ from the twin's");
    let filled = twin.filled.iter().filter(|f| **f == FILLED).count();
    assert_eq!(
        filled, unknown,
        "{what}: every unknown ground-truth disparity is filled"
    );
}

#[test]
fn densify_of_ground_truth_matches_its_twin_on_gl() {
    let eye = cones_truth();
    check(eye, &Device::gl(&gpu()).unwrap(), "GL");
}

#[cfg(feature = "vulkan")]
#[test]
fn densify_of_ground_truth_matches_its_twin_on_vulkan() {
    let eye = cones_truth();
    let device = viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap();
    check(eye, &device, "Vulkan");
}
