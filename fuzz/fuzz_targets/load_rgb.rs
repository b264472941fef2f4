#![no_main]
//! Colour loader (format sniffed from content) and the mask reader. Body: bodies.rs (shared with the stable driver tests/fuzz_stable.rs).
use libfuzzer_sys::fuzz_target;

mod bodies;

fuzz_target!(|data: &[u8]| bodies::load_rgb_target(data));
