//! The checked semi-global matcher (issue 48: the semi-global disparities split into matched
//! and inferred, the census matcher's stages and the trust stage in the same run) against the
//! twins on both executors.
//!
//! Bounds, from the numerics: the matchers' stages are exact (integers, single correctly rounded
//! f32 operations; stereo::matcher), and the trust rule compares integer grey levels and one f32
//! difference and copies a disparity, so every map must be the twins' bit for bit (no pixel
//! excused).

use viewsynth::io::{load_rgb, DepthMap, RgbImage};
use viewsynth::pass::Device;
use viewsynth::stereo::matcher::{estimate_disparities, estimate_disparities_sgm, Matcher, MatcherMethod};
use viewsynth::stereo::trust::census_checked;
use viewsynth::stereo::trust_reference::trust_reference;
use viewsynth_tests::{data_dir, gpu};

fn cones() -> (RgbImage, RgbImage) {
    let dir = data_dir().join("middlebury2003_cones");
    (
        load_rgb(&dir.join("im2.png")).unwrap(),
        load_rgb(&dir.join("im6.png")).unwrap(),
    )
}

fn differing(a: &DepthMap, b: &DepthMap) -> usize {
    assert_eq!(a.data.len(), b.data.len());
    (0..a.data.len())
        .filter(|&i| a.data[i].to_bits() != b.data[i].to_bits())
        .count()
}

/// One checked run over 0..=`max_disparity` against the twins: the semi-global twin's
/// disparities, the trust twin's matched ones (on the census twin's disparities, or on none past
/// the census check's bound) and the unchecked matcher's confidence.
fn check(device: &Device, max_disparity: u32, what: &str) {
    let (l, r) = cones();
    let mut matcher = Matcher::checked(device, l.width, l.height, max_disparity).unwrap();
    let out = matcher.estimate_checked(&l, &r, true).unwrap();
    let (sl, sr) = estimate_disparities_sgm(&l, &r, max_disparity).unwrap();
    let (cl, cr) = match census_checked(max_disparity) {
        true => estimate_disparities(&l, &r, max_disparity).unwrap(),
        false => {
            let none = || DepthMap::new(l.width, l.height, vec![0.0; sl.data.len()]).unwrap();
            (none(), none())
        }
    };
    let twin = [
        trust_reference(&sl, &cl, &l).unwrap(),
        trust_reference(&sr, &cr, &r).unwrap(),
    ];
    for (eye, (s, m)) in [(&sl, &twin[0]), (&sr, &twin[1])].into_iter().enumerate() {
        let d = differing(&out.disparity[eye], s);
        assert_eq!(
            d, 0,
            "{what}, eye {eye}: {d} semi-global disparities differ from the twin's"
        );
        let d = differing(&out.matched[eye], m);
        assert_eq!(
            d, 0,
            "{what}, eye {eye}: {d} matched disparities differ from the twin's"
        );
    }
    // The census stages leave the semi-global run as it is: its confidence is the unchecked
    // matcher's.
    let mut unchecked = Matcher::with_method(device, l.width, l.height, max_disparity, MatcherMethod::Sgm).unwrap();
    let plain = unchecked.estimate_with_confidence(&l, &r).unwrap();
    // Only a checked matcher splits its disparities.
    assert!(unchecked.estimate_checked(&l, &r, false).is_err());
    let confidence = out.confidence.as_ref().unwrap();
    for eye in 0..2 {
        let d = differing(&confidence[eye], &plain[eye].confidence);
        assert_eq!(
            d, 0,
            "{what}, eye {eye}: {d} confidences differ from the unchecked matcher's"
        );
    }
    // Both kinds occur, and of the flat-window kind too (census unknown, matched).
    let known = |d: &DepthMap, i: usize| d.data[i] > 0.0;
    let n = sl.data.len();
    let matched = (0..n).filter(|&i| known(&twin[0], i)).count();
    let inferred = (0..n).filter(|&i| known(&sl, i) && !known(&twin[0], i)).count();
    let flat = (0..n).filter(|&i| known(&twin[0], i) && !known(&cl, i)).count();
    println!(
        "{what}: left eye {matched} matched ({flat} in flat windows), {inferred} inferred, the twins' bit for bit"
    );
    assert!(flat > 0 && inferred > 100, "{what}: {matched} / {inferred} / {flat}");
    if census_checked(max_disparity) {
        assert!(matched > n / 2, "{what}: {matched} of {n} matched");
    }
}

fn both_searches(device: &Device, api: &str) {
    // Within the census check's bound, and past it (flat windows only).
    check(device, 64, &format!("{api}, search 0-64"));
    check(device, 300, &format!("{api}, search 0-300"));
}

#[test]
fn checked_matcher_matches_the_twins_on_gl() {
    both_searches(&Device::gl(&gpu()).unwrap(), "GL");
}

#[cfg(feature = "vulkan")]
#[test]
fn checked_matcher_matches_the_twins_on_vulkan() {
    let device = viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap();
    both_searches(&device, "Vulkan");
}
