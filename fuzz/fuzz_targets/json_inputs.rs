#![no_main]
//! Camera JSON (cyclopean), scene JSON: parse, validate, derive the middle camera and fixation.
use libfuzzer_sys::fuzz_target;
use viewsynth::cyclopean::camera_file::CameraFile;
use viewsynth::scene::Scene;

mod common;

fuzz_target!(|data: &[u8]| {
    if let Ok(cams) = serde_json::from_slice::<CameraFile>(data) {
        if let Ok((_, fixation)) = cams.middle_and_fixation() {
            assert!(fixation.is_finite());
        }
    }
    let p = common::scratch("json", data);
    let _ = Scene::load(&p);
});
