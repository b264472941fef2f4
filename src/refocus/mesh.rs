//! The mesh path: the kept grid triangles rasterised into the MRT framebuffer with a depth test.
//!
//! Interior triangles (every corner surrounded by kept triangles) are drawn indexed, one vertex
//! shader run per grid vertex: any pixel the rasteriser gives them lies in a kept triangle, so
//! the fill rule cannot lose a pixel there. Boundary triangles are drawn by vertex pulling and
//! pushed out by a fraction of a pixel, with an exact closed test per fragment, so pixel centres
//! on a kept edge next to a hole are kept whatever the fill rule or the row order.

use super::grid::Grid;
use crate::camera::{clip_from_view_opencv, PinholeCamera};
use crate::convention::{Conventions, DepthPlanes};
use crate::error::{Error, Result};
use crate::gpu::{
    Gpu, IndexBuffer, Program, ProgramKind, RenderPass, ShaderProgram, Texture, TextureFormat, VertexArray,
};

/// Width of the texture holding kept-triangle codes for vertex pulling (the shader library's).
pub use crate::gpu::shaders::TRI_TEX_WIDTH;
/// How far (window pixels) boundary triangles are pushed out before the exact closed test:
/// above the rasteriser's vertex snapping (1/512 px at 8 subpixel bits).
pub(crate) const EXPAND_PX: f32 = 1.0 / 32.0;
/// Below this many target pixels per source pixel a triangle is smaller than ~8 snapping steps
/// and the interior argument (a pixel near a triangle lies in a neighbour sharing a corner) no
/// longer holds: every triangle then takes the boundary path.
pub(crate) const MIN_INTERIOR_SCALE: f64 = 1.0 / 64.0;

/// The mesh path's programs (compiled once per context and settings) and the current source's
/// geometry (replaced when the source changes).
pub struct MeshPass {
    interior_program: Program,
    boundary_program: Program,
    interior: Option<IndexBuffer>,
    /// Interior triangles' codes too, for when the scale is too small for the indexed draw.
    all_as_boundary: Option<Texture>,
    boundary: Option<Texture>,
    interior_count: usize,
    boundary_count: usize,
    indexed_vao: VertexArray,
}

/// Kept-triangle codes as an R32UI texture `TRI_TEX_WIDTH` wide, for vertex pulling.
pub fn code_texture(gpu: &Gpu, codes: &[u32]) -> Result<Option<Texture>> {
    let Some((rows, bytes)) = code_rows(codes, gpu.max_image_side())? else {
        return Ok(None);
    };
    Ok(Some(
        Texture::new(gpu, TRI_TEX_WIDTH, rows, TextureFormat::R32Ui, Some(&bytes))?.with_label("kept triangle codes"),
    ))
}

/// The rows and R32UI texels of [`code_texture`] (None without triangles), refused beyond a
/// device's `max_side` or GL's vertex count.
pub fn code_rows(codes: &[u32], max_side: u32) -> Result<Option<(u32, Vec<u8>)>> {
    if codes.is_empty() {
        return Ok(None);
    }
    let rows = codes.len().div_ceil(TRI_TEX_WIDTH as usize);
    if rows > max_side as usize || codes.len().checked_mul(3).is_none_or(|v| v > i32::MAX as usize) {
        return Err(Error::param(
            "source size",
            format!(
                "{} triangles exceed the mesh path's limit; use the full-screen method",
                codes.len()
            ),
        ));
    }
    let mut padded = codes.to_vec();
    padded.resize(rows * TRI_TEX_WIDTH as usize, 0);
    Ok(Some((rows as u32, bytemuck::cast_slice(&padded).to_vec())))
}

impl MeshPass {
    /// Compile the programs; no geometry yet (see [`MeshPass::set_geometry`]).
    pub fn new(gpu: &Gpu, conv: Conventions, want_rgb: bool) -> Result<Self> {
        let program = |kind| ShaderProgram::new(conv, kind).build(gpu);
        Ok(MeshPass {
            interior_program: program(ProgramKind::RefocusMeshInterior { want_rgb })?,
            boundary_program: program(ProgramKind::RefocusMeshBoundary { want_rgb })?,
            interior: None,
            all_as_boundary: None,
            boundary: None,
            interior_count: 0,
            boundary_count: 0,
            indexed_vao: VertexArray::new(gpu)?.with_label("refocus interior mesh"),
        })
    }

    /// Upload the kept triangles of a new source (its index buffer and code textures).
    pub fn set_geometry(&mut self, gpu: &Gpu, grid: &Grid, keep: &[u8]) -> Result<()> {
        let (interior, boundary) = grid.split_kept_triangles(keep);
        let indices: Vec<u32> = interior.iter().flat_map(|&c| grid.triangle_vertices(c)).collect();
        let mut all = boundary.clone();
        all.extend_from_slice(&interior);
        // Free the previous source's buffers before allocating the new ones.
        self.interior = None;
        self.all_as_boundary = None;
        self.boundary = None;
        self.interior = if indices.is_empty() {
            None
        } else {
            Some(IndexBuffer::new(gpu, &indices)?.with_label("refocus interior triangles"))
        };
        self.all_as_boundary = if interior.is_empty() {
            None
        } else {
            code_texture(gpu, &all)?
        };
        self.boundary = code_texture(gpu, &boundary)?;
        self.interior_count = interior.len();
        self.boundary_count = boundary.len();
        Ok(())
    }

    pub fn triangle_count(&self) -> usize {
        self.interior_count + self.boundary_count
    }

    /// Both programs, for setting the uniforms they share.
    pub fn programs(&self) -> [&Program; 2] {
        [&self.interior_program, &self.boundary_program]
    }

    /// Draw in `pass` (depth-tested under `conv`). Texture units and shared uniforms are set by
    /// the caller; the code texture goes to `code_unit`.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &self,
        pass: &RenderPass,
        vao: &VertexArray,
        source: &PinholeCamera,
        target: &PinholeCamera,
        planes: &DepthPlanes,
        conv: &Conventions,
        code_unit: u32,
    ) {
        let m = clip_from_view_opencv(target, planes, conv);
        let (a, b) = planes.clip_z_coefficients(conv);
        for p in self.programs() {
            p.bind();
            p.set_mat4_rows("u_clip_from_target", &m);
            p.set_vec2("u_clip_z", [a as f32, b as f32]);
            p.set_vec2("u_dst_size", [target.width as f32, target.height as f32]);
            p.set_f32("u_expand_px", EXPAND_PX);
            p.set_i32("u_tris", code_unit as i32);
        }
        let scale = (target.k.fx / source.k.fx).min(target.k.fy / source.k.fy);
        let (pulled, pulled_count) = if scale < MIN_INTERIOR_SCALE {
            (
                self.all_as_boundary.as_ref().or(self.boundary.as_ref()),
                self.triangle_count(),
            )
        } else {
            (self.boundary.as_ref(), self.boundary_count)
        };
        // Depth clamp (no near/far clipping) and LEQUAL/GEQUAL come with the pass's DrawState:
        // with a 1e8 depth ratio, standard-Z f32 puts far surfaces on the far plane, where
        // clipping or a strict test would drop them.
        if let (Some(indices), true) = (&self.interior, scale >= MIN_INTERIOR_SCALE) {
            self.interior_program.bind();
            pass.draw_indexed(&self.indexed_vao, indices);
        }
        if let Some(codes) = pulled {
            self.boundary_program.bind();
            codes.bind(code_unit);
            pass.draw_triangles(vao, pulled_count);
        }
    }
}
