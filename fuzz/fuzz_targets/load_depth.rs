#![no_main]
//! Every depth format and decode option. Body: bodies.rs (shared with the stable driver tests/fuzz_stable.rs).
use libfuzzer_sys::fuzz_target;

mod bodies;

fuzz_target!(|data: &[u8]| bodies::load_depth_target(data));
