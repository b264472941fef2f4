#![no_main]
//! Batch manifests, CSV and JSON.
use libfuzzer_sys::fuzz_target;
use viewsynth::refocus::batch::load_manifest;

mod common;

fuzz_target!(|data: &[u8]| {
    if data.is_empty() {
        return;
    }
    let ext = if data[0] & 1 == 0 { "csv" } else { "json" };
    let p = common::scratch(ext, &data[1..]);
    if let Ok(frames) = load_manifest(&p) {
        assert!(!frames.is_empty());
    }
});
