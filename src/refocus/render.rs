//! GPU refocus. The programs are compiled once per `Refocuser`; a source (colour, depth and
//! the kept triangles) is uploaded into textures that the next source of the same size reuses;
//! each target renders into a framebuffer (kept per output size) holding only the requested
//! attachments, and its outputs are read back through the streaming readback of `gpu`: the row
//! order and the RGB packing happen on the GPU, the mapped bytes are the images' bytes.
//!
//! [`Refocuser::submit`] queues a target and returns at once; [`PendingRefocus::wait`] maps its
//! outputs later, so a caller can keep several targets (and frames) in flight.
//! [`Refocuser::render`] is the two in a row.

use super::grid::{axis_lookup, Grid};
use super::mesh::MeshPass;
use super::{BreakRule, Method, OutputSet, RefocusSource};
use crate::camera::PinholeCamera;
use crate::convention::{Conventions, DepthPlanes, RowOrder};
use crate::error::{Error, Result};
use crate::gpu::{
    Attachment, DeferredTimer, DrawState, Framebuffer, Gpu, PendingRead, Program, ProgramKind, ReadFormat,
    ShaderProgram, Texture, TextureFormat, Timing, VertexArray,
};
use crate::io::{DepthMap, Mask, RgbImage};
use std::time::Instant;

/// Output sizes whose framebuffers are kept (a batch uses one; a sweep over sizes a few).
const KEEP_TARGET_SIZES: usize = 4;

/// One refocused view. Images are top-down whatever the row-order convention.
pub struct RefocusOutput {
    /// The target camera: intrinsics and image size.
    pub camera: PinholeCamera,
    /// 8-bit colour, 0 where invalid; None when not requested.
    pub rgb: Option<RgbImage>,
    /// View-space Z in metres, 0 where invalid.
    pub depth: Option<DepthMap>,
    /// 1 where a kept triangle covers the pixel centre, 0 elsewhere (PNG: 255 / 0); None when not requested.
    pub mask: Option<Mask>,
    /// `wall_ms`: host time to record the draw and queue the reads (no wait); `gpu_ms`: the
    /// draw's GPU time from a timer query read after the fence, where the driver's timers are
    /// meaningful.
    pub render: Timing,
    /// Host time spent waiting for the GPU and mapping the outputs (on a software renderer the
    /// rasterisation itself happens here).
    pub readback_ms: f64,
}

enum Geometry {
    Mesh(MeshPass),
    Fullscreen { program: Program, keep: Option<Texture> },
}

/// The uploaded source.
struct Source {
    camera: PinholeCamera,
    planes: DepthPlanes,
    rgb: Option<Texture>,
    depth: Texture,
}

/// A framebuffer of one output size and the per-target lookup textures of that size.
struct TargetSlot {
    framebuffer: Framebuffer,
    cols: Texture,
    rows: Texture,
}

/// Programs compiled for one set of settings, ready to take any number of sources and targets.
pub struct Refocuser {
    gpu: Gpu,
    conv: Conventions,
    outputs: OutputSet,
    rule: BreakRule,
    source: Option<Source>,
    geometry: Geometry,
    vao: VertexArray,
    /// Most recently used last.
    slots: Vec<TargetSlot>,
}

/// A target queued on the GPU: its outputs arrive through [`PendingRefocus::wait`]. Tied to
/// the GL thread.
pub struct PendingRefocus {
    camera: PinholeCamera,
    rgb: Option<PendingRead>,
    depth: Option<PendingRead>,
    mask: Option<PendingRead>,
    timer: DeferredTimer,
    submit_ms: f64,
}

impl PendingRefocus {
    /// Whether every output has arrived (never blocks).
    pub fn is_ready(&self) -> bool {
        [&self.rgb, &self.depth, &self.mask]
            .into_iter()
            .flatten()
            .all(PendingRead::is_ready)
    }

    /// Wait for the outputs and hand them out: one copy out of each mapped buffer, no
    /// per-pixel conversion (the GPU packed RGB, flipped rows and wrote the mask as 0/1).
    pub fn wait(self) -> Result<RefocusOutput> {
        let t0 = Instant::now();
        let (w, h) = (self.camera.width, self.camera.height);
        let rgb = match self.rgb {
            Some(r) => Some(RgbImage::new(w, h, r.finish()?)?),
            None => None,
        };
        let depth = match self.depth {
            Some(r) => Some(DepthMap::new(w, h, r.finish_f32()?)?),
            None => None,
        };
        let mask = match self.mask {
            Some(r) => Some(Mask::new(w, h, r.finish()?)?),
            None => None,
        };
        let readback_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(RefocusOutput {
            camera: self.camera,
            rgb,
            depth,
            mask,
            render: Timing {
                gpu_ms: self.timer.read_ms(),
                wall_ms: self.submit_ms,
            },
            readback_ms,
        }
        .finite())
    }
}

impl Refocuser {
    /// Compile the programs and upload `src`.
    pub fn new(
        gpu: &Gpu,
        src: &RefocusSource,
        rule: &BreakRule,
        method: Method,
        outputs: OutputSet,
        conv: Conventions,
    ) -> Result<Self> {
        let mut r = Refocuser::with_settings(gpu, rule, method, outputs, conv)?;
        r.set_source(src)?;
        Ok(r)
    }

    /// Compile the programs for these settings; a source comes with [`Refocuser::set_source`].
    pub fn with_settings(
        gpu: &Gpu,
        rule: &BreakRule,
        method: Method,
        outputs: OutputSet,
        conv: Conventions,
    ) -> Result<Self> {
        rule.validate()?;
        let geometry = match method {
            Method::Fullscreen => {
                let kind = ProgramKind::RefocusFullscreen { want_rgb: outputs.rgb };
                let program = ShaderProgram::new(conv, kind).build(gpu)?;
                Geometry::Fullscreen { program, keep: None }
            }
            Method::Mesh => Geometry::Mesh(MeshPass::new(gpu, conv, outputs.rgb)?),
        };
        Ok(Refocuser {
            gpu: gpu.clone(),
            conv,
            outputs,
            rule: *rule,
            source: None,
            geometry,
            vao: VertexArray::new(gpu)?.with_label("refocus vertex array"),
            slots: Vec::new(),
        })
    }

    /// Upload a new source, reusing the previous source's textures when the size matches.
    pub fn set_source(&mut self, src: &RefocusSource) -> Result<()> {
        src.validate()?;
        let gpu = self.gpu.clone();
        let (w, h) = (src.rgb.width, src.rgb.height);
        // The grid's cells include a half-pixel border ring: (w + 1) x (h + 1) of them, each a
        // texel of the coverage texture, so the source side is one less than the GPU's limit.
        crate::gpu::check_image_size("source size", w.into(), h.into(), super::max_source_side(&gpu))?;
        let grid = Grid { width: w, height: h };
        let keep = grid.keep_mask(&src.depth.data, &self.rule);
        let same_size = self
            .source
            .as_ref()
            .is_some_and(|s| s.camera.width == w && s.camera.height == h);
        let previous = if same_size { self.source.take() } else { None };
        self.source = None; // free a differently sized source before allocating
        match &mut self.geometry {
            Geometry::Fullscreen { keep: keep_tex, .. } => {
                let flags = grid.coverage_flags(&keep);
                let (cx, cy) = (grid.cells_x() as u32, grid.cells_y() as u32);
                match keep_tex {
                    Some(t) if (t.width(), t.height()) == (cx, cy) => t.upload(&flags)?,
                    _ => {
                        *keep_tex = None;
                        *keep_tex = Some(
                            Texture::new(&gpu, cx, cy, TextureFormat::R8Ui, Some(&flags))?
                                .with_label("refocus coverage flags"),
                        );
                    }
                }
            }
            Geometry::Mesh(mesh) => mesh.set_geometry(&gpu, &grid, &keep)?,
        }
        let rgba: Option<Vec<u8>> = self.outputs.rgb.then(|| crate::gpu::pixels::rgb_to_rgba(&src.rgb.data));
        let depth_bytes: &[u8] = bytemuck::cast_slice(&src.depth.data);
        let (rgb, depth) = match previous {
            Some(p) => {
                if let (Some(t), Some(d)) = (&p.rgb, &rgba) {
                    t.upload(d)?;
                }
                p.depth.upload(depth_bytes)?;
                (p.rgb, p.depth)
            }
            None => (
                match &rgba {
                    Some(d) => {
                        Some(Texture::new(&gpu, w, h, TextureFormat::Rgba8, Some(d))?.with_label("refocus source rgb"))
                    }
                    None => None,
                },
                Texture::new(&gpu, w, h, TextureFormat::R32F, Some(depth_bytes))?.with_label("refocus source depth"),
            ),
        };
        // Every kept vertex lies in [min, max] of the valid depths; the factor 2 leaves room for
        // the expanded border of each triangle (which the vertex shader keeps within it).
        let planes = match src.depth_range() {
            Some((lo, hi)) => DepthPlanes {
                near: 0.25 * lo,
                far: 4.0 * hi,
            },
            None => DepthPlanes { near: 1.0, far: 2.0 },
        };
        self.source = Some(Source {
            camera: src.camera(),
            planes,
            rgb,
            depth,
        });
        Ok(())
    }

    /// The context this refocuser renders on.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// Number of kept triangles (mesh path) for reports.
    pub fn triangle_count(&self) -> Option<usize> {
        match &self.geometry {
            Geometry::Mesh(mesh) => Some(mesh.triangle_count()),
            Geometry::Fullscreen { .. } => None,
        }
    }

    /// The slot for output size w x h, most recently used last; allocated on first use.
    fn slot(&mut self, w: u32, h: u32) -> Result<&TargetSlot> {
        if let Some(i) = self
            .slots
            .iter()
            .position(|s| (s.framebuffer.width(), s.framebuffer.height()) == (w, h))
        {
            let s = self.slots.remove(i);
            self.slots.push(s);
        } else {
            if self.slots.len() >= KEEP_TARGET_SIZES {
                self.slots.remove(0); // free the least recently used before allocating
            }
            let o = self.outputs;
            let slot = |want: bool, format| {
                want.then_some(Attachment {
                    format,
                    clear: [0.0; 4],
                })
            };
            let attachments = [
                slot(o.rgb, TextureFormat::Rgba8),
                slot(o.depth, TextureFormat::R32F),
                slot(o.mask, TextureFormat::R8),
            ];
            let with_depth = matches!(self.geometry, Geometry::Mesh(_));
            let framebuffer = Framebuffer::new(&self.gpu, w, h, &attachments, with_depth)?.with_label("refocus target");
            let cols = Texture::new(&self.gpu, w, 1, TextureFormat::Rgba32F, None)?.with_label("refocus column lookup");
            let rows = Texture::new(&self.gpu, h, 1, TextureFormat::Rgba32F, None)?.with_label("refocus row lookup");
            self.slots.push(TargetSlot {
                framebuffer,
                cols,
                rows,
            });
        }
        Ok(self.slots.last().expect("pushed above"))
    }

    /// Render `target` (same pose as the source) and read back the requested outputs.
    pub fn render(&mut self, target: &PinholeCamera) -> Result<RefocusOutput> {
        self.submit(target)?.wait()
    }

    /// Record the draw of `target` and queue the reads of its outputs; returns without waiting.
    pub fn submit(&mut self, target: &PinholeCamera) -> Result<PendingRefocus> {
        let t0 = Instant::now();
        target.validate("target camera")?;
        self.gpu.check_image_size("output size", target.width, target.height)?;
        let Some(source) = &self.source else {
            return Err(Error::param("refocus source", "no source uploaded (set_source)"));
        };
        let (src_cam, planes) = (source.camera, source.planes);
        let conv = self.conv;
        let clear_depth = conv.clear_depth() as f32;
        let gpu = self.gpu.clone();
        let sk = src_cam.k;
        let tk = target.k;
        // The pixel -> source-point map in f64, per column and per row (it is separable).
        let cols = axis_lookup(src_cam.width, sk.cx, tk.cx, sk.fx / tk.fx, target.width);
        let rows = axis_lookup(src_cam.height, sk.cy, tk.cy, sk.fy / tk.fy, target.height);
        self.slot(target.width, target.height)?;
        let slot = self.slots.last().expect("slot allocated above");
        slot.cols.upload(bytemuck::cast_slice(&cols))?;
        slot.rows.upload(bytemuck::cast_slice(&rows))?;
        let source = self.source.as_ref().expect("checked above");
        let fb = &slot.framebuffer;
        let programs: Vec<&Program> = match &self.geometry {
            Geometry::Fullscreen { program, .. } => vec![program],
            Geometry::Mesh(mesh) => mesh.programs().to_vec(),
        };
        let state = match &self.geometry {
            Geometry::Mesh(_) => DrawState::depth_tested(&conv),
            Geometry::Fullscreen { .. } => DrawState::default(),
        };
        let mut timer = DeferredTimer::begin(&gpu);
        let pass = fb.begin_pass(state, clear_depth);
        if let Some(rgb) = &source.rgb {
            rgb.bind(0);
        }
        source.depth.bind(1);
        slot.cols.bind(3);
        slot.rows.bind(4);
        for p in programs {
            p.bind();
            p.set_i32("u_src_rgb", 0);
            p.set_i32("u_src_depth", 1);
            p.set_i32("u_keep", 2);
            p.set_i32("u_cols", 3);
            p.set_i32("u_rows", 4);
            p.set_ivec2("u_src_size", [src_cam.width as i32, src_cam.height as i32]);
            p.set_vec4("u_src_k", [sk.fx as f32, sk.fy as f32, sk.cx as f32, sk.cy as f32]);
            p.set_i32("u_dst_height", target.height as i32);
        }
        match &self.geometry {
            Geometry::Fullscreen { program, keep } => {
                program.bind();
                keep.as_ref().expect("uploaded with the source").bind(2);
                pass.draw_fullscreen(&self.vao);
            }
            Geometry::Mesh(mesh) => mesh.draw(&pass, &self.vao, &src_cam, target, &planes, &conv, 2),
        }
        drop(pass);
        timer.end();
        gpu.check("refocus draw")?;
        // Files are top-down: under the GL row order the GPU flips while copying.
        let flip = conv.row_order == RowOrder::BottomUp;
        let pending = PendingRefocus {
            camera: *target,
            rgb: fb.read_async(0, ReadFormat::RGB8, flip)?,
            depth: fb.read_async(1, ReadFormat::R32F, flip)?,
            mask: fb.read_async(2, ReadFormat::R8, flip)?,
            timer,
            submit_ms: 0.0,
        };
        Ok(PendingRefocus {
            submit_ms: t0.elapsed().as_secs_f64() * 1e3,
            ..pending
        })
    }
}
