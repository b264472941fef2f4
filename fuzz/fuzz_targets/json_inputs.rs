#![no_main]
//! Camera and scene JSON. Body: bodies.rs (shared with the stable driver tests/fuzz_stable.rs).
use libfuzzer_sys::fuzz_target;

mod bodies;

fuzz_target!(|data: &[u8]| bodies::json_inputs_target(data));
