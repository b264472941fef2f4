//! Element (index) buffers, and storage buffers shaders append to and indirect dispatches read.

use super::census::GlObject;
use super::Gpu;
use crate::error::{Error, Result};
use glow::HasContext;

/// A GL_ELEMENT_ARRAY_BUFFER of u32 indices, immutable after upload.
pub struct IndexBuffer {
    gpu: Gpu,
    raw: glow::Buffer,
    pub(super) count: usize,
}

impl IndexBuffer {
    /// Uploads `indices` (u32) to a new buffer.
    pub fn new(gpu: &Gpu, indices: &[u32]) -> Result<Self> {
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_ne_bytes()).collect();
        // SAFETY: a fresh buffer filled with exactly `bytes`; unbound afterwards.
        unsafe {
            let gl = gpu.gl();
            let raw = gl.create_buffer().map_err(Error::Gl)?;
            gpu.created(GlObject::Buffer);
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(raw));
            gl.buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, &bytes, glow::STATIC_DRAW);
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, None);
            gpu.label(glow::BUFFER, raw.0.get(), "viewsynth index buffer");
            let buffer = IndexBuffer {
                gpu: gpu.clone(),
                raw,
                count: indices.len(),
            };
            gpu.check("index buffer upload")?;
            Ok(buffer)
        }
    }

    /// Name this buffer for debuggers (RenderDoc, apitrace).
    pub fn with_label(self, name: &str) -> Self {
        self.gpu.label(glow::BUFFER, self.raw.0.get(), name);
        self
    }

    /// Bind as the element buffer of the currently bound vertex array.
    pub(super) fn bind(&self) {
        // SAFETY: valid handle.
        unsafe { self.gpu.gl().bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(self.raw)) }
    }
}

impl Drop for IndexBuffer {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_buffer(self.raw) }
        self.gpu.deleted(GlObject::Buffer);
    }
}

/// A GL buffer of u32 words that shaders read and write (`layout(std430, binding = b) buffer`)
/// and that an indirect compute dispatch reads its work-group counts from. Allocated once;
/// [`StorageBuffer::write_head`] rewrites its first words each frame without reallocating.
pub struct StorageBuffer {
    gpu: Gpu,
    raw: glow::Buffer,
    /// Size in u32 words.
    words: usize,
}

impl StorageBuffer {
    /// A buffer of `words` u32 words, contents undefined until written.
    pub fn new(gpu: &Gpu, words: usize) -> Result<Self> {
        let bytes = words
            .checked_mul(4)
            .and_then(|b| i32::try_from(b).ok())
            .ok_or_else(|| Error::Gl(format!("storage buffer of {words} words exceeds 2 GiB")))?;
        // SAFETY: a fresh buffer given its size; unbound afterwards.
        unsafe {
            let gl = gpu.gl();
            let raw = gl.create_buffer().map_err(Error::Gl)?;
            gpu.created(GlObject::Buffer);
            let buffer = StorageBuffer {
                gpu: gpu.clone(),
                raw,
                words,
            };
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(raw));
            gl.buffer_data_size(glow::SHADER_STORAGE_BUFFER, bytes, glow::DYNAMIC_COPY);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, None);
            gpu.label(glow::BUFFER, raw.0.get(), "viewsynth storage buffer");
            gpu.check("storage buffer allocation")?;
            Ok(buffer)
        }
    }

    /// Name this buffer for debuggers (RenderDoc, apitrace).
    pub fn with_label(self, name: &str) -> Self {
        self.gpu.label(glow::BUFFER, self.raw.0.get(), name);
        self
    }

    /// Overwrite the first `head.len()` words (a counter and indirect arguments), in order
    /// with the GL commands before and after.
    pub fn write_head(&self, head: &[u32]) {
        let n = head.len().min(self.words);
        let bytes: Vec<u8> = head[..n].iter().flat_map(|w| w.to_ne_bytes()).collect();
        // SAFETY: `bytes` fits inside the buffer (n <= words).
        unsafe {
            let gl = self.gpu.gl();
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.raw));
            gl.buffer_sub_data_u8_slice(glow::SHADER_STORAGE_BUFFER, 0, &bytes);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, None);
        }
    }

    /// Bind to shader storage binding point `index` (`layout(std430, binding = index)`).
    pub fn bind_storage(&self, index: u32) {
        // SAFETY: valid handle.
        unsafe {
            self.gpu
                .gl()
                .bind_buffer_base(glow::SHADER_STORAGE_BUFFER, index, Some(self.raw))
        }
    }

    /// Bind as the source of indirect dispatch arguments.
    pub(super) fn bind_dispatch_indirect(&self) {
        // SAFETY: valid handle.
        unsafe {
            self.gpu
                .gl()
                .bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, Some(self.raw))
        }
    }
}

impl Drop for StorageBuffer {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_buffer(self.raw) }
        self.gpu.deleted(GlObject::Buffer);
    }
}

/// A GL_UNIFORM_BUFFER holding the std140 parameter blocks of a pass's draws, one per slot of
/// [`UniformBuffer::slot_bytes`] (the block size rounded up to the context's offset alignment).
/// Grown, never shrunk: a steady stream of frames rewrites it without reallocating.
pub struct UniformBuffer {
    gpu: Gpu,
    raw: glow::Buffer,
    /// Allocated bytes.
    capacity: usize,
    /// GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, queried once (a state query per frame is a round trip
    /// on some drivers).
    alignment: usize,
}

impl UniformBuffer {
    /// An empty buffer (storage comes with the first [`UniformBuffer::write`]).
    pub fn new(gpu: &Gpu) -> Result<Self> {
        // SAFETY: a fresh buffer name, labelled once bound.
        unsafe {
            let gl = gpu.gl();
            let raw = gl.create_buffer().map_err(Error::Gl)?;
            gpu.created(GlObject::Buffer);
            gl.bind_buffer(glow::UNIFORM_BUFFER, Some(raw));
            gl.bind_buffer(glow::UNIFORM_BUFFER, None);
            gpu.label(glow::BUFFER, raw.0.get(), "viewsynth pass parameters");
            let alignment = gl.get_parameter_i32(glow::UNIFORM_BUFFER_OFFSET_ALIGNMENT).max(1) as usize;
            Ok(UniformBuffer {
                gpu: gpu.clone(),
                raw,
                capacity: 0,
                alignment,
            })
        }
    }

    /// The context's GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT: slots start at multiples of it.
    pub fn offset_alignment(&self) -> usize {
        self.alignment
    }

    /// Replace the contents with `bytes` (growing the store when needed).
    pub fn write(&mut self, bytes: &[u8]) -> Result<()> {
        let gl = self.gpu.gl();
        // SAFETY: the buffer is owned; the store is (re)allocated before a write that needs it.
        unsafe {
            gl.bind_buffer(glow::UNIFORM_BUFFER, Some(self.raw));
            if bytes.len() > self.capacity {
                gl.buffer_data_size(glow::UNIFORM_BUFFER, bytes.len() as i32, glow::DYNAMIC_DRAW);
                self.capacity = bytes.len();
            }
            gl.buffer_sub_data_u8_slice(glow::UNIFORM_BUFFER, 0, bytes);
            gl.bind_buffer(glow::UNIFORM_BUFFER, None);
        }
        self.gpu.check("uniform buffer write")
    }

    /// Bind bytes `[offset, offset + size)` to uniform block binding `binding`.
    pub fn bind_range(&self, binding: u32, offset: usize, size: usize) {
        // SAFETY: valid handle; the range lies inside the store written by `write`.
        unsafe {
            self.gpu.gl().bind_buffer_range(
                glow::UNIFORM_BUFFER,
                binding,
                Some(self.raw),
                offset as i32,
                size as i32,
            )
        }
    }
}

impl Drop for UniformBuffer {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_buffer(self.raw) }
        self.gpu.deleted(GlObject::Buffer);
    }
}
