//! Timing: deferred GL_TIME_ELAPSED queries where the driver gives real values (read after the
//! frame's fence, so timing never waits).

use super::Gpu;
use glow::HasContext;

/// A GPU timer whose result is read later, after the frame's fence, so timing never waits:
/// a pooled TIME_ELAPSED query where the driver gives real values, nothing elsewhere.
pub struct DeferredTimer {
    gpu: Gpu,
    query: Option<glow::Query>,
    ended: bool,
}

impl DeferredTimer {
    /// Begin timing the GL commands that follow.
    pub fn begin(gpu: &Gpu) -> Self {
        let query = if gpu.info().gpu_timers_meaningful {
            gpu.take_query().ok()
        } else {
            None
        };
        if let Some((q, fresh)) = query {
            // SAFETY: a pooled query object, not active.
            unsafe { gpu.gl().begin_query(glow::TIME_ELAPSED, q) };
            if fresh {
                // A generated name is an object once begun: only now can it be labelled.
                gpu.label(glow::QUERY, q.0.get(), "viewsynth frame timer");
            }
        }
        let query = query.map(|(q, _)| q);
        DeferredTimer {
            gpu: gpu.clone(),
            query,
            ended: false,
        }
    }

    /// End the timed section (no wait).
    pub fn end(&mut self) {
        if let (Some(_), false) = (self.query, self.ended) {
            // SAFETY: ends the query begun in `begin`.
            unsafe { self.gpu.gl().end_query(glow::TIME_ELAPSED) };
            self.ended = true;
        }
    }

    /// The GPU time in ms; call after the section's work is known to be done (its fence), so
    /// the query result is available and reading it does not stall.
    pub fn read_ms(mut self) -> Option<f64> {
        self.end();
        let q = self.query.take()?;
        // SAFETY: an ended query; its result is available once the fence after it signalled.
        let ns = unsafe { self.gpu.gl().get_query_parameter_u32(q, glow::QUERY_RESULT) };
        self.gpu.return_query(q);
        Some(ns as f64 * 1e-6)
    }
}

impl Drop for DeferredTimer {
    fn drop(&mut self) {
        self.end();
        if let Some(q) = self.query.take() {
            self.gpu.return_query(q);
        }
    }
}
