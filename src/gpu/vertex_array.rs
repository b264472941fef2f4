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
}

impl Drop for VertexArray {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_vertex_array(self.raw) }
    }
}
