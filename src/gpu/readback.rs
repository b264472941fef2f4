//! Streaming readback: every attachment is read through a pixel-pack buffer (PBO) and a fence,
//! so `glReadPixels` only queues a copy on the GPU and returns; the bytes are mapped later, when
//! the caller needs them, while the GPU goes on with the next target or frame.
//!
//! Why: a synchronous `glReadPixels` into client memory stalls the pipeline and, on NVIDIA, runs
//! at a quarter of the PBO path's bandwidth (1.9 vs 7-8.5 GB/s measured on an H100). Buffers come
//! from a per-context pool keyed by byte size, so a steady stream of same-sized frames allocates
//! no GL object. The channel packing the file needs (RGB from an RGBA8 target) is asked of
//! `glReadPixels` itself, so the mapped bytes go to the encoder as they are.

use super::census::{Census, GlObject};
use super::Gpu;
use crate::error::{Error, Result};
use glow::HasContext;
use std::collections::HashMap;

/// Free pixel-pack buffers by byte size; at most this many kept per size (more in flight are
/// allocated and freed, which only happens when a caller queues an unusual burst).
const KEEP_PER_SIZE: usize = 16;

/// The per-context pool of pixel-pack buffers and timer queries. Lives inside [`Gpu`] and is
/// emptied (objects deleted) before the context goes away.
#[derive(Default)]
pub(crate) struct ReadbackPool {
    free: HashMap<usize, Vec<glow::Buffer>>,
    queries: Vec<glow::Query>,
    /// Pixel-pack buffers created so far (tests and reports check the steady state adds none).
    created: usize,
}

impl ReadbackPool {
    /// Delete every pooled object; called while the context is still current.
    pub(crate) fn clear(&mut self, gl: &glow::Context, census: &Census) {
        // SAFETY: handles owned by the pool, context current.
        unsafe {
            for (_, list) in self.free.drain() {
                for b in list {
                    gl.delete_buffer(b);
                    census.deleted(GlObject::Buffer);
                }
            }
            for q in self.queries.drain(..) {
                gl.delete_query(q);
                census.deleted(GlObject::Query);
            }
        }
    }
}

/// The layout a read delivers: the GL transfer format and type and the bytes per pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadFormat {
    pub(super) format: u32,
    pub(super) ty: u32,
    /// Bytes per pixel in the delivered buffer (rows tightly packed).
    pub bytes_per_pixel: usize,
}

impl ReadFormat {
    /// Packed 8-bit RGB (from an RGBA8 target: GL drops alpha while copying).
    pub const RGB8: ReadFormat = ReadFormat {
        format: glow::RGB,
        ty: glow::UNSIGNED_BYTE,
        bytes_per_pixel: 3,
    };
    /// One float per pixel (R32F).
    pub const R32F: ReadFormat = ReadFormat {
        format: glow::RED,
        ty: glow::FLOAT,
        bytes_per_pixel: 4,
    };
    /// One unsigned 8-bit integer per pixel (R8UI).
    pub const R8UI: ReadFormat = ReadFormat {
        format: glow::RED_INTEGER,
        ty: glow::UNSIGNED_BYTE,
        bytes_per_pixel: 1,
    };
    /// Four floats per pixel (RGBA32F).
    pub const RGBA32F: ReadFormat = ReadFormat {
        format: glow::RGBA,
        ty: glow::FLOAT,
        bytes_per_pixel: 16,
    };
    /// One unsigned 32-bit integer per pixel (R32UI).
    pub const R32UI: ReadFormat = ReadFormat {
        format: glow::RED_INTEGER,
        ty: glow::UNSIGNED_INT,
        bytes_per_pixel: 4,
    };
    /// One byte per pixel (R8).
    pub const R8: ReadFormat = ReadFormat {
        format: glow::RED,
        ty: glow::UNSIGNED_BYTE,
        bytes_per_pixel: 1,
    };
}

/// A read queued on the GPU: a pooled pixel-pack buffer that will hold `len` bytes once `fence`
/// has signalled. Tied to the GL thread (it holds the context); dropping it unfinished returns
/// the buffer to the pool without reading.
pub struct PendingRead {
    gpu: Gpu,
    buffer: Option<glow::Buffer>,
    fence: Option<glow::Fence>,
    len: usize,
}

impl PendingRead {
    /// Queue `glReadPixels` of the bound read framebuffer's read buffer into a pooled PBO and
    /// fence it. The caller has bound the framebuffer and chosen the read buffer.
    pub(crate) fn queue(gpu: &Gpu, width: u32, height: u32, format: ReadFormat) -> Result<PendingRead> {
        let len = width as usize * height as usize * format.bytes_per_pixel;
        let buffer = gpu.take_pack_buffer(len)?;
        let gl = gpu.gl();
        // SAFETY: the buffer holds `len` bytes, exactly the packed rectangle at alignment 1;
        // reading into offset 0 of a bound PIXEL_PACK_BUFFER writes no client memory.
        let fence = unsafe {
            gl.bind_buffer(glow::PIXEL_PACK_BUFFER, Some(buffer));
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            gl.read_pixels(
                0,
                0,
                width as i32,
                height as i32,
                format.format,
                format.ty,
                glow::PixelPackData::BufferOffset(0),
            );
            gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
            gl.fence_sync(glow::SYNC_GPU_COMMANDS_COMPLETE, 0)
        };
        let mut pending = PendingRead {
            gpu: gpu.clone(),
            buffer: Some(buffer),
            fence: None,
            len,
        };
        pending.fence = Some(fence.map_err(|e| Error::Gl(format!("readback fence: {e}")))?);
        gpu.created(GlObject::Sync);
        gpu.check("queued readback")?;
        Ok(pending)
    }

    /// Whether the copy has finished (never blocks).
    pub fn is_ready(&self) -> bool {
        let Some(fence) = self.fence else { return true };
        // SAFETY: fence owned by self; a zero timeout only polls.
        let r = unsafe { self.gpu.gl().client_wait_sync(fence, 0, 0) };
        r == glow::ALREADY_SIGNALED || r == glow::CONDITION_SATISFIED
    }

    /// Waits, then copies the `len` bytes into `dst`.
    ///
    /// # Safety
    /// `dst` must be valid for `len` bytes of writes.
    unsafe fn copy_to(mut self, dst: *mut u8) -> Result<()> {
        self.wait()?;
        let gl = self.gpu.gl();
        let buffer = self.buffer.expect("buffer present until finished or dropped");
        if self.len > 0 {
            // SAFETY: the buffer holds `len` bytes written by the fenced copy; the mapping is
            // read while mapped and released before the buffer goes back to the pool.
            unsafe {
                gl.bind_buffer(glow::PIXEL_PACK_BUFFER, Some(buffer));
                let ptr = gl.map_buffer_range(glow::PIXEL_PACK_BUFFER, 0, self.len as i32, glow::MAP_READ_BIT);
                if ptr.is_null() {
                    gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
                    return Err(Error::Gl("readback: mapping the pixel-pack buffer failed".into()));
                }
                std::ptr::copy_nonoverlapping(ptr, dst, self.len);
                gl.unmap_buffer(glow::PIXEL_PACK_BUFFER);
                gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
            }
        }
        self.gpu.check("readback map")
    }

    /// Wait and return the bytes as a new vector.
    pub fn finish(self) -> Result<Vec<u8>> {
        // Copied into the new vector's spare room, not into zeros written first: one pass over
        // the image instead of two (the zeroing cost as much as the copy).
        let len = self.len;
        let mut out = crate::alloc::try_with_capacity::<u8>(len, "readback")?;
        // SAFETY: the vector has room for `len` bytes, all written by the copy before `set_len`.
        unsafe {
            self.copy_to(out.as_mut_ptr())?;
            out.set_len(len);
        }
        Ok(out)
    }

    /// Wait and return the bytes as native-endian f32 values (a cast of the copy, no conversion).
    pub fn finish_f32(self) -> Result<Vec<f32>> {
        if !self.len.is_multiple_of(4) {
            return Err(Error::Gl(format!("readback of {} bytes is not f32 data", self.len)));
        }
        let n = self.len / 4;
        let mut out = crate::alloc::try_with_capacity::<f32>(n, "depth readback")?;
        // SAFETY: as in `finish`: room for `n` f32 = `len` bytes, all written before `set_len`;
        // any bit pattern is an f32.
        unsafe {
            self.copy_to(out.as_mut_ptr().cast::<u8>())?;
            out.set_len(n);
        }
        Ok(out)
    }

    fn wait(&mut self) -> Result<()> {
        let Some(fence) = self.fence.take() else { return Ok(()) };
        let gl = self.gpu.gl();
        // 1 s per try: the timeout is an i32 of nanoseconds; a GPU that needs longer is waited
        // for again rather than given up on.
        const STEP_NS: i32 = 1_000_000_000;
        let mut flags = glow::SYNC_FLUSH_COMMANDS_BIT;
        loop {
            // SAFETY: fence owned by self; deleted once signalled or on failure.
            let r = unsafe { gl.client_wait_sync(fence, flags, STEP_NS) };
            flags = 0;
            match r {
                glow::ALREADY_SIGNALED | glow::CONDITION_SATISFIED => break,
                glow::TIMEOUT_EXPIRED => continue,
                _ => {
                    // SAFETY: as above.
                    unsafe { gl.delete_sync(fence) };
                    self.gpu.deleted(GlObject::Sync);
                    return Err(Error::Gl("readback: waiting for the GPU failed (WAIT_FAILED)".into()));
                }
            }
        }
        // SAFETY: signalled fence owned by self.
        unsafe { gl.delete_sync(fence) };
        self.gpu.deleted(GlObject::Sync);
        Ok(())
    }
}

impl Drop for PendingRead {
    fn drop(&mut self) {
        if let Some(fence) = self.fence.take() {
            // SAFETY: fence owned by self. The buffer may still be written by the GPU; GL
            // orders any later use of it after this copy, so pooling it is safe.
            unsafe { self.gpu.gl().delete_sync(fence) };
            self.gpu.deleted(GlObject::Sync);
        }
        if let Some(b) = self.buffer.take() {
            self.gpu.return_pack_buffer(self.len, b);
        }
    }
}

impl Gpu {
    fn take_pack_buffer(&self, len: usize) -> Result<glow::Buffer> {
        if let Some(b) = self.0.readback.borrow_mut().free.get_mut(&len).and_then(Vec::pop) {
            return Ok(b);
        }
        self.0.readback.borrow_mut().created += 1;
        let size = i32::try_from(len.max(1))
            .map_err(|_| Error::param("readback size", format!("{len} bytes exceed a GL buffer")))?;
        let gl = self.gl();
        // SAFETY: a fresh buffer sized once; STREAM_READ asks the driver for host-visible memory.
        unsafe {
            let b = gl.create_buffer().map_err(Error::Gl)?;
            self.created(GlObject::Buffer);
            gl.bind_buffer(glow::PIXEL_PACK_BUFFER, Some(b));
            gl.buffer_data_size(glow::PIXEL_PACK_BUFFER, size, glow::STREAM_READ);
            gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
            self.label(glow::BUFFER, b.0.get(), "viewsynth readback");
            self.check("readback buffer allocation")?;
            Ok(b)
        }
    }

    fn return_pack_buffer(&self, len: usize, b: glow::Buffer) {
        let mut pool = self.0.readback.borrow_mut();
        let list = pool.free.entry(len).or_default();
        if list.len() < KEEP_PER_SIZE {
            list.push(b);
        } else {
            // SAFETY: handle owned by the caller, not pooled.
            unsafe { self.gl().delete_buffer(b) }
            self.deleted(GlObject::Buffer);
        }
    }

    /// Pixel-pack buffers this context has created for readback so far.
    pub fn readback_buffers_created(&self) -> usize {
        self.0.readback.borrow().created
    }

    /// A pooled query object (for timer queries read after their frame's fence), and whether it
    /// is freshly created (not yet an object, so not yet labelled).
    pub(crate) fn take_query(&self) -> Result<(glow::Query, bool)> {
        if let Some(q) = self.0.readback.borrow_mut().queries.pop() {
            return Ok((q, false));
        }
        // SAFETY: object creation on the current context.
        let q = unsafe { self.gl().create_query() }.map_err(Error::Gl)?;
        self.created(GlObject::Query);
        Ok((q, true))
    }

    pub(crate) fn return_query(&self, q: glow::Query) {
        self.0.readback.borrow_mut().queries.push(q);
    }
}
