//! The trust pass (issue 48: the semi-global matcher's disparities split into matched and
//! inferred) against its twin on both executors.
//!
//! Bounds, from the numerics: the rule compares integer grey levels and one f32 difference and
//! copies a disparity, so the GPU's map must be the twin's bit for bit (no pixel excused).

use viewsynth::io::{load_rgb, DepthMap, RgbImage};
use viewsynth::pass::Device;
use viewsynth::stereo::matcher::{estimate_disparities, estimate_disparities_sgm};
use viewsynth::stereo::trust::Trust;
use viewsynth::stereo::trust_reference::trust_reference;
use viewsynth_tests::{data_dir, gpu};

/// Cones' left eye: its colour, the semi-global twin's disparities and the census twin's.
fn cones_left() -> (RgbImage, DepthMap, DepthMap) {
    let dir = data_dir().join("middlebury2003_cones");
    let (l, r) = (
        load_rgb(&dir.join("im2.png")).unwrap(),
        load_rgb(&dir.join("im6.png")).unwrap(),
    );
    let (semi_global, _) = estimate_disparities_sgm(&l, &r, 64).unwrap();
    let (census, _) = estimate_disparities(&l, &r, 64).unwrap();
    (l, semi_global, census)
}

fn check(eye: (RgbImage, DepthMap, DepthMap), device: &Device, what: &str) {
    let (color, semi_global, census) = eye;
    let gpu_out = Trust::new(device)
        .unwrap()
        .matched(&semi_global, &census, &color)
        .unwrap();
    let twin = trust_reference(&semi_global, &census, &color).unwrap();
    let differ = (0..twin.data.len())
        .filter(|&i| gpu_out.data[i].to_bits() != twin.data[i].to_bits())
        .count();
    assert_eq!(differ, 0, "{what}: {differ} disparities differ from the twin's");
    // Both kinds occur, and of the flat-window kind too (census unknown, matched).
    let known = |d: &DepthMap, i: usize| d.data[i] > 0.0;
    let n = twin.data.len();
    let matched = (0..n).filter(|&i| known(&twin, i)).count();
    let inferred = (0..n).filter(|&i| known(&semi_global, i) && !known(&twin, i)).count();
    let flat = (0..n).filter(|&i| known(&twin, i) && !known(&census, i)).count();
    println!("{what}: {matched} matched ({flat} in flat windows), {inferred} inferred, the twin's bit for bit");
    assert!(
        matched > n / 2 && inferred > 100 && flat > 0,
        "{what}: {matched} / {inferred} / {flat}"
    );
}

#[test]
fn trust_pass_matches_its_twin_on_gl() {
    let eye = cones_left();
    check(eye, &Device::gl(&gpu()).unwrap(), "GL");
}

#[cfg(feature = "vulkan")]
#[test]
fn trust_pass_matches_its_twin_on_vulkan() {
    let eye = cones_left();
    let device = viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap();
    check(eye, &device, "Vulkan");
}
