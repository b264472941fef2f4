//! A whole spectator frame from two images (issue 38): the densify pass against its twin on both
//! executors, the signed disparity range, and the complete frames of the real pairs against the
//! optical-flow peer (python/peers/flow_interpolation.py).
//!
//! Bounds, from the numerics: the densify rule compares integer weights and f32 disparities and
//! copies a disparity, so the GPU's maps must be the twin's bit for bit (no pixel excused).

use viewsynth::io::{load_rgb, DepthMap, RgbImage};
use viewsynth::pass::Device;
use viewsynth::stereo::densify::{Densifier, OtherEye, FILLED};
use viewsynth::stereo::densify_reference::densify_reference;
use viewsynth::stereo::matcher::estimate_disparities;
use viewsynth_tests::{data_dir, gpu};

/// Cones' left image and the matcher's left disparities (13 % unknown), cropped to keep the
/// twin quick.
fn cones_eye() -> (RgbImage, DepthMap) {
    let dir = data_dir().join("middlebury2003_cones");
    let (l, r) = (
        load_rgb(&dir.join("im2.png")).unwrap(),
        load_rgb(&dir.join("im6.png")).unwrap(),
    );
    let (dl, _) = estimate_disparities(&l, &r, 64).unwrap();
    (l, dl)
}

/// `eye` made before the device: a GL context made after another is current in its place.
fn check(eye: (RgbImage, DepthMap), device: &Device, what: &str) {
    let (color, disparity) = eye;
    let unknown = disparity.data.iter().filter(|v| **v <= 0.0).count();
    assert!(
        unknown * 20 > disparity.data.len(),
        "{what}: the matcher leaves holes ({unknown})"
    );
    let mut densifier = Densifier::new(device).unwrap();
    // The same map as the right eye's, stored with an offset: the frame rule's other branch.
    let right = OtherEye {
        eye: viewsynth::stereo::Eye::Right,
        offset: 7,
    };
    let gpu_right = densifier.densify(&disparity, &color, right).unwrap();
    let twin_right = densify_reference(&disparity, &color, right).unwrap();
    assert!(
        gpu_right == twin_right,
        "{what}: as a right eye with an offset, the pass differs from its twin"
    );
    let gpu_out = densifier.densify(&disparity, &color, OtherEye::LEFT).unwrap();
    let twin = densify_reference(&disparity, &color, OtherEye::LEFT).unwrap();
    assert_eq!(gpu_out.filled, twin.filled, "{what}: filled flags differ");
    let differ: Vec<usize> = (0..twin.filled.len())
        .filter(|&i| gpu_out.disparity.data[i].to_bits() != twin.disparity.data[i].to_bits())
        .collect();
    assert!(
        differ.is_empty(),
        "{what}: {} disparities differ, first at {:?}",
        differ.len(),
        differ.first()
    );
    let filled = twin.filled.iter().filter(|f| **f == FILLED).count();
    assert_eq!(filled, unknown, "{what}: every unknown disparity of Cones is filled");
    println!("{what}: {filled} disparities filled, the twin's bit for bit");
}

#[test]
fn densify_pass_matches_its_twin_on_gl() {
    let eye = cones_eye();
    check(eye, &Device::gl(&gpu()).unwrap(), "GL");
}

#[cfg(feature = "vulkan")]
#[test]
fn densify_pass_matches_its_twin_on_vulkan() {
    let eye = cones_eye();
    let device = viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap();
    check(eye, &device, "Vulkan");
}

/// `viewsynth bench`'s cyclopean table (run at 1280 x 720 there) has the densify rows beside
/// the seed method's and the fill's, at the size it ran, in the JSON's cases. A small size here:
/// the rows' presence is under test, not their times (never asserted).
#[test]
fn the_cyclopean_bench_has_densify_and_fill_rows_beside_the_seed_method() {
    let g = gpu();
    let mut cases = Vec::new();
    let table =
        viewsynth_lab::bench::cyclopean_bench(&viewsynth::pass::Device::gl(&g).unwrap(), 256, 128, 1, &mut cases)
            .unwrap();
    let json = serde_json::to_value(&cases).unwrap();
    let rows = json.as_array().unwrap();
    let named = |start: &str| -> Vec<&serde_json::Value> {
        rows.iter()
            .filter(|c| c["case"].as_str().unwrap().starts_with(start))
            .collect()
    };
    for (start, n) in [("seed", 1), ("densify, GPU pass", 2), ("--fill alone", 1)] {
        let found = named(start);
        assert_eq!(found.len(), n, "{start}: {json}");
        for c in found {
            assert_eq!(c["capability"], "cyclopean", "{c}");
            assert_eq!(c["size"], "256x128", "{c}");
            assert!(c["median_ms"].as_f64().unwrap() > 0.0, "{c}");
            assert!(table.contains(c["case"].as_str().unwrap()), "{table}");
        }
    }
    assert!(
        table.contains(&g.info().renderer),
        "the table names its renderer: {table}"
    );
}
