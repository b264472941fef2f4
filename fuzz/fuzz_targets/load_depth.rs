#![no_main]
//! Every depth format and decode option: errors are fine, panics and hangs are not.
use libfuzzer_sys::fuzz_target;
use viewsynth::io::{load_depth, DepthDecode};

mod common;

fuzz_target!(|data: &[u8]| {
    if data.is_empty() {
        return;
    }
    let ext = ["npy", "exr", "png", "pgm", "pfm"][data[0] as usize % 5];
    let decode = DepthDecode {
        scale: (data[0] & 8 != 0).then_some(1000.0),
        sun_rgbd_bit_rotate: data[0] & 16 != 0,
        swap_bytes: data[0] & 32 != 0,
    };
    let p = common::scratch(ext, &data[1..]);
    if let Ok(d) = load_depth(&p, &decode) {
        assert_eq!(d.data.len(), d.width as usize * d.height as usize);
    }
});
