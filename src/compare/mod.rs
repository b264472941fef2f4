//! `viewsynth compare`: our outputs against another renderer's (e.g. a Vulkan renderer's colour
//! and device depth), after converting conventions: row order, NDC depth range, reversed-Z and
//! device vs linear depth. Reports colour PSNR, the distribution of the per-pixel colour and
//! depth errors (median, p99, p99.9, maximum, share over thresholds: `distribution.rs`), FLIP
//! (`flip.rs`), mask agreement, a diff image, and names a reading of B's conventions that fits
//! far better than the declared one (`diagnose.rs`). CI limits: `thresholds.rs`.

mod colour;
mod colour_check;
mod depth_share;
mod diagnose;
pub mod distribution;
pub mod flip;
mod thresholds;

pub use colour::{srgb_decode, srgb_encode, Alpha, ChannelOrder, ColourReading, Transfer};
pub use depth_share::{DepthShare, DepthValidity};
pub use distribution::{ErrorDistribution, ShareOver};
pub use flip::Flip;
pub use thresholds::{percent, BadPixel, Thresholds};

use crate::convention::{Conventions, RowOrder};
use crate::depth::{DepthEncoding, DepthKind};
use crate::error::{Error, Result};
use crate::io::{ColourImage, DepthMap, Mask, RgbImage};
use crate::metrics;

/// Per-pixel colour thresholds (largest channel difference, 8-bit levels) whose shares are
/// always reported.
pub const COLOR_LEVELS_REPORTED: [f64; 6] = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0];
/// Relative depth error thresholds whose shares are always reported.
pub const DEPTH_REL_REPORTED: [f64; 5] = [1e-5, 1e-4, 1e-3, 1e-2, 1e-1];

/// One side: colour and optional depth as stored in its files (rows in `conv.row_order`).
pub struct Side {
    /// Colour at its file's precision.
    pub color: ColourImage,
    /// How the colour is stored (channel order, transfer, alpha).
    pub colour: ColourReading,
    /// Depth as stored in the file, decoded per `storage`; None compares colour only.
    pub depth: Option<DepthMap>,
    /// What the depth holds (view distance is refused: no rays here).
    pub storage: DepthEncoding,
    /// Device depth only: the file holds NDC z in `conv.ndc_depth`'s range (what a shader
    /// writes as clip z / w), not window depth; the only case where the NDC range matters, as
    /// window depth is the same function of Z under either range.
    pub ndc_z: bool,
    /// NDC depth range, reversed-Z and row order the side was rendered under.
    pub conv: Conventions,
}

impl Side {
    /// A side whose colour is stored as RGB, sRGB, straight alpha, and whose device depth (if
    /// any) is window depth.
    pub fn new(
        color: impl Into<ColourImage>,
        depth: Option<DepthMap>,
        storage: DepthEncoding,
        conv: Conventions,
    ) -> Self {
        Side {
            color: color.into(),
            colour: ColourReading::default(),
            depth,
            storage,
            ndc_z: false,
            conv,
        }
    }
}

/// The differences between two renderings, as printed and written to JSON by `compare`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Comparison {
    /// Colour PSNR over the compared pixels (peak 1 on colour in [0, 1], the same as peak 255
    /// on 8-bit levels); infinite (written "inf") when identical.
    #[serde(serialize_with = "infinite_as_string")]
    pub psnr_db: f64,
    /// Colour RMSE in 8-bit levels (1/255 of the range: fractional for 16-bit and float
    /// colour) over the compared pixels' samples.
    pub color_rmse: f64,
    /// Largest per-sample colour difference, 8-bit levels.
    pub max_color_diff: f64,
    /// Per pixel, the largest channel difference in 8-bit levels: its distribution over the
    /// compared pixels.
    pub color_error: ErrorDistribution,
    /// Bits per colour sample of A's and B's files (8, 16, or 32 for float): colour is
    /// compared at this precision, not quantised to 8 bits.
    pub color_bits: [u8; 2],
    /// Mean SSIM (Wang et al. 2004) on BT.601 luma over the compared pixels; None when the
    /// images are under 11x11 (no whole window).
    pub ssim: Option<f64>,
    /// Over pixels valid in both (after conversion to view Z).
    pub depth_max_abs: Option<f64>,
    /// Largest relative view-Z difference |A - B| / A, over pixels valid in both.
    pub depth_max_rel: Option<f64>,
    /// The distribution of |A - B| / A over pixels valid in both.
    pub depth_rel_error: Option<ErrorDistribution>,
    /// Pixels valid in exactly one side.
    pub mask_disagreement: Option<usize>,
    /// Over the compared pixels: depth valid in both, in A only, in B only.
    pub depth_valid: Option<DepthValidity>,
    /// The depth share at the bad-pixel threshold as `--max-bad-share` gates it: pixels over
    /// the threshold plus those valid on one side only, over those with depth on either side.
    pub depth_bad: Option<DepthShare>,
    /// Pixels compared: all, or those of the mask.
    pub pixels: usize,
    /// FLIP mean over the compared pixels (B the reference), when measured.
    pub flip_mean: Option<f64>,
    /// Readings of B's conventions that fit far better than the declared ones (colour first,
    /// then depth), each naming the option that declares it.
    pub suspicions: Vec<String>,
    /// The diff image is |A - B| (8-bit levels) times this, so the largest difference is white
    /// (255) and none saturates: 255 / max_color_diff, or 1 when A and B are identical.
    pub diff_scale: f64,
}

/// What [`compare_with`] measures beyond the defaults.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Measures {
    /// The per-pixel thresholds of the share gate (their shares are reported too).
    pub bad: BadPixel,
    /// Run FLIP (B the reference): its mean and its magma error map.
    pub flip: bool,
}

/// A comparison and its images.
#[derive(Debug, Clone)]
pub struct Compared {
    /// The figures.
    pub comparison: Comparison,
    /// |A - B| per channel times `comparison.diff_scale`, black outside the mask.
    pub diff: RgbImage,
    /// FLIP's error map in its magma colours, black outside the mask (with `Measures::flip`).
    pub flip_map: Option<RgbImage>,
}

/// JSON has no infinity: serde_json would write null. Writes "inf" / "-inf" instead.
fn infinite_as_string<S: serde::Serializer>(v: &f64, s: S) -> std::result::Result<S::Ok, S::Error> {
    if v.is_infinite() {
        s.serialize_str(if *v > 0.0 { "inf" } else { "-inf" })
    } else {
        s.serialize_f64(*v)
    }
}

pub(crate) fn optional_infinite_as_string<S: serde::Serializer>(
    v: &Option<f64>,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    match v {
        Some(v) => infinite_as_string(v, s),
        None => s.serialize_none(),
    }
}

/// The stored depth values, rows top-down.
fn stored_top_down(depth: &DepthMap, rows: RowOrder) -> Vec<f64> {
    let rows = match rows {
        RowOrder::TopDown => depth.data.clone(),
        RowOrder::BottomUp => colour::flip_rows(&depth.data, depth.width as usize),
    };
    rows.into_iter().map(f64::from).collect()
}

/// View distance per pixel (top-down), NaN where invalid. NDC z stored (`ndc_z`) is first
/// turned into window depth under `conv`'s range.
fn view_z(depth: &DepthMap, storage: DepthEncoding, conv: &Conventions, ndc_z: bool) -> Vec<f64> {
    stored_top_down(depth, conv.row_order)
        .into_iter()
        .map(|d| {
            let d = if ndc_z {
                crate::depth::window_depth_of_ndc_z(d, conv)
            } else {
                d
            };
            storage.view_z(conv, d, 1.0).unwrap_or(f64::NAN)
        })
        .collect()
}

/// The largest channel difference of each selected pixel, 8-bit levels (NaN against a number
/// counts as the whole range).
fn color_pixel_errors(a: &[f32], b: &[f32], selected: &[bool]) -> Vec<f64> {
    a.chunks_exact(3)
        .zip(b.chunks_exact(3))
        .zip(selected)
        .filter(|(_, s)| **s)
        .map(|((x, y), _)| x.iter().zip(y).map(|(x, y)| level_diff(*x, *y)).fold(0.0, f64::max))
        .collect()
}

/// |x - y| in 8-bit levels, rounded to 1e-4 levels: f32 samples hold v / 255 to ~1e-5 levels,
/// so 8-bit colour differs by whole levels and a 16-bit level (1/257 of one) stays visible;
/// 255 where one is NaN and the other not.
fn level_diff(x: f32, y: f32) -> f64 {
    let (x, y) = (f64::from(x), f64::from(y));
    match (x.is_nan(), y.is_nan()) {
        (false, false) => ((x - y).abs() * 255.0 * 1e4).round() / 1e4,
        (true, true) => 0.0,
        _ => 255.0,
    }
}

/// (PSNR, RMSE in levels, max difference in levels) over the selected pixels.
fn color_error(a: &[f32], b: &[f32], selected: &[bool]) -> (f64, f64, f64) {
    let (mut sq, mut max, mut n) = (0.0, 0.0f64, 0usize);
    for ((x, y), _) in a
        .chunks_exact(3)
        .zip(b.chunks_exact(3))
        .zip(selected)
        .filter(|(_, s)| **s)
    {
        for (x, y) in x.iter().zip(y) {
            let d = level_diff(*x, *y);
            sq += d * d;
            max = max.max(d);
            n += 1;
        }
    }
    let mse = sq / n.max(1) as f64;
    (metrics::psnr_from_mse(mse), mse.sqrt(), max)
}

/// Mean SSIM on BT.601 luma (0..255 scale) of the compared forms over the selected pixels.
fn ssim(a: &[f32], b: &[f32], width: u32, height: u32, selected: &[bool]) -> Option<f64> {
    let luma = |c: &[f32]| -> Vec<f64> {
        c.chunks_exact(3)
            .map(|p| 255.0 * (0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2])))
            .collect()
    };
    crate::ssim::ssim_luma_planes(&luma(a), &luma(b), width as usize, height as usize, Some(selected))
}

/// Depth errors over the selected pixels valid in both.
struct DepthErrors {
    max_abs: f64,
    /// |A - B| / A per pixel valid in both.
    rel: Vec<f64>,
    /// Which pixels hold depth on each side.
    valid: DepthValidity,
}

fn depth_error(a: &[f64], b: &[f64], selected: &[bool]) -> DepthErrors {
    let mut e = DepthErrors {
        max_abs: 0.0,
        rel: Vec::new(),
        valid: DepthValidity::default(),
    };
    for ((x, y), _) in a.iter().zip(b).zip(selected).filter(|(_, s)| **s) {
        match (x.is_nan(), y.is_nan()) {
            (false, false) => {
                e.max_abs = e.max_abs.max((x - y).abs());
                e.rel.push((x - y).abs() / x.abs());
                e.valid.both += 1;
            }
            (true, true) => {}
            (false, true) => e.valid.a_only += 1,
            (true, false) => e.valid.b_only += 1,
        }
    }
    e
}

/// Compare A and B after converting both to top-down images and view distance.
pub fn compare(a: &Side, b: &Side) -> Result<(Comparison, RgbImage)> {
    compare_masked(a, b, None)
}

/// [`compare`] over the pixels where `mask` (top-down, the images' size) is nonzero; the diff
/// image is black elsewhere. No FLIP; the default bad-pixel thresholds.
pub fn compare_masked(a: &Side, b: &Side, mask: Option<&Mask>) -> Result<(Comparison, RgbImage)> {
    let c = compare_with(a, b, mask, Measures::default())?;
    Ok((c.comparison, c.diff))
}

fn check_sides(a: &Side, b: &Side, mask: Option<&Mask>) -> Result<Vec<bool>> {
    if (a.color.width, a.color.height) != (b.color.width, b.color.height) {
        return Err(Error::SizeMismatch {
            message: format!(
                "A is {}x{}, B is {}x{}",
                a.color.width, a.color.height, b.color.width, b.color.height
            ),
        });
    }
    for (name, s) in [("A", a), ("B", b)] {
        s.storage.check_accepted(
            &format!("{name} depth kind"),
            &[DepthKind::ViewZ, DepthKind::Device, DepthKind::Disparity],
        )?;
        if s.colour.alpha == Alpha::Premultiplied && s.color.alpha.is_none() {
            return Err(Error::param(
                format!("{name} alpha"),
                "premultiplied declared, but its colour file has no alpha channel",
            ));
        }
        if let Some(d) = &s.depth {
            if (d.width, d.height) != (s.color.width, s.color.height) {
                return Err(Error::SizeMismatch {
                    message: format!("{name}: depth size differs from its colour"),
                });
            }
        }
    }
    let selected: Vec<bool> = match mask {
        Some(m) if (m.width, m.height) != (a.color.width, a.color.height) => {
            return Err(Error::SizeMismatch {
                message: format!(
                    "the mask is {}x{}, the images {}x{}",
                    m.width, m.height, a.color.width, a.color.height
                ),
            })
        }
        Some(m) => m.data.iter().map(|v| *v != 0).collect(),
        None => vec![true; a.color.width as usize * a.color.height as usize],
    };
    if !selected.iter().any(|s| *s) {
        return Err(Error::param("mask", "selects no pixel: nothing to compare"));
    }
    Ok(selected)
}

/// [`compare_masked`] measuring what `measures` asks: the share over its bad-pixel thresholds
/// and FLIP.
pub fn compare_with(a: &Side, b: &Side, mask: Option<&Mask>, measures: Measures) -> Result<Compared> {
    let selected = check_sides(a, b, mask)?;
    let pixels = selected.iter().filter(|s| **s).count();
    let (w, h) = (a.color.width, a.color.height);
    let ca = colour::compared_form(&a.color, a.colour, a.conv.row_order);
    let cb = colour::compared_form(&b.color, b.colour, b.conv.row_order);
    let (psnr_db, color_rmse, max_color_diff) = color_error(&ca, &cb, &selected);
    let diff_scale = if max_color_diff == 0.0 {
        1.0
    } else {
        255.0 / max_color_diff
    };
    let mut levels = COLOR_LEVELS_REPORTED.to_vec();
    levels.push(measures.bad.color_levels);
    let color_error = ErrorDistribution::of(color_pixel_errors(&ca, &cb, &selected), &levels)
        .expect("check_sides: the mask selects a pixel");
    let mut cmp = Comparison {
        psnr_db,
        color_rmse,
        max_color_diff,
        color_error,
        color_bits: [a.color.bits, b.color.bits],
        ssim: ssim(&ca, &cb, w, h, &selected),
        depth_max_abs: None,
        depth_max_rel: None,
        depth_rel_error: None,
        mask_disagreement: None,
        depth_valid: None,
        depth_bad: None,
        pixels,
        flip_mean: None,
        suspicions: Vec::new(),
        diff_scale,
    };
    let za = a.depth.as_ref().map(|d| view_z(d, a.storage, &a.conv, a.ndc_z));
    if let (Some(za), Some(db)) = (&za, &b.depth) {
        let e = depth_error(za, &view_z(db, b.storage, &b.conv, b.ndc_z), &selected);
        let mut rels = DEPTH_REL_REPORTED.to_vec();
        rels.push(measures.bad.depth_rel);
        // No pixel with depth on both sides (all NaN, say) compares nothing: no error is
        // measured, so a depth limit fails ("no depth was compared") instead of passing at 0.
        cmp.depth_max_rel = e.rel.iter().copied().reduce(f64::max);
        cmp.depth_max_abs = cmp.depth_max_rel.map(|_| e.max_abs);
        cmp.depth_bad = Some(DepthShare::of(&e.rel, e.valid, measures.bad.depth_rel));
        cmp.depth_rel_error = ErrorDistribution::of(e.rel, &rels);
        cmp.mask_disagreement = Some(e.valid.one_side());
        cmp.depth_valid = Some(e.valid);
    }
    let colour = colour_check::suspicion(a, b, &ca, &cb, &selected);
    // Flipped rows misplace depth too: the depth check would only name the same mistake.
    let rows_named = colour.as_ref().is_some_and(|c| c.rows);
    cmp.suspicions.extend(colour.map(|c| c.line));
    if !rows_named {
        let tolerance = diagnose::AGREE_REL.min(measures.bad.depth_rel);
        cmp.suspicions
            .extend(diagnose::diagnose(a, b, za.as_deref(), &selected, tolerance));
    }
    let data = ca
        .chunks_exact(3)
        .zip(cb.chunks_exact(3))
        .zip(&selected)
        .flat_map(|((x, y), s)| {
            let d = |i: usize| {
                if *s {
                    (level_diff(x[i], y[i]) * diff_scale).round().min(255.0) as u8
                } else {
                    0
                }
            };
            [d(0), d(1), d(2)]
        })
        .collect();
    let diff = RgbImage {
        width: w,
        height: h,
        data,
    };
    // FLIP is LDR FLIP: it reads 8-bit sRGB, so deeper colour is rounded for it alone. The
    // compared forms go before FLIP's working memory is taken (the peak of `compare`).
    let rgb8 = measures
        .flip
        .then(|| (colour::to_rgb8(&cb, w, h), colour::to_rgb8(&ca, w, h)));
    drop((ca, cb));
    let flip_map = rgb8.map(|(rb, ra)| {
        let flip = Flip::of(&rb, &ra);
        cmp.flip_mean = Some(flip.mean(&selected));
        flip.magma_map(&selected)
    });
    Ok(Compared {
        comparison: cmp,
        diff,
        flip_map,
    })
}
