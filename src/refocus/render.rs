//! GPU refocus: shared inputs (source colour, depth and the kept triangles) are uploaded once;
//! each target renders into a framebuffer holding only the requested attachments.

use super::grid::{axis_lookup, Grid};
use super::mesh::{MeshPass, TRI_TEX_WIDTH};
use super::{Method, OutputSet, RefocusSource};
use crate::camera::PinholeCamera;
use crate::convention::{Conventions, DepthPlanes};
use crate::error::{Error, Result};
use crate::gpu::{Attachment, Framebuffer, Gpu, GpuTimer, Program, Texture, TextureFormat, Timing, VertexArray};
use crate::io::{DepthMap, Mask, RgbImage};
use glow::HasContext;
use std::time::Instant;

const GRID_GLSL: &str = include_str!("../../shaders/common/refocus_grid.glsl");
const SAMPLE_GLSL: &str = include_str!("../../shaders/common/refocus_sample.glsl");
const FULLSCREEN_FRAG: &str = include_str!("../../shaders/refocus/fullscreen.frag");

/// One refocused view. Images are top-down whatever the row-order convention.
pub struct RefocusOutput {
    pub camera: PinholeCamera,
    pub rgb: Option<RgbImage>,
    /// View-space Z in metres, 0 where invalid.
    pub depth: Option<DepthMap>,
    pub mask: Option<Mask>,
    /// Draw time (GPU timer where meaningful; wall clock with glFinish always).
    pub render: Timing,
    /// Readback and conversion to top-down images.
    pub readback_ms: f64,
}

enum Geometry {
    Mesh(MeshPass),
    Fullscreen { program: Program, keep: Texture },
}

/// A source uploaded to the GPU, ready to render any number of targets.
pub struct Refocuser {
    gpu: Gpu,
    conv: Conventions,
    outputs: OutputSet,
    source: PinholeCamera,
    planes: DepthPlanes,
    rgb: Option<Texture>,
    depth: Texture,
    geometry: Geometry,
    vao: VertexArray,
    framebuffer: Option<Framebuffer>,
}

impl Refocuser {
    pub fn new(
        gpu: &Gpu,
        src: &RefocusSource,
        rule: &super::BreakRule,
        method: Method,
        outputs: OutputSet,
        conv: Conventions,
    ) -> Result<Self> {
        rule.validate()?;
        let (w, h) = (src.rgb.width, src.rgb.height);
        let max = gpu.max_image_side();
        // The grid's cells include a half-pixel border ring: (w + 1) x (h + 1) of them, each a
        // texel of the coverage texture, so the source side is one less than the GPU's limit.
        if w >= max || h >= max {
            return Err(Error::param(
                "source size",
                format!(
                    "{w}x{h}: its grid needs {}x{} cells (one per pixel plus the border ring) but this GPU's \
                     texture limit is {max}; sources up to {} px per side",
                    w + 1,
                    h + 1,
                    max - 1
                ),
            ));
        }
        let grid = Grid { width: w, height: h };
        let keep = grid.keep_mask(&src.depth.data, rule);
        let defines = format!(
            "{}#define WANT_RGB {}\n#define TRI_TEX_WIDTH {TRI_TEX_WIDTH}\n",
            conv.glsl_defines(),
            outputs.rgb as u8
        );
        let geometry = match method {
            Method::Fullscreen => {
                let frag = format!("{GRID_GLSL}\n{SAMPLE_GLSL}\n{FULLSCREEN_FRAG}");
                let program = Program::fullscreen(gpu, &defines, "refocus/fullscreen.frag", &frag)?;
                let flags = grid.coverage_flags(&keep);
                let (cx, cy) = (grid.cells_x() as u32, grid.cells_y() as u32);
                let keep = Texture::new(gpu, cx, cy, TextureFormat::R8Ui, Some(&flags))?;
                Geometry::Fullscreen { program, keep }
            }
            Method::Mesh => Geometry::Mesh(MeshPass::new(gpu, &grid, &keep, &defines, GRID_GLSL, SAMPLE_GLSL)?),
        };
        let rgb = if outputs.rgb {
            let rgba: Vec<u8> = crate::gpu::pixels::rgb_to_rgba(&src.rgb.data);
            Some(Texture::new(gpu, w, h, TextureFormat::Rgba8, Some(&rgba))?)
        } else {
            None
        };
        let depth_bytes: Vec<u8> = crate::gpu::pixels::f32_to_bytes(&src.depth.data);
        let depth = Texture::new(gpu, w, h, TextureFormat::R32F, Some(&depth_bytes))?;
        // Every kept vertex lies in [min, max] of the valid depths; the factor 2 leaves room for
        // the expanded border of each triangle (which the vertex shader keeps within it).
        let planes = match src.depth_range() {
            Some((lo, hi)) => DepthPlanes {
                near: 0.25 * lo,
                far: 4.0 * hi,
            },
            None => DepthPlanes { near: 1.0, far: 2.0 },
        };
        Ok(Refocuser {
            gpu: gpu.clone(),
            conv,
            outputs,
            source: src.camera(),
            planes,
            rgb,
            depth,
            geometry,
            vao: VertexArray::new(gpu)?,
            framebuffer: None,
        })
    }

    /// Number of kept triangles (mesh path) for reports.
    pub fn triangle_count(&self) -> Option<usize> {
        match &self.geometry {
            Geometry::Mesh(mesh) => Some(mesh.triangle_count()),
            Geometry::Fullscreen { .. } => None,
        }
    }

    fn framebuffer(&mut self, w: u32, h: u32) -> Result<&Framebuffer> {
        let reuse = matches!(&self.framebuffer, Some(f) if f.width == w && f.height == h);
        if !reuse {
            self.framebuffer = None; // free the old one before allocating
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
            self.framebuffer = Some(Framebuffer::new(&self.gpu, w, h, &attachments, with_depth)?);
        }
        Ok(self.framebuffer.as_ref().expect("framebuffer allocated above"))
    }

    /// Render `target` (same pose as the source) and read back the requested outputs.
    pub fn render(&mut self, target: &PinholeCamera) -> Result<RefocusOutput> {
        target.validate("target camera")?;
        let max = self.gpu.max_image_side();
        if target.width > max || target.height > max {
            return Err(Error::param(
                "output size",
                format!("{}x{} exceeds this GPU's limit of {max}", target.width, target.height),
            ));
        }
        let conv = self.conv;
        let clear_depth = conv.clear_depth() as f32;
        self.framebuffer(target.width, target.height)?;
        let gpu = self.gpu.clone();
        let gl = gpu.gl();
        let fb = self.framebuffer.as_ref().expect("framebuffer allocated above");
        let sk = &self.source.k;
        let tk = &target.k;
        // The pixel -> source-point map in f64, per column and per row (it is separable), created
        // before any texture unit is bound (creating a texture binds it on the active unit).
        let cols = axis_lookup(self.source.width, sk.cx, tk.cx, sk.fx / tk.fx, target.width);
        let rows = axis_lookup(self.source.height, sk.cy, tk.cy, sk.fy / tk.fy, target.height);
        let bytes = |t: &[[f32; 4]]| -> Vec<u8> { t.iter().flatten().flat_map(|v| v.to_ne_bytes()).collect() };
        let cols = Texture::new(&gpu, target.width, 1, TextureFormat::Rgba32F, Some(&bytes(&cols)))?;
        let rows = Texture::new(&gpu, target.height, 1, TextureFormat::Rgba32F, Some(&bytes(&rows)))?;
        let programs: Vec<&Program> = match &self.geometry {
            Geometry::Fullscreen { program, .. } => vec![program],
            Geometry::Mesh(mesh) => mesh.programs().to_vec(),
        };
        let timer = GpuTimer::start(&gpu);
        fb.bind_and_clear(clear_depth);
        if let Some(rgb) = &self.rgb {
            rgb.bind(0);
        }
        self.depth.bind(1);
        cols.bind(3);
        rows.bind(4);
        for p in programs {
            p.bind();
            p.set_i32("u_src_rgb", 0);
            p.set_i32("u_src_depth", 1);
            p.set_i32("u_keep", 2);
            p.set_i32("u_cols", 3);
            p.set_i32("u_rows", 4);
            p.set_ivec2("u_src_size", [self.source.width as i32, self.source.height as i32]);
            p.set_vec4("u_src_k", [sk.fx as f32, sk.fy as f32, sk.cx as f32, sk.cy as f32]);
            p.set_i32("u_dst_height", target.height as i32);
        }
        // SAFETY: plain state setting on the current context.
        unsafe {
            gl.disable(glow::BLEND);
            gl.disable(glow::CULL_FACE);
            gl.disable(glow::STENCIL_TEST);
        }
        match &self.geometry {
            Geometry::Fullscreen { program, keep } => {
                program.bind();
                self.vao.bind();
                keep.bind(2);
                self.vao.draw_fullscreen();
            }
            Geometry::Mesh(mesh) => mesh.draw(&gpu, &self.vao, &self.source, target, &self.planes, &conv, 2),
        }
        gpu.check("refocus draw")?;
        let render = timer.stop();

        let t0 = Instant::now();
        let (w, h) = (target.width, target.height);
        let mut outputs = (None, None, None);
        if let Some(data) = fb.read_color(0)? {
            let rgba = conv.row_order.convert_rows(data, w as usize * 4);
            let rgb = crate::gpu::pixels::rgba_to_rgb(&rgba);
            outputs.0 = Some(RgbImage::new(w, h, rgb)?);
        }
        if let Some(data) = fb.read_color(1)? {
            let bytes = conv.row_order.convert_rows(data, w as usize * 4);
            let z = crate::gpu::pixels::bytes_to_f32(&bytes);
            outputs.1 = Some(DepthMap::new(w, h, z)?);
        }
        if let Some(data) = fb.read_color(2)? {
            let m = conv
                .row_order
                .convert_rows(data, w as usize)
                .into_iter()
                .map(|v| (v >= 128) as u8)
                .collect();
            outputs.2 = Some(Mask::new(w, h, m)?);
        }
        fb.unbind();
        Ok(RefocusOutput {
            camera: *target,
            rgb: outputs.0,
            depth: outputs.1,
            mask: outputs.2,
            render,
            readback_ms: t0.elapsed().as_secs_f64() * 1e3,
        })
    }
}
