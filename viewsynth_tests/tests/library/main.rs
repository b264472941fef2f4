//! The library's own tests: one binary, grouped by concern. Each GPU pass is held against its
//! f64 twin (or an analytic oracle) with the tolerance derived beside the test; GPU tests need
//! EGL with GL 4.5 (Mesa llvmpipe in CI) and Vulkan tests a Vulkan 1.3 driver (lavapipe): a
//! missing one fails with the library's error, never a skip. Shared helpers: `viewsynth_tests`
//! (src/lib.rs). The command line's end-to-end tests are `cli/tests/integration/`.

/// `compare`: conversions of each side's conventions and colour storage, robust gates.
mod compare;
/// cyclopean: the gather, splat, densify, fill and temporal passes and the matchers against
/// their twins, and quality on real pairs.
mod cyclopean;
/// Degenerate and hostile values through the library's passes: never valid and non-finite.
mod numerics;
/// What every pass shares: the pass/twin contract, the shader library, the conventions sweep,
/// the context and its size limits.
mod passes;
/// refocus: accuracy against the twin and an independent oracle, conventions, edge cases,
/// colour everywhere, and the pipelined batch.
mod refocus;
/// reproject against its twin under every convention and depth kind.
mod reproject;
/// The ground-truth scenes' ray tracer against its twin.
mod scene;
/// stitch (ODS) against its twin and the ray-traced truth.
mod stitch;
/// The quick stress sweep of every capability.
mod stress;
/// GL against Vulkan on the same pass descriptions.
#[cfg(feature = "vulkan")]
mod vulkan;
