//! GPU layer: an EGL context and RAII wrappers over raw glow handles. Nothing outside this
//! folder touches a raw GL handle.

mod buffer;
pub mod devices;
mod egl;
mod framebuffer;
mod limits;
pub mod pixels;
mod policy;
mod program;
mod readback;
mod texture;
mod timer;
mod vertex_array;

pub use buffer::IndexBuffer;
pub use devices::EglDevice;
pub use egl::{DeviceChoice, EglContext, GpuInfo};
pub use framebuffer::{Attachment, Framebuffer};
pub use limits::check_image_size;
pub use policy::GpuPolicy;
pub use program::Program;
pub use readback::{PendingRead, ReadFormat};
pub use texture::{Texture, TextureFormat};
pub use timer::{DeferredTimer, GpuTimer, Timing};
pub use vertex_array::VertexArray;

use crate::error::{Error, Result};
use glow::HasContext;
use std::cell::RefCell;
use std::rc::Rc;

/// A shared handle to the current GL context. Resources keep one so the context outlives them.
#[derive(Clone)]
pub struct Gpu(Rc<GpuInner>);

/// The context and the per-context pools of reusable objects (readback buffers, queries).
pub(crate) struct GpuInner {
    ctx: EglContext,
    readback: RefCell<readback::ReadbackPool>,
    /// GL_MESA_pack_invert is supported and in use: glReadPixels reverses rows while packing.
    pack_invert: std::cell::Cell<bool>,
    pack_invert_supported: bool,
}

impl Drop for GpuInner {
    fn drop(&mut self) {
        // Pooled objects go while the context is still alive (it is dropped after this).
        self.readback.borrow_mut().clear(&self.ctx.gl);
    }
}

impl Gpu {
    /// A context on `choice` under the default policy (which still honours
    /// `VIEWSYNTH_REQUIRE_GPU`).
    pub fn new(choice: DeviceChoice) -> Result<Self> {
        Self::open(choice, GpuPolicy::default())
    }

    /// A context on `choice`, refused with [`Error::SoftwareRenderer`] when the policy (or
    /// `VIEWSYNTH_REQUIRE_GPU=1`) requires hardware and the renderer is software.
    pub fn open(choice: DeviceChoice, policy: GpuPolicy) -> Result<Self> {
        let policy = policy.with_env()?;
        let ctx = EglContext::new(choice)?;
        policy.check(&ctx.info)?;
        let pack_invert = ctx.gl.supported_extensions().contains("GL_MESA_pack_invert");
        Ok(Gpu(Rc::new(GpuInner {
            ctx,
            readback: RefCell::default(),
            pack_invert: std::cell::Cell::new(pack_invert),
            pack_invert_supported: pack_invert,
        })))
    }

    pub fn gl(&self) -> &glow::Context {
        &self.0.ctx.gl
    }

    pub fn info(&self) -> &GpuInfo {
        &self.0.ctx.info
    }

    /// `glClipControl(origin, depth)`: not in glow, loaded through eglGetProcAddress.
    pub fn clip_control(&self, origin: u32, depth: u32) {
        // SAFETY: GL 4.5 entry point with two enum arguments; the context is current.
        unsafe { (self.0.ctx.clip_control)(origin, depth) }
    }

    /// Whether reads can flip rows while packing (GL_MESA_pack_invert); otherwise a blit does.
    pub fn has_pack_invert(&self) -> bool {
        self.0.pack_invert.get()
    }

    /// Use GL_MESA_pack_invert where supported (the default) or the blit: tests and benchmarks
    /// compare the two flip paths on one context.
    pub fn use_pack_invert(&self, on: bool) {
        self.0.pack_invert.set(on && self.0.pack_invert_supported);
    }

    /// Fail on any pending GL error, naming what was being done.
    pub fn check(&self, what: &str) -> Result<()> {
        // SAFETY: plain state query.
        let err = unsafe { self.gl().get_error() };
        if err == glow::NO_ERROR {
            Ok(())
        } else {
            Err(Error::Gl(format!("{what}: GL error 0x{err:04X}")))
        }
    }

    /// Largest image side this context renders and samples without tiling.
    pub fn max_image_side(&self) -> u32 {
        let i = self.info();
        i.max_texture_size.min(i.max_viewport[0]).min(i.max_viewport[1]).max(0) as u32
    }

    /// [`check_image_size`] against this context's [`Self::max_image_side`].
    pub fn check_image_size(&self, name: &str, width: u32, height: u32) -> Result<()> {
        check_image_size(name, width.into(), height.into(), self.max_image_side())
    }
}

/// Name a GL object for debuggers (RenderDoc, apitrace); KHR_debug is core since GL 4.3.
pub(crate) fn label(gl: &glow::Context, kind: u32, raw: u32, name: &str) {
    // SAFETY: `raw` names a live object of `kind` on the current context.
    unsafe { gl.object_label(kind, raw, Some(name)) }
}
