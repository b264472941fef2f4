//! Kept-triangle codes as texel rows: how a mesh's triangles reach the GPU for vertex pulling
//! (refocus's mesh pass, cyclopean's forward warp).

use crate::error::{Error, Result};
use crate::pass::shaders::TRI_TEX_WIDTH;

/// The rows and R32UI texels of a kept-triangle code image `TRI_TEX_WIDTH` wide (None without
/// triangles), refused beyond a device's `max_side` or a 32-bit vertex count.
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
