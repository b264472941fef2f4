#![no_main]
//! Camera JSON (cyclopean, reproject --cameras), scene JSON: parse, validate, derive the middle
//! camera, the fixation and the depth planes of each eye's projection.
use libfuzzer_sys::fuzz_target;
use viewsynth::convention::DepthPlanes;
use viewsynth::cyclopean::camera_file::CameraFile;
use viewsynth::scene::Scene;

mod common;

fuzz_target!(|data: &[u8]| {
    if let Ok(cams) = serde_json::from_slice::<CameraFile>(data) {
        if let Ok((_, fixation)) = cams.middle_and_fixation() {
            assert!(fixation.is_finite());
        }
        for eye in [&cams.left, &cams.right] {
            if let Ok(planes) = DepthPlanes::from_gl_projection(&eye.proj, &cams.conventions) {
                assert!(planes.near > 0.0 && planes.near.is_finite() && planes.far > planes.near);
            }
        }
    }
    let p = common::scratch("json", data);
    let _ = Scene::load(&p);
});
