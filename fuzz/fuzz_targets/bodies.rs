//! The fuzz targets' bodies, shared by the cargo-fuzz binaries (nightly, libFuzzer) and by the
//! stable-Rust driver `tests/fuzz_stable.rs` (checked-in corpus replayed, then a time-boxed
//! mutation loop; run by `cargo test` and, longer, by `.ci/run`). Errors are fine; a panic, a
//! hang or a result that breaks its own invariants is a finding.
#![allow(dead_code)]

use std::path::PathBuf;

use viewsynth::convention::DepthPlanes;
use viewsynth::io::{load_depth, load_mask_png, load_npz_array, load_rgb, DepthDecode};
use viewsynth::refocus::batch::load_manifest;
use viewsynth::stereo::camera_file::CameraFile;
use viewsynth::world::Scene;

/// The loaders take paths: each input goes to a scratch file of this process and thread with
/// the extension that selects the format.
pub fn scratch(ext: &str, data: &[u8]) -> PathBuf {
    let thread = format!("{:?}", std::thread::current().id()).replace(|c: char| !c.is_ascii_alphanumeric(), "");
    let p = std::env::temp_dir().join(format!("viewsynth-fuzz-{}-{thread}.{ext}", std::process::id()));
    std::fs::write(&p, data).expect("scratch file");
    p
}

/// Every depth format and decode option (first byte: format and flags).
pub fn load_depth_target(data: &[u8]) {
    if data.is_empty() {
        return;
    }
    let ext = ["npy", "exr", "png", "pgm", "pfm"][data[0] as usize % 5];
    let decode = DepthDecode {
        scale: (data[0] & 8 != 0).then_some(1000.0),
        sun_rgbd_bit_rotate: data[0] & 16 != 0,
        swap_bytes: data[0] & 32 != 0,
    };
    let p = scratch(ext, &data[1..]);
    if let Ok(d) = load_depth(&p, &decode) {
        assert_eq!(d.data.len(), d.width as usize * d.height as usize);
    }
}

/// Colour loader (format sniffed from content) and the mask reader.
pub fn load_rgb_target(data: &[u8]) {
    let p = scratch("png", data);
    if let Ok(img) = load_rgb(&p) {
        assert_eq!(img.data.len(), img.width as usize * img.height as usize * 3);
    }
    if let Ok(m) = load_mask_png(&p) {
        assert_eq!(m.data.len(), m.width as usize * m.height as usize);
        assert!(m.data.iter().all(|v| *v <= 1));
    }
}

/// Camera JSON (cyclopean, reproject --cameras), scene JSON: parse, validate, derive the
/// middle camera, the fixation and the depth planes of each eye's projection.
pub fn json_inputs_target(data: &[u8]) {
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
    let p = scratch("json", data);
    let _ = Scene::load(&p);
}

/// Batch manifests, CSV and JSON (first byte: which).
pub fn batch_manifest_target(data: &[u8]) {
    if data.is_empty() {
        return;
    }
    let ext = if data[0] & 1 == 0 { "csv" } else { "json" };
    let p = scratch(ext, &data[1..]);
    if let Ok(frames) = load_manifest(&p) {
        assert!(!frames.is_empty());
    }
}

/// NumPy `.npz` archives (Middlebury 2014 disparity): the array by key (first byte: none,
/// `arr_0` or `disp`), and through the depth loader.
pub fn npz_target(data: &[u8]) {
    if data.is_empty() {
        return;
    }
    let key = [None, Some("arr_0"), Some("disp")][data[0] as usize % 3];
    let p = scratch("npz", &data[1..]);
    if let Ok((name, arr)) = load_npz_array(&p, key) {
        assert!(key.is_none_or(|k| k == name), "asked for {key:?}, got {name}");
        assert_eq!(arr.data.len(), arr.shape.iter().product::<usize>());
    }
    if let Ok(d) = load_depth(&p, &DepthDecode::default()) {
        assert_eq!(d.data.len(), d.width as usize * d.height as usize);
    }
}

/// A target's body.
pub type Body = fn(&[u8]);

/// Every target by name (the corpus folders' names).
pub const TARGETS: [(&str, Body); 5] = [
    ("load_depth", load_depth_target),
    ("load_rgb", load_rgb_target),
    ("json_inputs", json_inputs_target),
    ("batch_manifest", batch_manifest_target),
    ("npz", npz_target),
];
