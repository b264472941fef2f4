//! The census matcher's cost beside the cyclopean render (issue 26: "at 720p and above it
//! dominates the frame time"): the GPU pass against its CPU twin on a synthetic rectified pair,
//! so `bench` needs no data set.

use viewsynth::error::Result;
use viewsynth::io::RgbImage;

/// Disparity (px) of the synthetic pair's far wall.
pub const WALL_DISPARITY: u32 = 20;
/// Disparity (px) of the synthetic pair's near rectangle.
pub const NEAR_DISPARITY: u32 = 60;

/// A rectified pair of `width` x `height` (at least 128 x 64): a textured wall at
/// [`WALL_DISPARITY`] and, in front of it, a textured rectangle over the middle third of the
/// left image at [`NEAR_DISPARITY`]; per-pixel random colour, so every census window matches
/// only where it should. Also returns the left eye's true disparity.
pub fn synthetic_pair(width: u32, height: u32) -> Result<(RgbImage, RgbImage, Vec<f32>)> {
    let (w, h) = (width as usize, height as usize);
    if w < 128 || h < 64 {
        return Err(viewsynth::Error::param(
            "synthetic pair",
            format!("{w}x{h}: needs at least 128x64"),
        ));
    }
    let (far, near) = (WALL_DISPARITY as usize, NEAR_DISPARITY as usize);
    // xorshift64*: the same texture on every machine, no dependency.
    let texture = |mut state: u64, tw: usize| {
        (0..tw * h)
            .map(|_| {
                state ^= state >> 12;
                state ^= state << 25;
                state ^= state >> 27;
                let v = state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 32;
                [v as u8, (v >> 8) as u8, (v >> 16) as u8]
            })
            .collect::<Vec<_>>()
    };
    let (wall, rect) = (texture(0x5EED_0026, w + far), texture(0x5EED_0027, w));
    let (rx, ry) = (w / 3..2 * w / 3, h / 3..2 * h / 3);
    let in_rect = |x: usize, y: usize| rx.contains(&x) && ry.contains(&y);
    let mut left = Vec::with_capacity(3 * w * h);
    let mut right = Vec::with_capacity(3 * w * h);
    let mut truth = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (l, d) = match in_rect(x, y) {
                true => (rect[y * w + x], near),
                false => (wall[y * (w + far) + x], far),
            };
            left.extend(l);
            truth.push(d as f32);
            // The right pixel x sees the left pixel x + d of whichever surface is in front.
            right.extend(match in_rect(x + near, y) {
                true => rect[y * w + x + near],
                false => wall[y * (w + far) + x + far],
            });
        }
    }
    Ok((
        RgbImage::new(width, height, left)?,
        RgbImage::new(width, height, right)?,
        truth,
    ))
}
