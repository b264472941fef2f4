//! The time of one run, as both executors report it.

/// GPU and wall time of one timed section, in milliseconds.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Timing {
    /// None where timer queries are not meaningful (llvmpipe reports CPU-side fragments).
    pub gpu_ms: Option<f64>,
    /// Wall-clock time from start to stop, milliseconds.
    pub wall_ms: f64,
}
