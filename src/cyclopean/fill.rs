//! `--fill`: a complete middle view for spectators. Holes (pixels no eye saw: disocclusions,
//! unknown disparity, the borders only one eye covers) are filled in two dimensions from the
//! background layer around them (issue 38; the first fill went along the row, and its large
//! holes became visible horizontal streaks across slanted, textured surfaces):
//! - from the hole, walk the 16 directions of [`super::walk`] to the first rendered pixel in each;
//! - keep those no farther than twice the row's far end ([`REACH`]): the surfaces across the
//!   hole, not one that a walk along a thin hole meets far beyond it (the wall behind a floor);
//! - sort those candidates far to near; the background layer is the farthest and every next one
//!   within [`SAME_SURFACE`] (relative) of the one before it: a chain, so a slanted surface stays
//!   one layer while an occluder's edge, a jump in depth, starts another;
//! - the hole takes that layer's colour and depth, weighted by 1 / distance^2;
//! - except in a border strip (the row runs off the image on one side with no rendered pixel:
//!   a part of the view beyond both eyes' frames, which no occluder uncovered), where the
//!   layer is the chain of the nearest candidate: the surfaces next to the strip continue into
//!   it, where the farthest would be whatever a long walk along the strip reaches (the wall above
//!   a floor).
//!
//! A disocclusion uncovers what lies behind the occluder, so the foreground does not bleed into
//! it; a hole inside one surface is interpolated across it from every side.
//! Filled pixels carry [`FILLED`] alone in their source bits, so the mask file tells them apart
//! (value 128, [`crate::io::MASK_FILLED`]); rendered pixels pass through unchanged.
//!
//! One full-screen pass (shaders/cyclopean/fill.frag) on either executor, and [`fill_reference`](super::fill_reference::fill_reference),
//! its twin: the choices (which candidates, which layer) compare the same f32 depths, so they
//! agree exactly; the weighted means are the same f32 sums, up to the GPU's division (GLSL allows
//! 2.5 ulp) and its rounding of the normalised colour: one level at most, 1e-5 relative in depth.

use crate::error::{Error, Result};
use crate::pass::{Device, Draw, Image, ImageData, Target, ToDevice};
use crate::pass::{ProgramKind, ShaderProgram};
use crate::stereo::gather::CyclopeanOutput;

/// The source bit of filled pixels (above the eye and history bits).
pub const FILLED: u8 = crate::io::MASK_FILLED;

crate::param_block! {
    /// shaders/cyclopean/fill_params.glsl, member for member.
    pub struct FillParams("FillParams") {
        u_size: [i32; 2],
        u_filled: u32,
        u_same_surface: f32,
        u_reach: i32,
    }
}

/// Relative depth difference below which the pixels either side of a hole are taken as one
/// surface, and the hole is interpolated between them instead of copied from the farther.
pub const SAME_SURFACE: f32 = 0.05;

/// [`crate::stereo::walk::DIRECTIONS`]' entries along the row: +x and -x.
pub(super) const ROW_RIGHT: usize = 0;
pub(super) const ROW_LEFT: usize = 8;

/// Candidates count up to this multiple of the row's span, the farther row hit (inside the
/// image): 2, so every direction that crosses a vertical gap still does (the steepest, (1, 2),
/// at twice its width). With 1 the built-in scene's frame 4 gained 0.1 dB, but a large hole in
/// a slanted plane lost its steep directions, its chain broke and it took one side's depth.
pub const REACH: i64 = 2;

/// Fills middle views on one device.
pub struct Filler {
    device: Device,
    /// Colour, depth and sources of the last view, rewritten in place for the next of its size.
    inputs: [Option<Image>; 3],
}

/// Colour and depth of `out`, both needed: depth chooses the side, colour is what is filled.
pub(super) fn planes(out: &CyclopeanOutput) -> Result<(&crate::io::RgbImage, &crate::io::DepthMap)> {
    match (&out.color, &out.depth) {
        (Some(c), Some(d)) => Ok((c, d)),
        _ => Err(Error::param(
            "fill",
            "needs the middle view's colour and depth (render both, then drop what was not asked for)",
        )),
    }
}

impl Filler {
    /// A filler on `device` (a [`Device`], or a GL context).
    pub fn new(device: impl ToDevice) -> Result<Self> {
        Ok(Filler {
            device: device.to_device()?,
            inputs: [None, None, None],
        })
    }

    /// `out` (top-down rows, `width` x `height`) with its holes filled.
    pub fn fill(&mut self, out: &CyclopeanOutput, width: u32, height: u32) -> Result<CyclopeanOutput> {
        let (color, depth) = planes(out)?;
        let (w, h) = (width, height);
        let rgba = crate::pass::pixels::rgb_to_rgba(&color.data);
        let [color_slot, depth_slot, sources_slot] = &mut self.inputs;
        let d = &self.device;
        let images = [
            d.put_image(color_slot, &ImageData::rgba8(w, h, &rgba, "fill colour"))?,
            d.put_image(depth_slot, &ImageData::r32f(w, h, &depth.data, "fill depth"))?,
            d.put_image(sources_slot, &ImageData::r8ui(w, h, &out.sources, "fill sources"))?,
        ];
        let params = FillParams {
            u_size: [w as i32, h as i32],
            u_filled: FILLED.into(),
            u_same_surface: SAME_SURFACE,
            u_reach: REACH as i32,
        };
        // Memory rows are the top-down rows: the rule is symmetric, nothing to flip.
        let target = Target::view(w, h, true, true, crate::convention::RowOrder::TopDown);
        let program = ShaderProgram::new(Default::default(), ProgramKind::CyclopeanFill);
        let draw = Draw::fullscreen(program, bytemuck::bytes_of(&params), &images, w, h);
        let mut r = self.device.render(&target, &[draw])?;
        Ok(CyclopeanOutput {
            color: r.color(0)?,
            depth: r.depth(1)?,
            sources: r.take(2, "cyclopean fill")?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cyclopean::fill_reference::fill_reference;
    use crate::io::{DepthMap, RgbImage};

    fn view(w: u32, h: u32, z: Vec<f32>, sources: Vec<u8>) -> CyclopeanOutput {
        let color = (0..w * h).flat_map(|i| [i as u8, (i * 7) as u8, 3]).collect();
        CyclopeanOutput {
            color: Some(RgbImage::new(w, h, color).unwrap()),
            depth: Some(DepthMap::new(w, h, z).unwrap()),
            sources,
        }
    }

    #[test]
    fn a_hole_between_foreground_and_background_takes_the_background() {
        // Row: foreground (1 m) | hole | hole | background (5 m).
        let v = view(4, 1, vec![1.0, 0.0, 0.0, 5.0], vec![3, 0, 0, 3]);
        let f = fill_reference(&v, 4, 1).unwrap();
        assert_eq!(f.depth.as_ref().unwrap().data, [1.0, 5.0, 5.0, 5.0]);
        assert_eq!(f.sources, [3, FILLED, FILLED, 3]);
        let c = &f.color.as_ref().unwrap().data;
        assert_eq!(&c[3..6], &c[9..12], "the hole takes the background pixel's colour");
    }

    #[test]
    fn one_surface_either_side_is_interpolated_and_an_empty_row_takes_the_column() {
        // 2 m and 2.05 m: within SAME_SURFACE, so x = 1..3 mix the two ends by 1 / distance^2.
        let v = view(5, 1, vec![2.0, 0.0, 0.0, 0.0, 2.05], vec![1, 0, 0, 0, 1]);
        let f = fill_reference(&v, 5, 1).unwrap();
        let c = &f.color.as_ref().unwrap().data;
        // Red is the pixel index: 0 at the left end, 4 at the right; x = 1 weighs them 9 : 1.
        assert_eq!((c[3], c[6], c[9]), (0, 2, 4));
        let z = &f.depth.as_ref().unwrap().data;
        assert!((z[2] - 2.025).abs() < 1e-6, "{z:?}");
        // A 1 x 3 column: the middle row is empty, so it takes the column; 4 m and 9 m are two
        // surfaces, so the farther.
        let v = view(1, 3, vec![4.0, 0.0, 9.0], vec![2, 0, 2]);
        let f = fill_reference(&v, 1, 3).unwrap();
        assert_eq!(f.sources, [2, FILLED, 2]);
        assert_eq!(f.depth.as_ref().unwrap().data[1], 9.0);
        assert_eq!(f.color.as_ref().unwrap().data[3], 2);
    }

    /// A slanted, textured plane (depth growing along x, texture in both directions) with a
    /// 24 x 24 hole: the filled region varies no more from row to row than from column to
    /// column (the row-wise fill made every filled row one streak: row-to-row differences 3x the
    /// column-to-column ones on this plane), and its depth stays on the plane.
    #[test]
    fn a_hole_in_a_slanted_textured_plane_is_filled_without_row_streaks() {
        let (w, h) = (64u32, 64u32);
        let hole = |x: u32, y: u32| (20..44).contains(&x) && (20..44).contains(&y);
        let plane = |x: u32| 2.0 + 0.01 * x as f32;
        let tex = |x: u32, y: u32| {
            let (fx, fy) = (x as f32, y as f32);
            (128.0 + 60.0 * (fx * 0.31).sin() + 50.0 * (fy * 0.27).cos()) as u8
        };
        let color: Vec<u8> = (0..h).flat_map(|y| (0..w).flat_map(move |x| [tex(x, y); 3])).collect();
        let z: Vec<f32> = (0..h)
            .flat_map(|y| (0..w).map(move |x| if hole(x, y) { 0.0 } else { plane(x) }))
            .collect();
        let sources: Vec<u8> = (0..h)
            .flat_map(|y| (0..w).map(move |x| u8::from(!hole(x, y))))
            .collect();
        let v = CyclopeanOutput {
            color: Some(RgbImage::new(w, h, color).unwrap()),
            depth: Some(DepthMap::new(w, h, z).unwrap()),
            sources,
        };
        let f = fill_reference(&v, w, h).unwrap();
        let c = &f.color.as_ref().unwrap().data;
        let at = |x: u32, y: u32| c[3 * (y * w + x) as usize] as f64;
        let (mut along_rows, mut along_columns) = (0.0, 0.0);
        for y in 21..43 {
            for x in 21..43 {
                along_columns += (at(x + 1, y) - at(x, y)).abs();
                along_rows += (at(x, y + 1) - at(x, y)).abs();
                let zf = f.depth.as_ref().unwrap().data[(y * w + x) as usize];
                assert!((zf - plane(x)).abs() < 0.15, "({x}, {y}): {zf} m off the plane");
            }
        }
        // Within a factor 1.5 either way: neither direction streaks.
        assert!(
            along_rows <= 1.5 * along_columns && along_columns <= 1.5 * along_rows,
            "row-to-row {along_rows} vs column-to-column {along_columns}"
        );
        assert!(f.sources.iter().all(|s| *s != 0), "the hole is filled");
    }

    #[test]
    fn a_thin_hole_takes_its_sides_not_a_far_surface_beyond_its_end() {
        // Columns: foreground (1 m) | a one-pixel hole | background (3 m); above the hole's end,
        // in its column, a far wall (20 m) that the upward walk meets: beyond twice the row's
        // span (1 px) from row 3 on, so no candidate there. The farthest rule alone painted the wall in.
        let (w, h) = (5usize, 6usize);
        let mut z = vec![0f32; w * h];
        let mut sources = vec![1u8; w * h];
        for y in 0..h {
            for x in 0..w {
                z[y * w + x] = match (x, y) {
                    (2, 0) => 20.0,
                    (2, _) => 0.0,
                    (x, _) if x < 2 => 1.0,
                    _ => 3.0,
                };
            }
            if y > 0 {
                sources[y * w + 2] = 0;
            }
        }
        let f = fill_reference(&view(w as u32, h as u32, z, sources), w as u32, h as u32).unwrap();
        // Rows 1-2 see the wall within reach (2 px); from row 3 it is beyond.
        for y in 3..h {
            assert_eq!(f.depth.as_ref().unwrap().data[y * w + 2], 3.0, "row {y}");
        }
    }

    #[test]
    fn a_border_strip_continues_the_surface_next_to_it() {
        // A wall (10 m) across rows 0-1; below, a floor (2 m) in columns 0-3 and nothing in 4-5:
        // the strip beyond both eyes. Its row runs off the image, so it takes the nearest
        // candidate's layer (the floor), not the farthest (the wall up the strip).
        let (w, h) = (6usize, 8usize);
        let z: Vec<f32> = (0..w * h)
            .map(|i| match (i % w, i / w) {
                (_, 0 | 1) => 10.0,
                (x, _) if x < 4 => 2.0,
                _ => 0.0,
            })
            .collect();
        let sources = z.iter().map(|&d| (d > 0.0) as u8).collect();
        let f = fill_reference(&view(w as u32, h as u32, z, sources), w as u32, h as u32).unwrap();
        // From row 4, where the floor is nearer than the wall (rows 2-3 have the wall as near as
        // the floor in some direction: a tie goes to the farther).
        for y in 4..h {
            for x in 4..w {
                assert_eq!(f.depth.as_ref().unwrap().data[y * w + x], 2.0, "({x}, {y})");
                assert_eq!(f.sources[y * w + x], FILLED);
            }
        }
    }

    #[test]
    fn nothing_valid_stays_a_hole_and_valid_pixels_are_untouched() {
        let v = view(2, 2, vec![0.0; 4], vec![0; 4]);
        let f = fill_reference(&v, 2, 2).unwrap();
        assert_eq!(f.sources, [0; 4]);
        assert!(f.color.unwrap().data.iter().all(|c| *c == 0));
        let v = view(2, 1, vec![1.0, 2.0], vec![1, 2]);
        let f = fill_reference(&v, 2, 1).unwrap();
        assert_eq!(f.color, v.color);
        assert_eq!(f.sources, v.sources);
    }
}
