//! The mesh path's geometry: the kept grid triangles of one source, ready to be rasterised into
//! the refocus target with a depth test (render.rs describes the draws).
//!
//! Interior triangles (every corner surrounded by kept triangles) are drawn indexed, one vertex
//! shader run per grid vertex: any pixel the rasteriser gives them lies in a kept triangle, so
//! the fill rule cannot lose a pixel there. Boundary triangles are drawn by vertex pulling and
//! pushed out by a fraction of a pixel, with an exact closed test per fragment, so pixel centres
//! on a kept edge next to a hole are kept whatever the fill rule or the row order.

use crate::error::Result;
use crate::mesh::code_rows;
use crate::mesh::Grid;
use crate::pass::{Buffer, Device, Format, Image, ImageData, ImageId};

/// Width of the texture holding kept-triangle codes for vertex pulling (the shader library's).
pub use crate::pass::shaders::TRI_TEX_WIDTH;
/// How far (window pixels) boundary triangles are pushed out before the exact closed test:
/// above the rasteriser's vertex snapping (1/512 px at 8 subpixel bits).
pub(crate) const EXPAND_PX: f32 = 1.0 / 32.0;
/// Below this many target pixels per source pixel a triangle is smaller than ~8 snapping steps
/// and the interior argument (a pixel near a triangle lies in a neighbour sharing a corner) no
/// longer holds: every triangle then takes the boundary path.
pub(crate) const MIN_INTERIOR_SCALE: f64 = 1.0 / 64.0;

/// Kept-triangle codes as an R32UI image `TRI_TEX_WIDTH` wide, for vertex pulling.
fn code_image(device: &Device, codes: &[u32], max_side: u32, label: &str) -> Result<Option<Image>> {
    let Some((rows, bytes)) = code_rows(codes, max_side)? else {
        return Ok(None);
    };
    let image = device.upload(&ImageData::new(TRI_TEX_WIDTH, rows, Format::R32Ui, &bytes, label))?;
    Ok(Some(image))
}

/// One source's kept triangles on a device: the interior ones' vertex indices and the boundary
/// ones' codes (and every triangle's codes, for scales below [`MIN_INTERIOR_SCALE`]).
pub(super) struct MeshGeometry {
    interior: Option<Buffer>,
    all_as_boundary: Option<Image>,
    boundary: Option<Image>,
    interior_count: usize,
    boundary_count: usize,
}

/// What the mesh path draws at one scale.
pub(super) struct MeshDraws {
    /// The interior triangles' index buffer and count, when drawn indexed.
    pub interior: Option<(crate::pass::BufferId, u32)>,
    /// The pulled triangles' code image and count.
    pub pulled: Option<(ImageId, u32)>,
}

impl MeshGeometry {
    /// Split the kept triangles of `grid` and upload them.
    pub fn new(device: &Device, grid: &Grid, keep: &[u8], max_side: u32) -> Result<Self> {
        let (interior, boundary) = grid.split_kept_triangles(keep);
        let indices: Vec<u32> = interior.iter().flat_map(|&c| grid.triangle_vertices(c)).collect();
        let mut all = boundary.clone();
        all.extend_from_slice(&interior);
        Ok(MeshGeometry {
            interior: match indices.is_empty() {
                true => None,
                false => Some(device.upload_indices(&indices, "refocus interior triangles")?),
            },
            all_as_boundary: match interior.is_empty() {
                true => None,
                false => code_image(device, &all, max_side, "refocus all triangle codes")?,
            },
            boundary: code_image(device, &boundary, max_side, "refocus boundary triangle codes")?,
            interior_count: interior.len(),
            boundary_count: boundary.len(),
        })
    }

    /// Kept triangles, for reports.
    pub fn triangle_count(&self) -> usize {
        self.interior_count + self.boundary_count
    }

    /// The draws at `scale` (target pixels per source pixel, the smaller axis).
    pub fn draws(&self, scale: f64) -> MeshDraws {
        if scale < MIN_INTERIOR_SCALE {
            let pulled = self.all_as_boundary.as_ref().or(self.boundary.as_ref());
            return MeshDraws {
                interior: None,
                pulled: pulled.map(|i| (i.id(), self.triangle_count() as u32)),
            };
        }
        MeshDraws {
            interior: self.interior.as_ref().map(|b| (b.id(), self.interior_count as u32)),
            pulled: self.boundary.as_ref().map(|i| (i.id(), self.boundary_count as u32)),
        }
    }
}
