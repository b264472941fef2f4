#![no_main]
//! Colour loader (format sniffed from content) and the mask reader.
use libfuzzer_sys::fuzz_target;
use viewsynth::io::{load_mask_png, load_rgb};

mod common;

fuzz_target!(|data: &[u8]| {
    let p = common::scratch("png", data);
    if let Ok(img) = load_rgb(&p) {
        assert_eq!(img.data.len(), img.width as usize * img.height as usize * 3);
    }
    let _ = load_mask_png(&p);
});
