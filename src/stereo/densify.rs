//! Dense disparities before rendering (issue 38): the matcher leaves 13-27 % of a real pair
//! unknown (occlusions, textureless and inconsistent regions). Filling them in the disparity
//! domain, not in colour, lets the renderer cover nearly every pixel with geometry, so the colour
//! fill is left with true disocclusions only.
//!
//! The rule, per unknown pixel p of one eye: walk the 16 directions of [`super::walk`] (at most
//! [`RADIUS`] px) to the first known disparity in each; give candidate i the integer weight
//! `2^30 / (COLOUR_SOFTNESS + |c_p - c_i|_1)^2 / r_i` (the colour difference summed over r, g, b
//! in levels, r_i the walk's distance); sort the candidates by disparity (equal ones in direction
//! order) and take the first whose running weight reaches [`QUANTILE_PERCENT`] % of the total.
//! - The low quantile leans to the background side: an occluded pixel belongs to the surface
//!   behind its occluder, whose disparity is the smaller. Measured on Cones and Tsukuba (all
//!   pixels of the middle view, --fill): the weighted median gave 0.1-0.6 dB less than the 15 %
//!   quantile, the minimum (pure background) 1.5-1.8 dB less.
//! - The colour weights keep a textureless region on the surface of its own colour.
//!
//! Known disparities pass through. The flag output says which were filled ([`FILLED`]), so a
//! caller can tell rendered-from-matched from rendered-from-filled pixels.
//!
//! One full-screen pass per eye (shaders/cyclopean/densify.frag) on either executor, and
//! [`densify_reference`](super::densify_reference::densify_reference), its twin. Every decision compares integers and copies a disparity, so
//! the GPU's maps are the twin's bit for bit.

use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use crate::pass::{Device, Draw, Format, Image, ImageData, ProgramKind, ShaderProgram, Target, ToDevice};

/// The flag of a filled disparity.
pub const FILLED: u8 = 1;
/// Farthest a walk goes, pixels (Chebyshev): an unknown region wider than twice this keeps its
/// middle unknown (the colour fill's, then).
pub const RADIUS: u32 = 256;
/// Colour distance (levels summed over r, g, b) at which a candidate's weight falls to 1/4.
pub const COLOUR_SOFTNESS: u32 = 24;
/// The weighted quantile taken, percent.
pub const QUANTILE_PERCENT: u32 = 15;
/// The weighted quantile taken among the candidates that put a pixel outside the other eye's
/// frame, percent: no lean to the background there, since no occluder hid the pixel.
pub const OUT_OF_FRAME_PERCENT: u32 = 50;

/// Whose disparities a densify pass fills: the eye, and the offset they are stored with
/// (d + offset, so that signed ranges stay positive), which together say where a pixel's match
/// lies in the other eye (left: x - d, right: x + d).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OtherEye {
    /// The eye whose disparities are filled.
    pub eye: crate::stereo::Eye,
    /// The offset the disparities are stored with.
    pub offset: u32,
}

impl OtherEye {
    /// The left eye's disparities, stored as they are.
    pub const LEFT: OtherEye = OtherEye {
        eye: crate::stereo::Eye::Left,
        offset: 0,
    };

    /// The sign of the shift to the match: x - d on the left eye, x + d on the right.
    fn sign(self) -> f32 {
        match self.eye {
            crate::stereo::Eye::Left => -1.0,
            crate::stereo::Eye::Right => 1.0,
        }
    }

    /// Whether stored disparity `v` at column `x` puts the match outside the other eye's frame
    /// of `width` columns: a candidate that does explains why `x` is unknown without an
    /// occluder. f32 as the shader, so both decide alike.
    pub(super) fn outside(self, x: f32, v: f32, width: f32) -> bool {
        let partner = x + self.sign() * (v - self.offset as f32);
        partner < 0.0 || partner > width - 1.0
    }
}

crate::param_block! {
    /// shaders/cyclopean/densify_params.glsl, member for member.
    pub struct DensifyParams("DensifyParams") {
        u_size: [i32; 2],
        u_radius: i32,
        u_filled: u32,
        u_sign: f32,
        u_offset: f32,
    }
}

/// One eye made dense: its disparities (known ones unchanged) and a flag per pixel, [`FILLED`]
/// where the disparity was filled.
#[derive(Debug, Clone, PartialEq)]
pub struct Dense {
    /// Disparities, 0 where still unknown (no known pixel within [`RADIUS`]).
    pub disparity: DepthMap,
    /// [`FILLED`] or 0 per pixel.
    pub filled: Vec<u8>,
}

pub(super) fn check(disparity: &DepthMap, color: &RgbImage) -> Result<()> {
    if (disparity.width, disparity.height) != (color.width, color.height) {
        return Err(Error::SizeMismatch {
            message: format!(
                "densify: disparity {}x{} vs colour {}x{}",
                disparity.width, disparity.height, color.width, color.height
            ),
        });
    }
    Ok(())
}

/// The weight of a candidate at colour distance `diff` (summed levels) and walk distance `r`.
pub(super) fn weight(diff: u32, r: u32) -> u32 {
    let s = COLOUR_SOFTNESS + diff;
    ((1u32 << 30) / (s * s)) / r
}

/// Makes disparity maps dense on one device.
pub struct Densifier {
    device: Device,
    /// Disparity and colour of the last eye, rewritten in place for the next of its size.
    inputs: [Option<Image>; 2],
}

impl Densifier {
    /// A densifier on `device` (a [`Device`], or a GL context).
    pub fn new(device: impl ToDevice) -> Result<Self> {
        Ok(Densifier {
            device: device.to_device()?,
            inputs: [None, None],
        })
    }

    /// `disparity` (0 = unknown) made dense, guided by the eye's `color`; the twin's maps bit for bit.
    pub fn densify(&mut self, disparity: &DepthMap, color: &RgbImage, other: OtherEye) -> Result<Dense> {
        check(disparity, color)?;
        let (w, h) = (disparity.width, disparity.height);
        let rgba = crate::pass::pixels::rgb_to_rgba(&color.data);
        let [disparity_slot, color_slot] = &mut self.inputs;
        let d = &self.device;
        let images = [
            d.put_image(
                disparity_slot,
                &ImageData::r32f(w, h, &disparity.data, "densify disparity"),
            )?,
            d.put_image(color_slot, &ImageData::rgba8(w, h, &rgba, "densify colour"))?,
        ];
        let params = DensifyParams {
            u_size: [w as i32, h as i32],
            u_radius: RADIUS as i32,
            u_filled: FILLED.into(),
            u_sign: other.sign(),
            u_offset: other.offset as f32,
        };
        // Memory rows are the top-down rows and the walk reads them as the twin does: no flip.
        let target = Target {
            width: w,
            height: h,
            outputs: vec![Some(Format::R32F), Some(Format::R8)],
            rows: crate::convention::RowOrder::TopDown,
            depth_test: None,
        };
        let program = ShaderProgram::new(Default::default(), ProgramKind::CyclopeanDensify);
        let draw = Draw::fullscreen(program, bytemuck::bytes_of(&params), &images, w, h);
        let mut r = self.device.render(&target, &[draw])?;
        let disparity = r
            .depth(0)?
            .ok_or_else(|| r.api.readback_error("densify: the disparity was not read back"))?;
        Ok(Dense {
            disparity,
            filled: r.take(1, "densify flags")?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stereo::densify_reference::densify_reference;

    fn grey(w: u32, h: u32, v: impl Fn(u32, u32) -> u8) -> RgbImage {
        let mut data = Vec::with_capacity((3 * w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                data.extend([v(x, y); 3]);
            }
        }
        RgbImage::new(w, h, data).unwrap()
    }

    /// The GLSL constants are the Rust ones.
    #[test]
    fn the_shader_constants_are_the_twins() {
        let glsl = include_str!("../../shaders/cyclopean/densify_params.glsl");
        for line in [
            format!("const uint COLOUR_SOFTNESS = {}u;", COLOUR_SOFTNESS),
            format!("const uint QUANTILE_PERCENT = {}u;", QUANTILE_PERCENT),
            format!("const uint OUT_OF_FRAME_PERCENT = {}u;", OUT_OF_FRAME_PERCENT),
        ] {
            assert!(glsl.contains(&line), "densify_params.glsl lacks `{line}`");
        }
        // The largest running sum times 100 stays inside the shader's u32.
        assert!(16 * 100 * weight(0, 1) as u64 <= u32::MAX as u64);
    }

    #[test]
    fn an_occluded_band_takes_the_background_beside_it() {
        // Row: background 30 px (disparity 5) | unknown band 3 px | foreground (disparity 20).
        // The band is background surface (its colour), and nearer the foreground's pixels in
        // most directions: it still takes the background. (Every disparity keeps its match
        // inside the other eye's frame, as a matched pixel's does.)
        let (w, h) = (36u32, 5u32);
        let d: Vec<f32> = (0..h)
            .flat_map(|_| {
                (0..w).map(|x| {
                    if x < 30 {
                        5.0
                    } else if x < 33 {
                        0.0
                    } else {
                        20.0
                    }
                })
            })
            .collect();
        let color = grey(w, h, |x, _| if x < 33 { 90 } else { 200 });
        let dense = densify_reference(&DepthMap::new(w, h, d).unwrap(), &color, OtherEye::LEFT).unwrap();
        for x in 30..33 {
            assert_eq!(dense.disparity.data[2 * w as usize + x], 5.0, "x = {x}");
            assert_eq!(dense.filled[2 * w as usize + x], FILLED);
        }
        assert_eq!(dense.filled[0], 0, "known disparities are not flagged");
    }

    #[test]
    fn a_strip_the_other_eye_cannot_see_takes_the_surface_beside_it() {
        // Left eye, one colour: rows 0..8 foreground (disparity 12) from x = 12 on, its first 12
        // columns unknown: their matches would lie left of the right eye's frame. Rows 8..12:
        // background (disparity 3) known from x = 3. The strip is no occlusion, so it
        // takes the foreground beside it, not the background below; on the right eye (match at
        // x + d, inside the frame) the same map leans to the background as before.
        let (w, h) = (24u32, 12u32);
        let color = grey(w, h, |_, _| 220);
        let d: Vec<f32> = (0..h)
            .flat_map(|y| {
                (0..w).map(move |x| match (x, y) {
                    (0..=11, 0..=7) | (0..=2, _) => 0.0,
                    (_, 0..=7) => 12.0,
                    _ => 3.0,
                })
            })
            .collect();
        let map = DepthMap::new(w, h, d).unwrap();
        let left = densify_reference(&map, &color, OtherEye::LEFT).unwrap();
        let right = OtherEye {
            eye: crate::stereo::Eye::Right,
            offset: 0,
        };
        let right = densify_reference(&map, &color, right).unwrap();
        for y in 0..8 {
            // Left of x = 3 the background's matches leave the frame too: either may be right.
            for x in 3..12 {
                let i = (y * w + x) as usize;
                assert_eq!(left.disparity.data[i], 12.0, "left ({x}, {y})");
            }
        }
        // The right eye's pixel next to the background takes it (the occlusion rule).
        assert_eq!(right.disparity.data[(7 * w + 5) as usize], 3.0);
        // An offset shifts the frame test with the stored values: stored 12 + 10 is d = 12.
        let shifted = DepthMap::new(
            w,
            h,
            map.data.iter().map(|v| if *v > 0.0 { v + 10.0 } else { 0.0 }).collect(),
        )
        .unwrap();
        let offset = OtherEye {
            eye: crate::stereo::Eye::Left,
            offset: 10,
        };
        let shifted = densify_reference(&shifted, &color, offset).unwrap();
        assert_eq!(shifted.disparity.data[(2 * w + 5) as usize], 22.0);
    }

    #[test]
    fn a_region_takes_the_disparity_of_its_own_colour() {
        // Left half dark at disparity 30 (foreground), right half bright at 4: an unknown
        // square inside the dark half, touching the border between them, stays dark's.
        let (w, h) = (32u32, 16u32);
        let color = grey(w, h, |x, _| if x < 16 { 20 } else { 230 });
        let d: Vec<f32> = (0..h)
            .flat_map(|y| {
                (0..w).map(move |x| match (x, y) {
                    (10..=15, 4..=11) => 0.0,
                    (0..=15, _) => 30.0,
                    _ => 4.0,
                })
            })
            .collect();
        let dense = densify_reference(&DepthMap::new(w, h, d).unwrap(), &color, OtherEye::LEFT).unwrap();
        for y in 4..12 {
            for x in 10..16 {
                assert_eq!(dense.disparity.data[(y * w + x) as usize], 30.0, "({x}, {y})");
            }
        }
    }

    #[test]
    fn nothing_known_stays_unknown() {
        let dense = densify_reference(
            &DepthMap::new(4, 3, vec![0.0; 12]).unwrap(),
            &grey(4, 3, |x, _| x as u8),
            OtherEye::LEFT,
        )
        .unwrap();
        assert!(dense.disparity.data.iter().all(|v| *v == 0.0));
        assert!(dense.filled.iter().all(|f| *f == 0));
    }
}
