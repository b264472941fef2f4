//! An empty vertex array object: core profile needs one bound for any draw, even when vertex
//! shaders pull their data from textures.

use super::Gpu;
use crate::error::{Error, Result};
use glow::HasContext;

pub struct VertexArray {
    gpu: Gpu,
    raw: glow::VertexArray,
}

impl VertexArray {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        // SAFETY: object creation on the current context.
        let raw = unsafe { gpu.gl().create_vertex_array() }.map_err(Error::Gl)?;
        Ok(VertexArray { gpu: gpu.clone(), raw })
    }

    pub fn bind(&self) {
        // SAFETY: valid handle.
        unsafe { self.gpu.gl().bind_vertex_array(Some(self.raw)) }
    }

    /// Draw the one full-screen triangle of shaders/common/fullscreen.vert with the bound
    /// program, setting the state such a pass relies on: no depth test, blending, culling or
    /// stencil.
    pub fn draw_fullscreen(&self) {
        let gl = self.gpu.gl();
        // SAFETY: valid VAO; three vertices generated in the vertex shader, no buffers read.
        unsafe {
            gl.bind_vertex_array(Some(self.raw));
            gl.disable(glow::DEPTH_TEST);
            gl.disable(glow::BLEND);
            gl.disable(glow::CULL_FACE);
            gl.disable(glow::STENCIL_TEST);
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
        }
    }
}

impl Drop for VertexArray {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_vertex_array(self.raw) }
    }
}
