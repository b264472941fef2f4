//! Backend-neutral render passes: what a capability asks the GPU to do, described once and run
//! by either executor (OpenGL: `crate::gpu`'s `GlExecutor`; Vulkan: `crate::vulkan::VkExecutor`).
//! This folder knows no backend: it holds the vocabulary both executors share (the shader
//! library [`shaders`], [`Timing`], [`GpuPolicy`], the image-size rule [`check_image_size`]),
//! and each backend sits above it, mirror images.
//!
//! Design (after vello's recorded passes): a capability describes a pass as data and never
//! calls a graphics API. A [`Draw`] names
//! - the program (a [`ShaderProgram`]: the registry's `ProgramKind` and its typed switches under
//!   the conventions), which both backends build from the same GLSL (SPIR-V by build.rs);
//! - one parameter block: the bytes of a `#[repr(C)]` bytemuck `Pod` struct made with
//!   [`param_block!`], mirrored field for field by a std140 block (binding 0: a uniform block
//!   under GL, a read-only storage buffer under Vulkan, shaders/common/vulkan.glsl) in one
//!   `*_params.glsl` file that both backends include, so there are no loose uniforms and no
//!   hand-packed byte offsets (the layout test holds every block against the offsets the GL
//!   compiler reports);
//! - the images it samples, bound at bindings 1, 2, ... in the order listed;
//! - its viewport inside the [`Target`] (the colour attachments, one per fragment output
//!   location; an output not asked for gets no attachment and no readback).
//!
//! Rows: images are uploaded and attachments read in *memory* order, row 0 = NDC y = -1 in both
//! APIs; [`Target::rows`] says how memory rows map to the top-down files, and the executor
//! returns top-down rows (GL flips on the GPU while reading, Vulkan while copying out).
//!
//! A [`Device`] is a shared handle to one executor: renderers keep a clone, upload their inputs
//! once ([`Device::upload`], freed when the [`Image`] drops) and render many times; executors
//! cache programs/pipelines and targets, so a steady state creates nothing.

mod limits;
pub mod pixels;
mod policy;
#[cfg(test)]
mod readback_tests;
pub mod shaders;
mod timing;

pub use crate::convention::Conventions;
use crate::convention::RowOrder;
use crate::error::Result;
pub use limits::check_image_size;
pub use policy::{parse_require_env, GpuPolicy, REQUIRE_GPU_ENV};
pub use shaders::{ProgramKind, ShaderProgram};
use std::cell::RefCell;
use std::rc::Rc;
pub use timing::Timing;

/// Texel formats a pass samples or renders into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// 8-bit RGBA, normalised; read back as RGB (3 bytes a pixel).
    Rgba8,
    /// 32-bit float, single channel.
    R32F,
    /// 8-bit single channel, normalised.
    R8,
    /// 32-bit unsigned integer, single channel (atomics; sampled with a `usampler2D`).
    R32Ui,
    /// 8-bit unsigned integer, single channel (flags; sampled with a `usampler2D`).
    R8Ui,
    /// 4 x 32-bit float (per-column and per-row lookups located in f64 on the host).
    Rgba32F,
}

impl Format {
    /// Bytes a texel of an uploaded image.
    pub fn texel_bytes(self) -> usize {
        match self {
            Format::Rgba8 | Format::R32F | Format::R32Ui => 4,
            Format::R8 | Format::R8Ui => 1,
            Format::Rgba32F => 16,
        }
    }

    /// Whether this format's read-back texels come as f32s ([`Texels::Floats`]) rather than
    /// bytes: the one rule both executors follow.
    pub fn reads_as_floats(self) -> bool {
        matches!(self, Format::R32F | Format::Rgba32F)
    }
}

/// Host texels of an image to upload, rows in memory order.
#[derive(Debug, Clone, Copy)]
pub struct ImageData<'a> {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Texel format of `bytes`.
    pub format: Format,
    /// `width * height * format.texel_bytes()` bytes.
    pub bytes: &'a [u8],
    /// Debugger name (GL object label, Vulkan debug-utils name).
    pub label: &'a str,
}

impl<'a> ImageData<'a> {
    /// `bytes` as `width` x `height` texels of `format`.
    pub fn new(width: u32, height: u32, format: Format, bytes: &'a [u8], label: &'a str) -> Self {
        ImageData {
            width,
            height,
            format,
            bytes,
            label,
        }
    }

    /// RGBA8 texels (an RGB image goes through [`pixels::rgb_to_rgba`] first).
    pub fn rgba8(width: u32, height: u32, texels: &'a [u8], label: &'a str) -> Self {
        Self::new(width, height, Format::Rgba8, texels, label)
    }

    /// R32F texels: the f32s' native-endian bytes, borrowed as they are.
    pub fn r32f(width: u32, height: u32, values: &'a [f32], label: &'a str) -> Self {
        Self::new(width, height, Format::R32F, bytemuck::cast_slice(values), label)
    }

    /// R8UI texels (flags, source bits).
    pub fn r8ui(width: u32, height: u32, texels: &'a [u8], label: &'a str) -> Self {
        Self::new(width, height, Format::R8Ui, texels, label)
    }
}

/// An executor's handle of an uploaded or created image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ImageId(pub usize);

/// An executor's handle of a storage buffer (u32 words).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BufferId(pub usize);

/// An image a step loads, stores or updates atomically.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StorageImage {
    /// A created image ([`Device::create_image`]).
    Image(ImageId),
    /// Output location `k` of the run's target, after its draws (e.g. a compute pass rewriting
    /// some texels of the colour the draws wrote), or, in a run without draws, after the clear
    /// (a compute pass writing the outputs: the stereo matcher).
    Output(usize),
}

/// How many work groups a dispatch runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Groups {
    /// x, y (z = 1).
    Fixed([u32; 2]),
    /// The 3 words at `offset_words` of `buffer`, which an earlier step wrote.
    Indirect {
        /// The buffer holding the counts.
        buffer: BufferId,
        /// Word offset of x (then y, z).
        offset_words: usize,
    },
}

/// A compute dispatch.
#[derive(Debug, Clone)]
pub struct Dispatch<'a> {
    /// The program and its switches.
    pub program: ShaderProgram,
    /// The std140 parameter block (binding 0).
    pub params: &'a [u8],
    /// Sampled images, at bindings 1, 2, ... in this order.
    pub images: &'a [ImageId],
    /// Storage images, at `STORAGE_IMAGE(0)`, `(1)`, ... (shaders/common/bindings.glsl).
    pub storage_images: &'a [StorageImage],
    /// Storage buffers, at `STORAGE_BUFFER(0)`, `(1)`, ...
    pub buffers: &'a [BufferId],
    /// Work groups.
    pub groups: Groups,
}

/// One step of a run, executed in order; every step sees what the steps before it wrote (the
/// executors put a barrier between steps; consecutive draws share one render pass).
#[derive(Debug, Clone)]
pub enum Step<'a> {
    /// Fill a created single-channel 32-bit image with the 4 bytes of a value.
    Clear {
        /// The image (R32UI or R32F).
        image: ImageId,
        /// The texel's bits.
        bits: u32,
    },
    /// Write `words` at the start of `buffer`.
    WriteBuffer {
        /// The buffer.
        buffer: BufferId,
        /// The words (at most the buffer's size).
        words: &'a [u32],
    },
    /// A compute dispatch.
    Dispatch(Dispatch<'a>),
    /// A full-screen draw into the run's target.
    Draw(Draw<'a>),
}

/// The colour attachments of a pass.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Target {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Per fragment output location: its format, or None when not asked for (no attachment,
    /// nothing read back).
    pub outputs: Vec<Option<Format>>,
    /// How memory rows map to the top-down rows returned.
    pub rows: RowOrder,
    /// A depth buffer, cleared to these conventions' far value and tested with their compare
    /// (less, or greater under reversed-Z; GL's NDC depth range where they say so); None: no
    /// depth buffer.
    pub depth_test: Option<crate::convention::Conventions>,
}

/// One full-screen triangle.
#[derive(Debug, Clone)]
pub struct Draw<'a> {
    /// The program and its switches.
    pub program: ShaderProgram,
    /// The std140 parameter block (binding 0): `bytemuck::bytes_of` of a [`param_block!`] struct.
    pub params: &'a [u8],
    /// Sampled images, at bindings 1, 2, ... in this order.
    pub images: &'a [ImageId],
    /// Storage buffers, at `STORAGE_BUFFER(0)`, `(1)`, ... (shaders/common/bindings.glsl).
    pub buffers: &'a [BufferId],
    /// x, y (memory rows), width, height inside the target.
    pub viewport: [u32; 4],
    /// Triangles drawn (3 vertices each, pulled by the vertex shader: no vertex buffers); 1
    /// for the full-screen triangle.
    pub triangles: u32,
    /// An index buffer ([`Device::upload_indices`]): the triangles' vertices are its first
    /// `3 * triangles` indices (`gl_VertexID` is the index, so the vertex shader runs once per
    /// shared vertex where the driver caches); None: vertex `3 t + k` is corner k of triangle t.
    pub indices: Option<BufferId>,
}

impl<'a> Draw<'a> {
    /// One full-screen triangle of `program` over the whole `width` x `height` target, sampling
    /// `images`, without storage buffers or indices: what most passes draw.
    pub fn fullscreen(
        program: ShaderProgram,
        params: &'a [u8],
        images: &'a [ImageId],
        width: u32,
        height: u32,
    ) -> Self {
        Draw {
            program,
            params,
            images,
            buffers: &[],
            viewport: [0, 0, width, height],
            triangles: 1,
            indices: None,
        }
    }
}

/// One output's texels as read back, rows top-down: bytes (RGB8 from an RGBA8 target, R8, the
/// integer formats) or f32s (R32F, RGBA32F; [`Format::reads_as_floats`]). Each lands in a vector of its own element type, so a depth map takes the read
/// f32s as they are (a byte vector had to be copied into an aligned one: a second pass over
/// every depth output, ~1 ms a VGA target).
#[derive(Debug, Clone, PartialEq)]
pub enum Texels {
    /// RGB8 colour (packed from RGBA8), R8 and the integer formats.
    Bytes(Vec<u8>),
    /// R32F and RGBA32F.
    Floats(Vec<f32>),
}

impl Texels {
    /// The texels as bytes (f32s as their native-endian bytes, copied).
    pub fn into_bytes(self) -> Result<Vec<u8>> {
        match self {
            Texels::Bytes(b) => Ok(b),
            Texels::Floats(f) => crate::alloc::try_copy(bytemuck::cast_slice(&f), "readback"),
        }
    }

    /// The texels as f32s (bytes reinterpreted, copied; their length a multiple of 4).
    pub fn into_floats(self) -> Result<Vec<f32>> {
        match self {
            Texels::Bytes(b) => crate::alloc::try_pod_collect(&b, "depth readback"),
            Texels::Floats(f) => Ok(f),
        }
    }
}

/// What a pass read back: per output location, top-down texels where asked for.
#[derive(Debug)]
pub struct Rendered {
    /// Per location of [`Target::outputs`].
    pub outputs: Vec<Option<Texels>>,
    /// Wall time of draws and readback (and GPU time where the backend measures it).
    pub timing: Timing,
    /// The target's width and height (0 x 0 without one).
    pub size: (u32, u32),
    /// The graphics API the run was on (named by a [`crate::Error::Readback`]).
    pub api: Api,
}

impl Target {
    /// A view pass's target: colour (RGBA8, read as RGB) and depth (R32F) at locations 0 and 1
    /// where asked for, the mask or source bits (R8) at 2 always; no depth test.
    pub fn view(width: u32, height: u32, color: bool, depth: bool, rows: RowOrder) -> Target {
        Target {
            width,
            height,
            outputs: vec![
                color.then_some(Format::Rgba8),
                depth.then_some(Format::R32F),
                Some(Format::R8),
            ],
            rows,
            depth_test: None,
        }
    }
}

impl Rendered {
    /// Output `i` as an RGB image, where it was rendered.
    pub fn color(&mut self, i: usize) -> Result<Option<crate::io::RgbImage>> {
        let (w, h) = self.size;
        self.outputs[i]
            .take()
            .map(|c| crate::io::RgbImage::new(w, h, c.into_bytes()?))
            .transpose()
    }

    /// Output `i` as a depth map (its f32 texels), where it was rendered.
    pub fn depth(&mut self, i: usize) -> Result<Option<crate::io::DepthMap>> {
        let (w, h) = self.size;
        self.outputs[i]
            .take()
            .map(|d| crate::io::DepthMap::new(w, h, d.into_floats()?))
            .transpose()
    }

    /// Output `i`'s bytes (asked for, so present), or an error naming the pass.
    pub fn take(&mut self, i: usize, what: &str) -> Result<Vec<u8>> {
        self.take_texels(i, what)?.into_bytes()
    }

    /// Output `i`'s f32s (asked for, so present), or an error naming the pass.
    pub fn take_floats(&mut self, i: usize, what: &str) -> Result<Vec<f32>> {
        self.take_texels(i, what)?.into_floats()
    }

    fn take_texels(&mut self, i: usize, what: &str) -> Result<Texels> {
        self.outputs
            .get_mut(i)
            .and_then(Option::take)
            .ok_or_else(|| self.api.readback_error(format!("{what}: output {i} was not rendered")))
    }
}

/// The graphics API under a [`Device`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Api {
    /// OpenGL 4.5 core over EGL.
    Gl,
    /// Vulkan 1.3.
    Vulkan,
}

impl Api {
    /// The API's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Api::Gl => "OpenGL",
            Api::Vulkan => "Vulkan",
        }
    }

    /// A [`crate::Error::Readback`] of a run on this API.
    pub fn readback_error(self, message: impl Into<String>) -> crate::Error {
        crate::Error::Readback {
            backend: self.name(),
            message: message.into(),
        }
    }
}

/// A queued run ([`Executor::submit`]); its outputs come with [`Executor::wait`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ticket(pub usize);

/// Runs pass descriptions on one graphics API.
pub trait Executor {
    /// Which API this is.
    fn api(&self) -> Api;
    /// Largest image side this device renders and samples.
    fn max_image_side(&self) -> u32;
    /// Upload `image`; the handle is valid until [`Executor::free`].
    fn upload(&mut self, image: &ImageData) -> Result<ImageId>;
    /// An image a step can store to and sample, contents undefined until written.
    fn create_image(&mut self, width: u32, height: u32, format: Format, label: &str) -> Result<ImageId>;
    /// Release an uploaded or created image.
    fn free(&mut self, id: ImageId);
    /// A storage buffer of `words` u32 words (also usable for indirect dispatch counts).
    fn create_buffer(&mut self, words: usize, label: &str) -> Result<BufferId>;
    /// Release a buffer.
    fn free_buffer(&mut self, id: BufferId);
    /// Replace the texels of an uploaded image (same size and format), ordered before every
    /// later submit and after every earlier one: a stream of same-sized inputs reuses one image.
    fn write_image(&mut self, id: ImageId, bytes: &[u8]) -> Result<()>;
    /// An immutable buffer of u32 indices for indexed draws ([`Draw::indices`]); freed with
    /// [`Executor::free_buffer`].
    fn upload_indices(&mut self, indices: &[u32], label: &str) -> Result<BufferId>;
    /// Queue `steps` in order; the draws (at most one contiguous group) render into `target`,
    /// whose attachments are cleared to 0 first (without draws: before the first step, so
    /// compute steps can store the outputs), and its outputs are copied out asynchronously.
    /// Returns without waiting; several runs may be in flight.
    fn submit(&mut self, target: Option<&Target>, steps: &[Step]) -> Result<Ticket>;
    /// Whether a submitted run has finished (never blocks).
    fn is_ready(&mut self, ticket: Ticket) -> bool;
    /// Wait for a submitted run and hand out its outputs, top-down (each ticket once).
    fn wait(&mut self, ticket: Ticket) -> Result<Rendered>;
    /// The renderer's name for manifests and reports.
    fn renderer(&self) -> String;
}

/// The draws of `steps` form one contiguous group (one render pass), and need a target.
pub(crate) fn check_steps(target: Option<&Target>, steps: &[Step]) -> Result<()> {
    let draws: Vec<usize> = (0..steps.len())
        .filter(|&i| matches!(steps[i], Step::Draw(_)))
        .collect();
    if let (Some(first), Some(last)) = (draws.first(), draws.last()) {
        if last - first + 1 != draws.len() {
            return Err(crate::Error::param(
                "pass steps",
                "draws must be contiguous (one render pass)",
            ));
        }
        if target.is_none() {
            return Err(crate::Error::param("pass steps", "draws without a target"));
        }
    }
    Ok(())
}

/// A shared handle to an executor (renderers keep clones).
#[derive(Clone)]
pub struct Device(Rc<RefCell<Box<dyn Executor>>>);

impl Device {
    /// A device over `executor`.
    pub fn new(executor: impl Executor + 'static) -> Self {
        Device(Rc::new(RefCell::new(Box::new(executor))))
    }

    /// Which API runs the passes.
    pub fn api(&self) -> Api {
        self.0.borrow().api()
    }

    /// Largest image side this device renders and samples.
    pub fn max_image_side(&self) -> u32 {
        self.0.borrow().max_image_side()
    }

    /// [`check_image_size`] against this device's limit.
    pub fn check_image_size(&self, name: &str, width: u32, height: u32) -> Result<()> {
        let max = self.0.borrow().max_image_side();
        check_image_size(name, width.into(), height.into(), max)
    }

    /// Upload `image` (checked against the device's size limit first).
    pub fn upload(&self, image: &ImageData) -> Result<Image> {
        self.check_image_size(image.label, image.width, image.height)?;
        let expected = image.width as usize * image.height as usize * image.format.texel_bytes();
        if image.bytes.len() != expected {
            return Err(crate::Error::param(
                image.label.to_string(),
                format!(
                    "{} bytes for {}x{} {:?}",
                    image.bytes.len(),
                    image.width,
                    image.height,
                    image.format
                ),
            ));
        }
        let id = self.0.borrow_mut().upload(image)?;
        Ok(Image {
            device: self.clone(),
            id,
            shape: (image.width, image.height, image.format),
        })
    }

    /// `image` into the one `slot` holds: its texels rewritten in place when it has `image`'s
    /// size and format (a steady-state frame allocates nothing), else the old image freed
    /// before the new one is uploaded (peak memory holds one). A failed write or upload leaves
    /// the slot empty, so the next call uploads anew. Returns the id of the image now held.
    pub fn put_image(&self, slot: &mut Option<Image>, image: &ImageData) -> Result<ImageId> {
        let shape = (image.width, image.height, image.format);
        let held = match slot.take() {
            Some(old) if old.shape == shape => {
                self.write_image(&old, image.bytes)?;
                old
            }
            old => {
                drop(old);
                self.upload(image)?
            }
        };
        Ok(slot.insert(held).id)
    }

    /// Run one pass: `draws` into `target`, outputs read back top-down.
    pub fn render(&self, target: &Target, draws: &[Draw]) -> Result<Rendered> {
        let steps: Vec<Step> = draws.iter().cloned().map(Step::Draw).collect();
        self.run(Some(target), &steps)
    }

    /// Run `steps` in order (draws into `target`, read back top-down at the end).
    pub fn run(&self, target: Option<&Target>, steps: &[Step]) -> Result<Rendered> {
        self.submit(target, steps)?.wait()
    }

    /// Queue `steps` (draws into `target`); the outputs come with [`Pending::wait`], so a
    /// caller can keep several runs in flight.
    pub fn submit(&self, target: Option<&Target>, steps: &[Step]) -> Result<Pending> {
        if let Some(t) = target {
            self.check_image_size("render target", t.width, t.height)?;
        }
        check_steps(target, steps)?;
        let ticket = self.0.borrow_mut().submit(target, steps)?;
        Ok(Pending {
            device: self.clone(),
            ticket: Some(ticket),
            size: target.map_or((0, 0), |t| (t.width, t.height)),
        })
    }

    /// Replace the texels of `image` (its size and format; see [`Executor::write_image`]).
    pub fn write_image(&self, image: &Image, bytes: &[u8]) -> Result<()> {
        self.0.borrow_mut().write_image(image.id, bytes)
    }

    /// An index buffer for [`Draw::indices`].
    pub fn upload_indices(&self, indices: &[u32], label: &str) -> Result<Buffer> {
        if indices.is_empty() {
            return Err(crate::Error::param(label.to_string(), "no indices"));
        }
        let id = self.0.borrow_mut().upload_indices(indices, label)?;
        Ok(Buffer {
            device: self.clone(),
            id,
        })
    }

    /// The renderer's name (GL_RENDERER, or "Vulkan: " and the device's name).
    pub fn renderer(&self) -> String {
        self.0.borrow().renderer()
    }

    /// A storage image of `width` x `height` (checked against the device's limit).
    pub fn create_image(&self, width: u32, height: u32, format: Format, label: &str) -> Result<Image> {
        self.check_image_size(label, width, height)?;
        let id = self.0.borrow_mut().create_image(width, height, format, label)?;
        Ok(Image {
            device: self.clone(),
            id,
            shape: (width, height, format),
        })
    }

    /// A storage buffer of `words` u32 words.
    pub fn create_buffer(&self, words: usize, label: &str) -> Result<Buffer> {
        let id = self.0.borrow_mut().create_buffer(words, label)?;
        Ok(Buffer {
            device: self.clone(),
            id,
        })
    }
}

/// A submitted run ([`Device::submit`]); dropping it unwaited waits and discards the outputs.
pub struct Pending {
    device: Device,
    ticket: Option<Ticket>,
    size: (u32, u32),
}

impl Pending {
    /// Whether the outputs have arrived (never blocks).
    pub fn is_ready(&self) -> bool {
        self.ticket.is_none_or(|t| self.device.0.borrow_mut().is_ready(t))
    }

    /// Wait for the run and hand out its outputs, top-down.
    pub fn wait(mut self) -> Result<Rendered> {
        let ticket = self
            .ticket
            .take()
            .ok_or_else(|| self.device.api().readback_error("run waited twice"))?;
        let mut out = self.device.0.borrow_mut().wait(ticket)?;
        out.size = self.size;
        Ok(out)
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if let Some(t) = self.ticket.take() {
            // An error here has nobody to go to; the executor frees the run's slot either way.
            let _ = self.device.0.borrow_mut().wait(t);
        }
    }
}

/// A storage buffer, released when dropped.
pub struct Buffer {
    device: Device,
    id: BufferId,
}

impl Buffer {
    /// The handle steps list.
    pub fn id(&self) -> BufferId {
        self.id
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        self.device.0.borrow_mut().free_buffer(self.id);
    }
}

/// An uploaded image, released when dropped.
pub struct Image {
    device: Device,
    id: ImageId,
    /// Width, height and texel format, as made.
    shape: (u32, u32, Format),
}

impl Image {
    /// The handle draws list.
    pub fn id(&self) -> ImageId {
        self.id
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        self.device.0.borrow_mut().free(self.id);
    }
}

/// A pass's parameter block: a `#[repr(C)]` Pod struct mirrored by a std140 GLSL block.
pub trait ParamBlock: bytemuck::Pod {
    /// The GLSL block name (its mirror in `shaders/<capability>/*_params.glsl`).
    const BLOCK: &'static str;
    /// Each field's GLSL name and byte offset in the Rust struct (`offset_of!`).
    const FIELDS: &'static [(&'static str, usize)];
}

/// Declares a parameter block: a `#[repr(C)]` Pod struct whose field names are the GLSL member
/// names, and its [`ParamBlock`] table (block name, field offsets) for the layout test. Fields
/// must be laid out so that std140 needs no padding the struct lacks (vec3 followed by a float,
/// arrays of 16-byte elements); the test catches any mismatch.
#[macro_export]
macro_rules! param_block {
    ($(#[$m:meta])* $vis:vis struct $name:ident ($block:literal) { $($(#[$fm:meta])* $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$m])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
        #[allow(non_snake_case, missing_docs)]
        $vis struct $name { $($(#[$fm])* pub $field: $ty),* }

        impl $crate::pass::ParamBlock for $name {
            const BLOCK: &'static str = $block;
            const FIELDS: &'static [(&'static str, usize)] =
                &[$((stringify!($field), std::mem::offset_of!($name, $field))),*];
        }
    };
}

/// A row-major f64 matrix as std140 `mat4` (column-major f32), as GLSL reads it.
pub fn mat4_std140(rows: &[[f64; 4]; 4]) -> [[f32; 4]; 4] {
    let mut cols = [[0f32; 4]; 4];
    for (r, row) in rows.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            cols[c][r] = *v as f32;
        }
    }
    cols
}

/// What a renderer can be opened on: an existing [`Device`] (shared), or a GL context (a new GL
/// executor on it), so GL callers keep passing `&Gpu`.
pub trait ToDevice {
    /// The device to render on.
    fn to_device(self) -> Result<Device>;
}

impl ToDevice for &Device {
    fn to_device(self) -> Result<Device> {
        Ok(self.clone())
    }
}

/// Objects an executor holds by handle (images, buffers): a freed slot is reused by the next
/// insert, so handles stay small and a steady state does not grow the table.
pub(crate) struct Slots<T>(Vec<Option<T>>);

impl<T> Default for Slots<T> {
    fn default() -> Self {
        Slots(Vec::new())
    }
}

impl<T> Slots<T> {
    /// Store `value`; its handle.
    pub(crate) fn insert(&mut self, value: T) -> usize {
        match self.0.iter().position(Option::is_none) {
            Some(i) => {
                self.0[i] = Some(value);
                i
            }
            None => {
                self.0.push(Some(value));
                self.0.len() - 1
            }
        }
    }

    /// The value at `i`, unless freed.
    pub(crate) fn get(&self, i: usize) -> Option<&T> {
        self.0.get(i).and_then(Option::as_ref)
    }

    /// Take the value at `i` out, freeing the slot.
    pub(crate) fn take(&mut self, i: usize) -> Option<T> {
        self.0.get_mut(i).and_then(Option::take)
    }

    /// Free slot `i` (dropping its value).
    pub(crate) fn remove(&mut self, i: usize) {
        if let Some(slot) = self.0.get_mut(i) {
            *slot = None;
        }
    }
}
