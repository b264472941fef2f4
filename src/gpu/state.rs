//! Fixed-function state, set per pass and restored after it.
//!
//! Design: outside a pass the context is in one known baseline (no depth test or clamp, GL clip
//! control, no blending, culling, stencil or scissor, every write mask on). A pass states what it needs as a
//! [`DrawState`] value and draws through the [`RenderPass`] guard that
//! [`Framebuffer::begin_pass`] returns: the guard binds and clears the framebuffer, applies the
//! state, and on drop puts the baseline back and unbinds, so no pass inherits another's state.
//! The context remembers the state last applied and emits only the calls that change it, so a
//! stream of identical passes costs no state calls. Capabilities never name a GL enum: depth
//! test and clip control come from the [`Conventions`] the pass runs under.

use super::{Framebuffer, Gpu, IndexBuffer, VertexArray};
use crate::convention::{Conventions, NdcDepthRange};
use glow::HasContext;

/// Depth test with a float depth buffer under the conventions: LEQUAL (GEQUAL reversed-Z), depth
/// writes on, depth clamp on (no near/far clipping), clip control from the NDC range.
///
/// LEQUAL/GEQUAL, not strict: at a 1e8 depth ratio standard-Z f32 rounds far surfaces onto the
/// clear value itself, which a strict test would reject; clamping keeps surfaces the projection
/// puts beyond the far plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DepthTest {
    /// Reversed-Z: GEQUAL test, near maps to the larger depth.
    pub reversed_z: bool,
    /// NDC depth range of the clip control ([-1, 1] GL default, or [0, 1]).
    pub ndc_depth: NdcDepthRange,
}

impl DepthTest {
    /// The depth test of a pass rendered under `conv`.
    pub fn for_conventions(conv: &Conventions) -> Self {
        DepthTest {
            reversed_z: conv.reversed_z,
            ndc_depth: conv.ndc_depth,
        }
    }
}

/// What a pass needs set beyond the baseline. `DrawState::default()` is the baseline: no depth
/// test (full-screen and compute passes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DrawState {
    /// Depth test of the pass; None for no depth test.
    pub depth: Option<DepthTest>,
}

impl DrawState {
    /// A depth-tested pass under `conv`.
    pub fn depth_tested(conv: &Conventions) -> Self {
        DrawState {
            depth: Some(DepthTest::for_conventions(conv)),
        }
    }
}

impl Gpu {
    /// Make `state` current, emitting only what differs from the state last applied.
    pub(super) fn apply_draw_state(&self, state: DrawState) {
        let known = self.0.draw_state.get();
        if known == Some(state) {
            return;
        }
        let gl = self.gl();
        // SAFETY: plain state setting on the current context.
        unsafe {
            if known.is_none() {
                // First use: the parts no pass changes, set once (clears rely on the masks).
                gl.disable(glow::BLEND);
                gl.disable(glow::CULL_FACE);
                gl.disable(glow::STENCIL_TEST);
                gl.disable(glow::SCISSOR_TEST);
                gl.color_mask(true, true, true, true);
                gl.depth_mask(true);
                gl.depth_range_f64(0.0, 1.0);
            }
            match state.depth {
                None => {
                    gl.disable(glow::DEPTH_TEST);
                    gl.disable(glow::DEPTH_CLAMP);
                }
                Some(d) => {
                    gl.enable(glow::DEPTH_TEST);
                    gl.enable(glow::DEPTH_CLAMP);
                    gl.depth_func(if d.reversed_z { glow::GEQUAL } else { glow::LEQUAL });
                }
            }
        }
        let ndc = state.depth.map_or(NdcDepthRange::MinusOneToOne, |d| d.ndc_depth);
        let known_ndc = known
            .and_then(|k| k.depth)
            .map_or(NdcDepthRange::MinusOneToOne, |d| d.ndc_depth);
        if known.is_none() || ndc != known_ndc {
            self.clip_control(
                glow::LOWER_LEFT,
                match ndc {
                    NdcDepthRange::MinusOneToOne => glow::NEGATIVE_ONE_TO_ONE,
                    NdcDepthRange::ZeroToOne => glow::ZERO_TO_ONE,
                },
            );
        }
        self.0.draw_state.set(Some(state));
    }
}

/// Drawing into one framebuffer under one [`DrawState`]; dropping it restores the baseline and
/// unbinds the framebuffer. Reads of the framebuffer come after the pass.
pub struct RenderPass<'a> {
    fb: &'a Framebuffer,
}

impl Framebuffer {
    /// Bind, set the full viewport, clear every attachment (depth to `clear_depth`) and apply
    /// `state` until the returned pass is dropped.
    pub fn begin_pass(&self, state: DrawState, clear_depth: f32) -> RenderPass<'_> {
        self.gpu().apply_draw_state(state);
        self.bind_and_clear(clear_depth);
        RenderPass { fb: self }
    }
}

impl RenderPass<'_> {
    /// Restrict drawing to `width` x `height` pixels from (`x`, `y`) (framebuffer rows).
    pub fn viewport(&self, x: u32, y: u32, width: u32, height: u32) {
        // SAFETY: plain state; the next pass (bind_and_clear) sets its own viewport.
        unsafe {
            self.fb
                .gpu()
                .gl()
                .viewport(x as i32, y as i32, width as i32, height as i32)
        }
    }

    /// `count` triangles whose vertices the bound program pulls itself (no vertex buffers).
    pub fn draw_triangles(&self, vao: &VertexArray, count: usize) {
        vao.bind();
        // SAFETY: the vertex shader reads no attribute arrays; 3 vertices per triangle.
        unsafe { self.fb.gpu().gl().draw_arrays(glow::TRIANGLES, 0, (count * 3) as i32) }
    }

    /// The first `triangles` triangles of `indices` (u32) with `vao` and the bound program.
    pub fn draw_indexed(&self, vao: &VertexArray, indices: &IndexBuffer, triangles: usize) {
        vao.bind();
        indices.bind();
        let count = (3 * triangles).min(indices.count);
        // SAFETY: the element buffer is bound to this VAO and holds at least `count` indices.
        unsafe {
            self.fb
                .gpu()
                .gl()
                .draw_elements(glow::TRIANGLES, count as i32, glow::UNSIGNED_INT, 0)
        }
    }
}

impl Drop for RenderPass<'_> {
    fn drop(&mut self) {
        let gpu = self.fb.gpu();
        gpu.apply_draw_state(DrawState::default());
        self.fb.unbind();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convention::RowOrder;
    use crate::gpu::{Attachment, DeviceChoice, TextureFormat};

    /// (depth test, depth clamp, depth func, clip depth mode) as GL reports them.
    fn depth_state(gpu: &Gpu) -> (bool, bool, u32, u32) {
        let gl = gpu.gl();
        // SAFETY: plain state queries on the current context.
        unsafe {
            (
                gl.is_enabled(glow::DEPTH_TEST),
                gl.is_enabled(glow::DEPTH_CLAMP),
                gl.get_parameter_i32(glow::DEPTH_FUNC) as u32,
                gl.get_parameter_i32(glow::CLIP_DEPTH_MODE) as u32,
            )
        }
    }

    #[test]
    fn a_pass_sets_its_depth_state_and_dropping_it_restores_the_baseline() {
        let gpu = Gpu::new(DeviceChoice::Auto).expect("GPU tests need EGL + OpenGL 4.5 (Mesa llvmpipe)");
        let color = Some(Attachment {
            format: TextureFormat::R8,
            clear: [0.0; 4],
        });
        let fb = Framebuffer::new(&gpu, 4, 3, &[color], true).unwrap();
        let vulkan_reversed = Conventions {
            ndc_depth: NdcDepthRange::ZeroToOne,
            reversed_z: true,
            row_order: RowOrder::TopDown,
        };
        let baseline = (false, false, glow::NEGATIVE_ONE_TO_ONE);
        for (conv, func, mode) in [
            (vulkan_reversed, glow::GEQUAL, glow::ZERO_TO_ONE),
            (Conventions::default(), glow::LEQUAL, glow::NEGATIVE_ONE_TO_ONE),
            // Twice the same: the cached state must still be the one GL has.
            (Conventions::default(), glow::LEQUAL, glow::NEGATIVE_ONE_TO_ONE),
        ] {
            {
                let _pass = fb.begin_pass(DrawState::depth_tested(&conv), conv.clear_depth() as f32);
                assert_eq!(depth_state(&gpu), (true, true, func, mode), "{conv:?}");
            }
            let (test, clamp, _, clip) = depth_state(&gpu);
            assert_eq!((test, clamp, clip), baseline, "after {conv:?}");
            let _plain = fb.begin_pass(DrawState::default(), 1.0);
            let (test, clamp, _, clip) = depth_state(&gpu);
            assert_eq!((test, clamp, clip), baseline, "full-screen pass after {conv:?}");
        }
        gpu.check("draw state test").unwrap();
    }
}
