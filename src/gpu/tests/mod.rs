//! The GL layer's own tests (a real context: Mesa llvmpipe in CI): the census of live objects
//! and the streaming readback. They sit in the library, so the GL types they drive stay sealed
//! (`pub(crate)`); the rest of the library's tests are the `viewsynth_tests` crate.

use crate::gpu::{DeviceChoice, Gpu};
use crate::refocus::RefocusSource;

mod live_objects;
mod readback;

fn gpu() -> Gpu {
    Gpu::new(DeviceChoice::Auto).unwrap_or_else(|e| {
        panic!("GPU tests need EGL + OpenGL 4.5 core (run ci/install-deps.sh for Mesa llvmpipe): {e}")
    })
}

fn synthetic(width: u32, height: u32) -> RefocusSource {
    let cam = crate::world::demo_camera(width, height);
    let (rgb, depth) = crate::world::render(&cam);
    RefocusSource::new(rgb, depth, cam.k).unwrap()
}
