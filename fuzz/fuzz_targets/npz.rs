#![no_main]
//! NumPy .npz archives (Middlebury 2014 disparity). Body: bodies.rs (shared with the stable driver tests/fuzz_stable.rs).
use libfuzzer_sys::fuzz_target;

mod bodies;

fuzz_target!(|data: &[u8]| bodies::npz_target(data));
