//! The GL executor: runs [`crate::pass::Draw`]s with the GPU layer's RAII objects (no raw GL
//! here), beside them as `crate::vulkan`'s executor is beside ash.
//! Programs are built once per [`ShaderProgram`], framebuffers once per size and output set
//! (the last few kept), the parameter blocks of a pass go into one uniform buffer at aligned
//! offsets (one `glBufferSubData` a pass), and outputs are read through the pooled pixel-pack
//! buffers with the row flip and RGB packing done on the GPU. Compute steps bind storage images
//! to image units and storage buffers to their bindings from 0 (shaders/common/bindings.glsl),
//! with `glMemoryBarrier(ALL)` between steps. A submit queues every read (fenced pixel-pack
//! buffers) and a deferred timer query and returns; `wait` maps the reads, so several runs can
//! be in flight and nothing waits on the GPU until their outputs are wanted.

use super::{
    Attachment, DeferredTimer, DrawState, Framebuffer, Gpu, IndexBuffer, PendingRead, Program, ReadFormat,
    StorageBuffer, Texture, TextureFormat, UniformBuffer, VertexArray,
};
use crate::convention::RowOrder;
use crate::error::{Error, Result};
use crate::pass::{
    Api, BufferId, Device, Executor, Format, Groups, ImageData, ImageId, Rendered, ShaderProgram, Slots, Step,
    StorageImage, Target, Texels, Ticket, Timing, ToDevice,
};
use std::time::Instant;

impl Device {
    /// OpenGL on `gpu`.
    pub fn gl(gpu: &Gpu) -> Result<Self> {
        Ok(Device::new(GlExecutor::new(gpu)?))
    }
}

/// A GL context opens a new GL executor on it, so GL callers keep passing `&Gpu`.
impl ToDevice for &Gpu {
    fn to_device(self) -> Result<Device> {
        Device::gl(self)
    }
}

/// Framebuffers kept for reuse (sizes and output sets seen most recently).
const KEPT_TARGETS: usize = 4;

fn texture_format(f: Format) -> TextureFormat {
    match f {
        Format::Rgba8 => TextureFormat::Rgba8,
        Format::R32F => TextureFormat::R32F,
        Format::R8 => TextureFormat::R8,
        Format::R32Ui => TextureFormat::R32Ui,
        Format::R8Ui => TextureFormat::R8Ui,
        Format::Rgba32F => TextureFormat::Rgba32F,
    }
}

fn read_format(f: Format) -> ReadFormat {
    match f {
        Format::Rgba8 => ReadFormat::RGB8,
        Format::R32F => ReadFormat::R32F,
        Format::R8 => ReadFormat::R8,
        Format::R32Ui => ReadFormat::R32UI,
        Format::R8Ui => ReadFormat::R8UI,
        Format::Rgba32F => ReadFormat::RGBA32F,
    }
}

/// A buffer a step binds: storage (compute, vertex pulling) or indices (indexed draws).
enum GlBuffer {
    Storage(StorageBuffer),
    Index(IndexBuffer),
}

/// A submitted run: its queued reads (each with whether its format reads as f32s) and timer.
struct InFlight {
    reads: Vec<Option<(PendingRead, bool)>>,
    timer: DeferredTimer,
    submit_ms: f64,
}

/// Size, outputs and whether there is a depth buffer.
type TargetKey = (u32, u32, Vec<Option<Format>>, bool);

/// Passes on an OpenGL context.
pub(crate) struct GlExecutor {
    gpu: Gpu,
    vao: VertexArray,
    /// Indexed draws bind their element buffer here (a VAO's state), pulled draws use `vao`.
    indexed_vao: VertexArray,
    params: UniformBuffer,
    programs: Vec<(ShaderProgram, Program)>,
    targets: Vec<(TargetKey, Framebuffer)>,
    images: Slots<Texture>,
    buffers: Slots<GlBuffer>,
    runs: Slots<InFlight>,
}

impl GlExecutor {
    /// An executor on `gpu`.
    pub(crate) fn new(gpu: &Gpu) -> Result<Self> {
        Ok(GlExecutor {
            gpu: gpu.clone(),
            vao: VertexArray::new(gpu)?.with_label("pass vertex array"),
            indexed_vao: VertexArray::new(gpu)?.with_label("pass indexed vertex array"),
            params: UniformBuffer::new(gpu)?,
            programs: Vec::new(),
            targets: Vec::new(),
            images: Slots::default(),
            buffers: Slots::default(),
            runs: Slots::default(),
        })
    }

    fn program(&mut self, spec: ShaderProgram) -> Result<usize> {
        if let Some(i) = self.programs.iter().position(|(s, _)| *s == spec) {
            return Ok(i);
        }
        let p = spec.build(&self.gpu)?;
        self.programs.push((spec, p));
        Ok(self.programs.len() - 1)
    }

    fn target(&mut self, t: &Target) -> Result<usize> {
        let key = (t.width, t.height, t.outputs.clone(), t.depth_test.is_some());
        if let Some(i) = self.targets.iter().position(|(k, _)| *k == key) {
            return Ok(i);
        }
        if self.targets.len() >= KEPT_TARGETS {
            self.targets.remove(0);
        }
        let attachments: Vec<Option<Attachment>> = t
            .outputs
            .iter()
            .map(|o| {
                o.map(|f| Attachment {
                    format: texture_format(f),
                    clear: [0.0; 4],
                })
            })
            .collect();
        let fb = Framebuffer::new(&self.gpu, t.width, t.height, &attachments, t.depth_test.is_some())?
            .with_label("pass target");
        self.targets.push((key, fb));
        Ok(self.targets.len() - 1)
    }
}

/// `n` rounded up to a multiple of `a`.
fn align(n: usize, a: usize) -> usize {
    n.div_ceil(a) * a
}

impl Executor for GlExecutor {
    fn api(&self) -> Api {
        Api::Gl
    }

    fn max_image_side(&self) -> u32 {
        self.gpu.max_image_side()
    }

    fn upload(&mut self, image: &ImageData) -> Result<ImageId> {
        let t = Texture::new(
            &self.gpu,
            image.width,
            image.height,
            texture_format(image.format),
            Some(image.bytes),
        )?
        .with_label(image.label);
        Ok(ImageId(self.images.insert(t)))
    }

    fn free(&mut self, id: ImageId) {
        self.images.remove(id.0);
    }

    fn create_image(&mut self, width: u32, height: u32, format: Format, label: &str) -> Result<ImageId> {
        let t = Texture::new(&self.gpu, width, height, texture_format(format), None)?.with_label(label);
        Ok(ImageId(self.images.insert(t)))
    }

    fn create_buffer(&mut self, words: usize, label: &str) -> Result<BufferId> {
        let b = StorageBuffer::new(&self.gpu, words)?.with_label(label);
        Ok(BufferId(self.buffers.insert(GlBuffer::Storage(b))))
    }

    fn upload_indices(&mut self, indices: &[u32], label: &str) -> Result<BufferId> {
        let b = IndexBuffer::new(&self.gpu, indices)?.with_label(label);
        Ok(BufferId(self.buffers.insert(GlBuffer::Index(b))))
    }

    fn write_image(&mut self, id: ImageId, bytes: &[u8]) -> Result<()> {
        // glTexSubImage2D: ordered after the draws already queued that sample the old texels.
        self.image(id)?.upload(bytes)
    }

    fn renderer(&self) -> String {
        self.gpu.info().renderer.clone()
    }

    fn is_ready(&mut self, ticket: Ticket) -> bool {
        self.runs
            .get(ticket.0)
            .is_none_or(|r| r.reads.iter().flatten().all(|(read, _)| read.is_ready()))
    }

    fn wait(&mut self, ticket: Ticket) -> Result<Rendered> {
        let run = self
            .runs
            .take(ticket.0)
            .ok_or_else(|| Error::Gl(format!("pass run {} was not submitted or was waited for", ticket.0)))?;
        let outputs = run
            .reads
            .into_iter()
            .map(|r| {
                r.map(|(r, floats)| match floats {
                    true => r.finish_f32().map(Texels::Floats),
                    false => r.finish().map(Texels::Bytes),
                })
                .transpose()
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Rendered {
            outputs,
            timing: Timing {
                gpu_ms: run.timer.read_ms(),
                wall_ms: run.submit_ms,
            },
            size: (0, 0),
            api: Api::Gl,
        })
    }

    fn free_buffer(&mut self, id: BufferId) {
        self.buffers.remove(id.0);
    }

    fn submit(&mut self, target: Option<&Target>, steps: &[Step]) -> Result<Ticket> {
        let t0 = Instant::now();
        // Programs first (compiles happen once per program), then the target.
        let mut programs = Vec::with_capacity(steps.len());
        for step in steps {
            programs.push(match step {
                Step::Draw(d) => Some(self.program(d.program)?),
                Step::Dispatch(d) => Some(self.program(d.program)?),
                _ => None,
            });
        }
        let fb = target.map(|t| self.target(t)).transpose()?;
        // Every step's block in one buffer, each at an aligned offset.
        let alignment = self.params.offset_alignment();
        let mut blocks = Vec::new();
        let mut offsets = Vec::with_capacity(steps.len());
        for step in steps {
            offsets.push(blocks.len());
            let params = match step {
                Step::Draw(d) => d.params,
                Step::Dispatch(d) => d.params,
                _ => &[],
            };
            blocks.extend_from_slice(params);
            blocks.resize(align(blocks.len(), alignment), 0);
        }
        if !blocks.is_empty() {
            self.params.write(&blocks)?;
        }
        let fb = fb.map(|i| &self.targets[i].1);
        let mut timer = DeferredTimer::begin(&self.gpu);
        let mut pass = None;
        if let (Some(fb), false) = (fb, steps.iter().any(|s| matches!(s, Step::Draw(_)))) {
            // No draws (no kept triangles, or compute steps storing to the outputs): the target
            // is still cleared, before the steps so that what they store survives.
            drop(fb.begin_pass(DrawState::default(), 1.0));
            self.gpu.memory_barrier();
        }
        for (k, step) in steps.iter().enumerate() {
            if k > 0 && !matches!((&steps[k - 1], step), (Step::Draw(_), Step::Draw(_))) {
                // What earlier steps wrote, before this one reads it.
                self.gpu.memory_barrier();
            }
            if !matches!(step, Step::Draw(_)) {
                pass = None;
            }
            match step {
                Step::Clear { image, bits } => self.image(*image)?.clear_bits(*bits)?,
                Step::WriteBuffer { buffer, words } => self.buffer(*buffer)?.write_head(words),
                Step::Draw(d) => {
                    let fb = fb.ok_or_else(|| Error::Gl("a draw without a target".into()))?;
                    if pass.is_none() {
                        let (state, clear) = match target.and_then(|t| t.depth_test) {
                            Some(conv) => (DrawState::depth_tested(&conv), conv.clear_depth() as f32),
                            None => (DrawState::default(), 1.0),
                        };
                        pass = Some(fb.begin_pass(state, clear));
                    }
                    let p = &self.programs[programs[k].expect("built above")].1;
                    self.bind(p, (offsets[k], d.params.len()), d.images, d.buffers)?;
                    let [x, y, w, h] = d.viewport;
                    let pass = pass.as_ref().expect("begun above");
                    pass.viewport(x, y, w, h);
                    match d.indices {
                        Some(id) => match self.buffers.get(id.0) {
                            Some(GlBuffer::Index(ib)) => pass.draw_indexed(&self.indexed_vao, ib, d.triangles as usize),
                            _ => return Err(Error::Gl(format!("{}: buffer {} holds no indices", p.name(), id.0))),
                        },
                        None => pass.draw_triangles(&self.vao, d.triangles as usize),
                    }
                }
                Step::Dispatch(d) => {
                    let p = &self.programs[programs[k].expect("built above")].1;
                    self.bind(p, (offsets[k], d.params.len()), d.images, d.buffers)?;
                    // Bound while the dispatch runs, unbound when these drop.
                    let mut bound = Vec::with_capacity(d.storage_images.len());
                    for (unit, s) in d.storage_images.iter().enumerate() {
                        let t = match s {
                            StorageImage::Image(id) => self.image(*id)?,
                            StorageImage::Output(i) => fb
                                .and_then(|f| f.color(*i))
                                .ok_or_else(|| Error::Gl(format!("{}: no output {i} to store to", p.name())))?,
                        };
                        bound.push(t.bind_image(unit as u32)?);
                    }
                    match d.groups {
                        Groups::Fixed(g) => p.dispatch(g),
                        Groups::Indirect { buffer, offset_words } => {
                            p.dispatch_indirect(self.buffer(buffer)?, offset_words)
                        }
                    }
                    drop(bound);
                }
            }
        }
        drop(pass);
        timer.end();
        self.gpu.check("pass steps")?;
        let reads = match (target, fb) {
            (Some(target), Some(fb)) => {
                // What the steps wrote, before the readback.
                self.gpu.memory_barrier();
                let flip = target.rows == RowOrder::BottomUp;
                target
                    .outputs
                    .iter()
                    .enumerate()
                    .map(|(i, f)| match f {
                        Some(f) => Ok(fb
                            .read_async(i, read_format(*f), flip)?
                            .map(|read| (read, f.reads_as_floats()))),
                        None => Ok(None),
                    })
                    .collect::<Result<Vec<_>>>()?
            }
            _ => Vec::new(),
        };
        let run = InFlight {
            reads,
            timer,
            submit_ms: t0.elapsed().as_secs_f64() * 1e3,
        };
        Ok(Ticket(self.runs.insert(run)))
    }
}

impl GlExecutor {
    fn image(&self, id: ImageId) -> Result<&Texture> {
        self.images
            .get(id.0)
            .ok_or_else(|| Error::Gl(format!("pass image {} was freed", id.0)))
    }

    fn buffer(&self, id: BufferId) -> Result<&StorageBuffer> {
        match self.buffers.get(id.0) {
            Some(GlBuffer::Storage(b)) => Ok(b),
            Some(GlBuffer::Index(_)) => Err(Error::Gl(format!("pass buffer {} holds indices", id.0))),
            None => Err(Error::Gl(format!("pass buffer {} was freed", id.0))),
        }
    }

    /// Make `p` current with its parameter block (`block`: offset and length in the uniform
    /// buffer) at binding 0, the sampled images at texture units 1, 2, ... (the GLSL
    /// `layout(binding = k)`) and the storage buffers at their bindings from 0.
    fn bind(&self, p: &Program, block: (usize, usize), images: &[ImageId], buffers: &[BufferId]) -> Result<()> {
        p.bind();
        if block.1 > 0 {
            self.params.bind_range(0, block.0, block.1);
        }
        for (k, id) in images.iter().enumerate() {
            let t = self
                .image(*id)
                .map_err(|_| Error::Gl(format!("{}: image {} was freed", p.name(), id.0)))?;
            t.bind(k as u32 + 1);
        }
        for (b, id) in buffers.iter().enumerate() {
            self.buffer(*id)?.bind_storage(b as u32);
        }
        Ok(())
    }
}
