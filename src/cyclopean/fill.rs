//! `--fill`: a complete middle view for spectators. Holes (pixels no eye saw: disocclusions,
//! unknown disparity, the borders only one eye covers) take the colour and depth of the nearest
//! rendered pixel on their background side: along the row, the farther of the nearest valid
//! pixels to the left and to the right (a disocclusion uncovers what lies behind the occluder,
//! so the foreground edge must not bleed into it).
//! Where both sides lie on one surface (depths within [`SAME_SURFACE`] relative) the hole is in
//! that surface, not a disocclusion, and is interpolated between them by distance. Without a
//! valid pixel in the row, the column is searched the same way (up before down).
//! Filled pixels carry [`FILLED`] alone in their source bits, so the mask file tells them apart
//! (value 128, [`crate::io::MASK_FILLED`]); rendered pixels pass through unchanged.
//!
//! One full-screen pass (shaders/cyclopean/fill.frag) on either executor, and [`fill_reference`],
//! its twin: the choices (which side, one surface or two) compare the same f32 depths, so they
//! agree exactly; copied texels are exact, interpolated ones are the same f32 arithmetic up to
//! the GPU's rounding of the normalised colour (one level at a tie) and its mix (a few ulp).

use super::CyclopeanOutput;
use crate::error::{Error, Result};
use crate::gpu::{ProgramKind, ShaderProgram};
use crate::pass::{Device, Draw, Format, Image, ImageData, Target, ToDevice};

/// The source bit of filled pixels (above the eye and history bits).
pub const FILLED: u8 = crate::io::MASK_FILLED;

crate::param_block! {
    /// shaders/cyclopean/fill_params.glsl, member for member.
    pub struct FillParams("FillParams") {
        u_size: [i32; 2],
        u_filled: u32,
        u_same_surface: f32,
    }
}

/// Relative depth difference below which the pixels either side of a hole are taken as one
/// surface, and the hole is interpolated between them instead of copied from the farther.
pub const SAME_SURFACE: f32 = 0.05;

/// Fills middle views on one device.
pub struct Filler {
    device: Device,
    /// Colour, depth and sources of the last view, rewritten in place for the next of its size.
    inputs: [Option<Image>; 3],
}

/// Colour and depth of `out`, both needed: depth chooses the side, colour is what is filled.
fn planes(out: &CyclopeanOutput) -> Result<(&crate::io::RgbImage, &crate::io::DepthMap)> {
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
        let rgba = crate::gpu::pixels::rgb_to_rgba(&color.data);
        let depth_bytes: &[u8] = bytemuck::cast_slice(&depth.data);
        let image = |format, bytes, label| ImageData {
            width: w,
            height: h,
            format,
            bytes,
            label,
        };
        let [color_slot, depth_slot, sources_slot] = &mut self.inputs;
        let d = &self.device;
        let images = [
            d.put_image(color_slot, &image(Format::Rgba8, &rgba, "fill colour"))?,
            d.put_image(depth_slot, &image(Format::R32F, depth_bytes, "fill depth"))?,
            d.put_image(sources_slot, &image(Format::R8Ui, &out.sources, "fill sources"))?,
        ];
        let params = FillParams {
            u_size: [w as i32, h as i32],
            u_filled: FILLED.into(),
            u_same_surface: SAME_SURFACE,
        };
        // Memory rows are the top-down rows: the rule is symmetric, nothing to flip.
        let target = Target::view(w, h, true, true, crate::convention::RowOrder::TopDown);
        let draw = Draw {
            program: ShaderProgram::new(Default::default(), ProgramKind::CyclopeanFill),
            params: bytemuck::bytes_of(&params),
            images: &images,
            buffers: &[],
            viewport: [0, 0, w, h],
            triangles: 1,
            indices: None,
        };
        let mut r = self.device.render(&target, &[draw])?;
        Ok(CyclopeanOutput {
            color: r.color(0)?,
            depth: r.depth(1)?,
            sources: r.take(2, "cyclopean fill")?,
        })
    }
}

/// The twin of [`Filler::fill`]: the same rule on the CPU.
pub fn fill_reference(out: &CyclopeanOutput, width: u32, height: u32) -> Result<CyclopeanOutput> {
    let (color, depth) = planes(out)?;
    let (w, h) = (width as i64, height as i64);
    let valid = |x: i64, y: i64| out.sources[(y * w + x) as usize] != 0;
    let z = |(x, y): (i64, i64)| depth.data[(y * w + x) as usize];
    // Steps to the nearest valid pixel from (x, y) along (dx, dy) before the edge, and where.
    let nearest = |x: i64, y: i64, dx: i64, dy: i64| -> Option<(i64, (i64, i64))> {
        (1..=w.max(h))
            .map(|k| (k, (x + k * dx, y + k * dy)))
            .take_while(|&(_, (cx, cy))| cx >= 0 && cy >= 0 && cx < w && cy < h)
            .find(|&(_, (cx, cy))| valid(cx, cy))
    };
    let mut filled = out.clone();
    let (fc, fd) = (
        filled.color.as_mut().expect("checked above"),
        filled.depth.as_mut().expect("checked above"),
    );
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if out.sources[i] != 0 {
                continue;
            }
            let mut sides = (nearest(x, y, -1, 0), nearest(x, y, 1, 0));
            if sides == (None, None) {
                sides = (nearest(x, y, 0, -1), nearest(x, y, 0, 1));
            }
            let q = match sides {
                (None, None) => {
                    fc.data[3 * i..3 * i + 3].fill(0);
                    fd.data[i] = 0.0;
                    continue;
                }
                (Some((_, a)), None) => a,
                (None, Some((_, b))) => b,
                (Some((da, a)), Some((db, b))) => {
                    let (za, zb) = (z(a), z(b));
                    if (za - zb).abs() <= SAME_SURFACE * za.max(zb) {
                        // One surface on both sides: interpolated as the shader's mix does, in f32.
                        let t = da as f32 / (da + db) as f32;
                        let (ja, jb) = ((a.1 * w + a.0) as usize, (b.1 * w + b.0) as usize);
                        for c in 0..3 {
                            let (ca, cb) = (color.data[3 * ja + c] as f32, color.data[3 * jb + c] as f32);
                            fc.data[3 * i + c] = (ca + (cb - ca) * t).round() as u8;
                        }
                        fd.data[i] = za + (zb - za) * t;
                        filled.sources[i] = FILLED;
                        continue;
                    }
                    if za > zb {
                        a
                    } else {
                        b
                    }
                }
            };
            let j = (q.1 * w + q.0) as usize;
            fc.data.copy_within(3 * j..3 * j + 3, 3 * i);
            fd.data[i] = depth.data[j];
            filled.sources[i] = FILLED;
        }
    }
    Ok(filled)
}

#[cfg(test)]
mod tests {
    use super::*;
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
        // 2 m and 2.05 m: within SAME_SURFACE, so x = 1..3 mix the two ends by distance.
        let v = view(5, 1, vec![2.0, 0.0, 0.0, 0.0, 2.05], vec![1, 0, 0, 0, 1]);
        let f = fill_reference(&v, 5, 1).unwrap();
        let c = &f.color.as_ref().unwrap().data;
        // Red is the pixel index: 0 at the left end, 4 at the right.
        assert_eq!((c[3], c[6], c[9]), (1, 2, 3));
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
