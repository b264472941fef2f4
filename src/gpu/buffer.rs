//! Element (index) buffers.

use super::Gpu;
use crate::error::{Error, Result};
use glow::HasContext;

/// A GL_ELEMENT_ARRAY_BUFFER of u32 indices, immutable after upload.
pub struct IndexBuffer {
    gpu: Gpu,
    raw: glow::Buffer,
    pub count: usize,
}

impl IndexBuffer {
    pub fn new(gpu: &Gpu, indices: &[u32]) -> Result<Self> {
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_ne_bytes()).collect();
        // SAFETY: a fresh buffer filled with exactly `bytes`; unbound afterwards.
        unsafe {
            let gl = gpu.gl();
            let raw = gl.create_buffer().map_err(Error::Gl)?;
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(raw));
            gl.buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, &bytes, glow::STATIC_DRAW);
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, None);
            let buffer = IndexBuffer {
                gpu: gpu.clone(),
                raw,
                count: indices.len(),
            };
            gpu.check("index buffer upload")?;
            Ok(buffer)
        }
    }

    /// Bind as the element buffer of the currently bound vertex array.
    pub fn bind(&self) {
        // SAFETY: valid handle.
        unsafe { self.gpu.gl().bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(self.raw)) }
    }
}

impl Drop for IndexBuffer {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_buffer(self.raw) }
    }
}
