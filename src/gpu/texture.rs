//! 2-D textures with immutable storage, upload and readback.

use super::census::GlObject;
use super::Gpu;
use crate::error::{Error, Result};
use glow::HasContext;

/// Texel formats used by the passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureFormat {
    /// 8-bit RGBA, normalised.
    Rgba8,
    /// 8-bit single channel, normalised.
    R8,
    /// 8-bit unsigned integer, single channel.
    R8Ui,
    /// 32-bit float, single channel.
    R32F,
    /// 32-bit float RGBA.
    Rgba32F,
    /// 32-bit unsigned integer, single channel.
    R32Ui,
    /// 32-bit float depth buffer.
    Depth32F,
}

impl TextureFormat {
    fn internal(self) -> u32 {
        match self {
            TextureFormat::Rgba8 => glow::RGBA8,
            TextureFormat::R8 => glow::R8,
            TextureFormat::R8Ui => glow::R8UI,
            TextureFormat::R32F => glow::R32F,
            TextureFormat::Rgba32F => glow::RGBA32F,
            TextureFormat::R32Ui => glow::R32UI,
            TextureFormat::Depth32F => glow::DEPTH_COMPONENT32F,
        }
    }
    /// (format, type, bytes per texel) for transfers.
    pub(super) fn transfer(self) -> (u32, u32, usize) {
        match self {
            TextureFormat::Rgba8 => (glow::RGBA, glow::UNSIGNED_BYTE, 4),
            TextureFormat::R8 => (glow::RED, glow::UNSIGNED_BYTE, 1),
            TextureFormat::R8Ui => (glow::RED_INTEGER, glow::UNSIGNED_BYTE, 1),
            TextureFormat::R32F => (glow::RED, glow::FLOAT, 4),
            TextureFormat::Rgba32F => (glow::RGBA, glow::FLOAT, 16),
            TextureFormat::R32Ui => (glow::RED_INTEGER, glow::UNSIGNED_INT, 4),
            TextureFormat::Depth32F => (glow::DEPTH_COMPONENT, glow::FLOAT, 4),
        }
    }
}

/// A 2D texture owning its GL object (deleted on drop).
pub struct Texture {
    gpu: Gpu,
    pub(super) raw: glow::Texture,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) format: TextureFormat,
}

impl Texture {
    /// Allocate a texture; `data` (tightly packed rows, row 0 first) is uploaded when given.
    /// Sampling is nearest with clamp-to-edge: passes that filter do it themselves in f32 with
    /// `texelFetch`, because fixed-function bilinear weights have only ~8 bits.
    pub fn new(gpu: &Gpu, width: u32, height: u32, format: TextureFormat, data: Option<&[u8]>) -> Result<Self> {
        gpu.check_image_size("texture size", width, height)?;
        let gl = gpu.gl();
        let (fmt, ty, bpp) = format.transfer();
        if let Some(d) = data {
            let need = width as usize * height as usize * bpp;
            if d.len() != need {
                return Err(Error::Gl(format!(
                    "texture upload: {} bytes given, {need} needed",
                    d.len()
                )));
            }
        }
        // SAFETY: fresh texture; storage sized width x height; data length checked above.
        unsafe {
            let raw = gl.create_texture().map_err(Error::Gl)?;
            gpu.created(GlObject::Texture);
            gl.bind_texture(glow::TEXTURE_2D, Some(raw));
            gpu.label(glow::TEXTURE, raw.0.get(), "viewsynth texture");
            gl.tex_storage_2d(glow::TEXTURE_2D, 1, format.internal(), width as i32, height as i32);
            for (p, v) in [
                (glow::TEXTURE_MIN_FILTER, glow::NEAREST),
                (glow::TEXTURE_MAG_FILTER, glow::NEAREST),
                (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE),
                (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE),
            ] {
                gl.tex_parameter_i32(glow::TEXTURE_2D, p, v as i32);
            }
            if let Some(d) = data {
                gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
                gl.tex_sub_image_2d(
                    glow::TEXTURE_2D,
                    0,
                    0,
                    0,
                    width as i32,
                    height as i32,
                    fmt,
                    ty,
                    glow::PixelUnpackData::Slice(Some(d)),
                );
            }
            gl.bind_texture(glow::TEXTURE_2D, None);
            let tex = Texture {
                gpu: gpu.clone(),
                raw,
                width,
                height,
                format,
            };
            gpu.check("texture allocation")?;
            Ok(tex)
        }
    }

    /// Replace the whole content (same size and format) without reallocating: streams of
    /// same-sized frames reuse one texture.
    pub fn upload(&self, data: &[u8]) -> Result<()> {
        let (fmt, ty, bpp) = self.format.transfer();
        let need = self.width as usize * self.height as usize * bpp;
        if data.len() != need {
            return Err(Error::Gl(format!(
                "texture upload: {} bytes given, {need} needed",
                data.len()
            )));
        }
        let gl = self.gpu.gl();
        // SAFETY: the texture has storage of exactly this size; data length checked above.
        unsafe {
            gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            gl.tex_sub_image_2d(
                glow::TEXTURE_2D,
                0,
                0,
                0,
                self.width as i32,
                self.height as i32,
                fmt,
                ty,
                glow::PixelUnpackData::Slice(Some(data)),
            );
            gl.bind_texture(glow::TEXTURE_2D, None);
        }
        self.gpu.check("texture upload")
    }

    /// Name this texture for debuggers (RenderDoc, apitrace).
    pub fn with_label(self, name: &str) -> Self {
        self.gpu.label(glow::TEXTURE, self.raw.0.get(), name);
        self
    }

    /// Bind as image unit `unit` for compute load/store/atomics (R32UI or R32F, the image
    /// formats the passes use) until the returned binding is dropped.
    pub fn bind_image(&self, unit: u32) -> Result<ImageBinding> {
        let format = match self.format {
            TextureFormat::R32Ui => glow::R32UI,
            TextureFormat::R32F => glow::R32F,
            TextureFormat::Rgba8 => glow::RGBA8,
            other => return Err(Error::Gl(format!("image binding of a {other:?} texture"))),
        };
        // SAFETY: valid 32-bit-per-texel texture, level 0, read-write as an image of its own
        // format.
        unsafe {
            self.gpu
                .gl()
                .bind_image_texture(unit, Some(self.raw), 0, false, 0, glow::READ_WRITE, format)
        };
        Ok(ImageBinding {
            gpu: self.gpu.clone(),
            unit,
        })
    }

    /// Fill every texel of a single-channel 32-bit texture (R32UI, R32F) with the 4 bytes of
    /// `bits` (glClearTexImage: the driver fills it, no upload).
    pub fn clear_bits(&self, bits: u32) -> Result<()> {
        let (format, ty, bpp) = self.format.transfer();
        if bpp != 4 || !matches!(self.format, TextureFormat::R32Ui | TextureFormat::R32F) {
            return Err(Error::Gl(format!("clear of a {:?} texture", self.format)));
        }
        let value = bits.to_ne_bytes();
        // SAFETY: level 0 of a live texture; `value` holds one texel of its transfer format.
        unsafe {
            self.gpu
                .0
                .ctx
                .clip_control
                .ClearTexImage(self.raw.0.get(), 0, format, ty, value.as_ptr().cast())
        };
        self.gpu.check("texture clear")
    }

    /// Bind to texture unit `unit`.
    pub fn bind(&self, unit: u32) {
        // SAFETY: valid handle.
        unsafe {
            self.gpu.gl().active_texture(glow::TEXTURE0 + unit);
            self.gpu.gl().bind_texture(glow::TEXTURE_2D, Some(self.raw));
        }
    }
}

/// A texture bound as a compute image unit; unbound on drop.
pub struct ImageBinding {
    gpu: Gpu,
    unit: u32,
}

impl Drop for ImageBinding {
    fn drop(&mut self) {
        // SAFETY: unbinding an image unit is always valid.
        unsafe {
            self.gpu
                .gl()
                .bind_image_texture(self.unit, None, 0, false, 0, glow::READ_WRITE, glow::R32UI)
        }
    }
}

impl Drop for Texture {
    fn drop(&mut self) {
        // SAFETY: handle owned by self.
        unsafe { self.gpu.gl().delete_texture(self.raw) }
        self.gpu.deleted(GlObject::Texture);
    }
}
