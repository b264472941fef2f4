//! Ray-traced ODS ground truth: every equirect pixel's ray starts on the (pole-faded) IPD/2
//! circle, tangent to its direction ([`OdsRig::ray`]), and is traced in f64 through the scene.

use super::{equirect_angles, OdsRig, Side};
use crate::error::{Error, Result};
use crate::world;

/// Exact colour (0..255, unrounded; black where nothing is hit) and ray distance (0 = none) of
/// one eye's equirect, rows top-down.
#[derive(Debug, Clone)]
pub struct OdsTruth {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Colour per pixel, 0..=255 per channel, unrounded; black where nothing is hit.
    pub color: Vec<[f64; 3]>,
    /// Distance along the ODS ray to the hit, metres; 0 where nothing is hit.
    pub distance: Vec<f64>,
}

/// Ray-traces `side`'s equirect (`width` x `height`) of the built-in scene for `rig`, in f64.
pub fn ods_truth(rig: &OdsRig, side: Side, width: u32, height: u32) -> Result<OdsTruth> {
    rig.validate()?;
    if !(1..=crate::io::MAX_DIMENSION).contains(&width) || !(1..=crate::io::MAX_DIMENSION).contains(&height) {
        return Err(Error::param("equirect size", format!("{width}x{height}")));
    }
    let n = width as usize * height as usize;
    let (mut color, mut distance) = (vec![[0.0; 3]; n], vec![0.0; n]);
    for v in 0..height {
        for u in 0..width {
            let (lon, lat) = equirect_angles(u, v, width, height);
            let (o, d) = rig.ray(side, lon, lat);
            if let Some(hit) = world::trace(o, d) {
                let i = v as usize * width as usize + u as usize;
                color[i] = world::hit_color(&hit);
                distance[i] = hit.t;
            }
        }
    }
    Ok(OdsTruth {
        width,
        height,
        color,
        distance,
    })
}
