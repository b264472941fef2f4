//! Framebuffers with multiple render targets (MRT) and an optional float depth buffer.

use super::census::GlObject;
use super::{Gpu, PendingRead, ReadFormat, Texture, TextureFormat};
use crate::error::{Error, Result};
use glow::HasContext;
use std::cell::RefCell;

/// GL_PACK_INVERT_MESA (GL_MESA_pack_invert): glReadPixels returns rows top row first.
const PACK_INVERT_MESA: u32 = 0x8758;

/// One colour attachment: its format and the value it is cleared to.
#[derive(Debug, Clone, Copy)]
pub struct Attachment {
    /// Texel format of the attachment's texture.
    pub format: TextureFormat,
    /// Clear value (RGBA; integer formats take it converted).
    pub clear: [f32; 4],
}

/// An FBO owning its colour textures and depth texture. Fragment output location i writes
/// attachment i; a `None` slot gets no texture and `GL_NONE` as its draw buffer, so a shader
/// output that is not wanted costs no memory, bandwidth or readback.
pub struct Framebuffer {
    gpu: Gpu,
    raw: glow::Framebuffer,
    /// Colour attachments by output location; None where the slot has no texture.
    colors: Vec<Option<Texture>>,
    clears: Vec<[f32; 4]>,
    /// The float depth buffer, when asked for.
    depth: Option<Texture>,
    width: u32,
    height: u32,
    /// Companion of the same attachments that reads with flipped rows are blitted into;
    /// created on the first such read and kept.
    flipped: RefCell<Option<Box<Framebuffer>>>,
}

impl Framebuffer {
    /// The colour attachment of output location `index`; None for an empty slot (or past the
    /// last).
    pub fn color(&self, index: usize) -> Option<&Texture> {
        self.colors.get(index).and_then(|t| t.as_ref())
    }

    /// A `width` x `height` FBO with one texture per `Some` attachment and, if `with_depth`, a [`TextureFormat::Depth32F`] depth buffer; fails if GL reports it incomplete.
    pub fn new(
        gpu: &Gpu,
        width: u32,
        height: u32,
        attachments: &[Option<Attachment>],
        with_depth: bool,
    ) -> Result<Self> {
        let mut colors = Vec::new();
        for a in attachments {
            colors.push(match a {
                Some(a) => Some(Texture::new(gpu, width, height, a.format, None)?),
                None => None,
            });
        }
        let depth = if with_depth {
            Some(Texture::new(gpu, width, height, TextureFormat::Depth32F, None)?)
        } else {
            None
        };
        let gl = gpu.gl();
        // SAFETY: attaches textures owned by the returned value; completeness is checked.
        unsafe {
            let raw = gl.create_framebuffer().map_err(Error::Gl)?;
            gpu.created(GlObject::Framebuffer);
            let fb = Framebuffer {
                gpu: gpu.clone(),
                raw,
                colors,
                clears: attachments.iter().map(|a| a.map_or([0.0; 4], |a| a.clear)).collect(),
                depth,
                width,
                height,
                flipped: RefCell::new(None),
            };
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(raw));
            gpu.label(glow::FRAMEBUFFER, raw.0.get(), "viewsynth framebuffer");
            let mut draw = Vec::new();
            for (i, t) in fb.colors.iter().enumerate() {
                let at = glow::COLOR_ATTACHMENT0 + i as u32;
                match t {
                    Some(t) => {
                        gl.framebuffer_texture_2d(glow::FRAMEBUFFER, at, glow::TEXTURE_2D, Some(t.raw), 0);
                        draw.push(at);
                    }
                    None => draw.push(glow::NONE),
                }
            }
            if let Some(d) = &fb.depth {
                gl.framebuffer_texture_2d(
                    glow::FRAMEBUFFER,
                    glow::DEPTH_ATTACHMENT,
                    glow::TEXTURE_2D,
                    Some(d.raw),
                    0,
                );
            }
            gl.draw_buffers(&draw);
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            if status != glow::FRAMEBUFFER_COMPLETE {
                return Err(Error::Gl(format!("framebuffer incomplete: 0x{status:04X}")));
            }
            gpu.check("framebuffer creation")?;
            Ok(fb)
        }
    }

    /// Name this framebuffer and its attachments for debuggers (RenderDoc, apitrace).
    pub fn with_label(self, name: &str) -> Self {
        self.gpu.label(glow::FRAMEBUFFER, self.raw.0.get(), name);
        for (i, t) in self.colors.iter().enumerate() {
            if let Some(t) = t {
                self.gpu
                    .label(glow::TEXTURE, t.raw.0.get(), &format!("{name} colour {i}"));
            }
        }
        if let Some(d) = &self.depth {
            self.gpu.label(glow::TEXTURE, d.raw.0.get(), &format!("{name} depth"));
        }
        self
    }

    pub(super) fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// Bind for drawing, set the viewport and clear every attachment (depth to `clear_depth`).
    /// Called by [`Framebuffer::begin_pass`] after it applied the draw state, whose baseline
    /// has scissor off and every write mask on.
    pub(super) fn bind_and_clear(&self, clear_depth: f32) {
        let gl = self.gpu.gl();
        // SAFETY: valid FBO; clear values sized per attachment type.
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.raw));
            gl.viewport(0, 0, self.width as i32, self.height as i32);
            for (i, (t, c)) in self.colors.iter().zip(&self.clears).enumerate() {
                let Some(t) = t else { continue };
                if matches!(t.format, TextureFormat::R32Ui | TextureFormat::R8Ui) {
                    let v = [c[0] as u32, c[1] as u32, c[2] as u32, c[3] as u32];
                    gl.clear_buffer_u32_slice(glow::COLOR, i as u32, &v);
                } else {
                    gl.clear_buffer_f32_slice(glow::COLOR, i as u32, c);
                }
            }
            if self.depth.is_some() {
                gl.clear_buffer_f32_slice(glow::DEPTH, 0, &[clear_depth]);
            }
        }
    }

    /// Read colour attachment `index` back (rows in memory order, row 0 = framebuffer row 0,
    /// the texture's own transfer layout); None for an empty slot. Goes through the streaming
    /// readback and waits for it: callers that can overlap work use [`Framebuffer::read_async`].
    #[cfg(test)]
    pub fn read_color(&self, index: usize) -> Result<Option<Vec<u8>>> {
        let Some(t) = self.colors.get(index).and_then(|t| t.as_ref()) else {
            return Ok(None);
        };
        let (format, ty, bytes_per_pixel) = t.format.transfer();
        let layout = ReadFormat {
            format,
            ty,
            bytes_per_pixel,
        };
        match self.read_async(index, layout, false)? {
            Some(read) => Ok(Some(read.finish()?)),
            None => Ok(None),
        }
    }

    /// Queue a read of colour attachment `index` in `layout` (which may pack channels, e.g.
    /// RGB out of RGBA8) into a pooled pixel-pack buffer; None for an empty slot. With
    /// `flip_rows` the rows arrive bottom row first: the attachment is first blitted upside down
    /// into a companion framebuffer on the GPU, so the CPU never reorders rows.
    pub fn read_async(&self, index: usize, layout: ReadFormat, flip_rows: bool) -> Result<Option<PendingRead>> {
        if self.colors.get(index).and_then(|t| t.as_ref()).is_none() {
            return Ok(None);
        }
        let gl = self.gpu.gl();
        let at = glow::COLOR_ATTACHMENT0 + index as u32;
        let (w, h) = (self.width as i32, self.height as i32);
        // Mesa packs rows in reverse while copying (GL_MESA_pack_invert): no extra pass, which
        // on a software rasteriser costs as much as the draw. Elsewhere a GPU blit flips.
        let pack_invert = flip_rows && self.gpu.has_pack_invert();
        let source = if flip_rows && !pack_invert {
            let mut flipped = self.flipped.borrow_mut();
            if flipped.is_none() {
                let attachments: Vec<Option<Attachment>> = self
                    .colors
                    .iter()
                    .map(|t| {
                        t.as_ref().map(|t| Attachment {
                            format: t.format,
                            clear: [0.0; 4],
                        })
                    })
                    .collect();
                *flipped = Some(Box::new(Framebuffer::new(
                    &self.gpu,
                    self.width,
                    self.height,
                    &attachments,
                    false,
                )?));
            }
            let target = flipped.as_ref().expect("created above").raw;
            let mut draw = vec![glow::NONE; self.colors.len()];
            draw[index] = at;
            // SAFETY: both framebuffers are complete and of the same size and formats; the
            // blit copies attachment `index` with its rows reversed.
            unsafe {
                gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.raw));
                gl.read_buffer(at);
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(target));
                gl.draw_buffers(&draw);
                gl.disable(glow::SCISSOR_TEST);
                gl.blit_framebuffer(0, 0, w, h, 0, h, w, 0, glow::COLOR_BUFFER_BIT, glow::NEAREST);
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, None);
            }
            target
        } else {
            self.raw
        };
        // SAFETY: valid framebuffer with attachment `index` present.
        unsafe {
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(source));
            gl.read_buffer(at);
        }
        if pack_invert {
            // SAFETY: a pixel-store flag of GL_MESA_pack_invert, reset right after the read.
            unsafe { gl.pixel_store_i32(PACK_INVERT_MESA, 1) };
        }
        let read = PendingRead::queue(&self.gpu, self.width, self.height, layout);
        // SAFETY: resetting pixel-store state and unbinding are always valid.
        unsafe {
            if pack_invert {
                gl.pixel_store_i32(PACK_INVERT_MESA, 0);
            }
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
        }
        Ok(Some(read?))
    }

    pub(super) fn unbind(&self) {
        // SAFETY: binding the default framebuffer is always valid.
        unsafe { self.gpu.gl().bind_framebuffer(glow::FRAMEBUFFER, None) }
    }
}

impl Drop for Framebuffer {
    fn drop(&mut self) {
        // SAFETY: handle owned by self; the textures drop after it.
        unsafe { self.gpu.gl().delete_framebuffer(self.raw) }
        self.gpu.deleted(GlObject::Framebuffer);
    }
}
