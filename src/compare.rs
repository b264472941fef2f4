//! `viewsynth compare`: our outputs against another renderer's (e.g. a Vulkan renderer's colour
//! and device depth), after converting conventions: row order, NDC depth range, reversed-Z and
//! device vs linear depth. Reports colour PSNR, depth errors and mask agreement, writes a diff
//! image, and names a convention that fits far better than the declared one (a flipped or
//! mis-ranged input).

use crate::convention::{Conventions, DepthPlanes, NdcDepthRange, RowOrder};
use crate::error::{Error, Result};
use crate::io::{DepthMap, RgbImage};
use crate::metrics;

/// How one side's depth is stored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DepthStorage {
    /// View-space distance (metres); <= 0 or non-finite = invalid.
    ViewZ,
    /// Window depth under the side's conventions with these planes; the far value = invalid.
    Device(DepthPlanes),
}

/// One side: colour and optional depth as stored in its files (rows in `conv.row_order`).
pub struct Side {
    pub color: RgbImage,
    pub depth: Option<DepthMap>,
    pub storage: DepthStorage,
    pub conv: Conventions,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Comparison {
    pub psnr_db: f64,
    pub max_color_diff: u8,
    /// Over pixels valid in both (after conversion to view Z).
    pub depth_max_abs: Option<f64>,
    pub depth_max_rel: Option<f64>,
    /// Pixels valid in exactly one side.
    pub mask_disagreement: Option<usize>,
    pub pixels: usize,
    /// A reading of B's conventions that fits far better than the declared one, if any.
    pub suspicion: Option<String>,
}

fn to_top_down(color: &RgbImage, rows: RowOrder) -> RgbImage {
    let data = rows.convert_rows(color.data.clone(), color.width as usize * 3);
    RgbImage {
        width: color.width,
        height: color.height,
        data,
    }
}

/// View distance per pixel (top-down), NaN where invalid.
fn view_z(depth: &DepthMap, storage: DepthStorage, conv: &Conventions) -> Vec<f64> {
    let bytes: Vec<u8> = crate::gpu::pixels::f32_to_bytes(&depth.data);
    let rows = conv.row_order.convert_rows(bytes, depth.width as usize * 4);
    crate::gpu::pixels::bytes_to_f32(&rows)
        .into_iter()
        .map(|d| d as f64)
        .map(|d| match storage {
            DepthStorage::ViewZ => {
                if d.is_finite() && d > 0.0 {
                    d
                } else {
                    f64::NAN
                }
            }
            DepthStorage::Device(planes) => {
                let far = conv.clear_depth();
                if !d.is_finite() || (d - far).abs() <= 1e-6 {
                    return f64::NAN;
                }
                let ndc = match conv.ndc_depth {
                    NdcDepthRange::MinusOneToOne => 2.0 * d - 1.0,
                    NdcDepthRange::ZeroToOne => d,
                };
                let z = planes.view_z_of_ndc_z(conv, ndc);
                if z.is_finite() && z > 0.0 {
                    z
                } else {
                    f64::NAN
                }
            }
        })
        .collect()
}

fn color_error(a: &RgbImage, b: &RgbImage) -> (f64, u8) {
    let (mut sq, mut max) = (0.0, 0u8);
    for (x, y) in a.data.iter().zip(&b.data) {
        let d = (*x as i32 - *y as i32).unsigned_abs() as u8;
        sq += (d as f64) * (d as f64);
        max = max.max(d);
    }
    (metrics::psnr_from_mse(sq / a.data.len().max(1) as f64), max)
}

fn depth_error(a: &[f64], b: &[f64]) -> (f64, f64, usize, usize) {
    let (mut abs, mut rel, mut disagree, mut both) = (0f64, 0f64, 0, 0);
    for (x, y) in a.iter().zip(b) {
        match (x.is_nan(), y.is_nan()) {
            (false, false) => {
                both += 1;
                abs = abs.max((x - y).abs());
                rel = rel.max((x - y).abs() / x.abs());
            }
            (true, true) => {}
            _ => disagree += 1,
        }
    }
    (abs, rel, disagree, both)
}

/// Compare A and B after converting both to top-down images and view distance.
pub fn compare(a: &Side, b: &Side) -> Result<(Comparison, RgbImage)> {
    if (a.color.width, a.color.height) != (b.color.width, b.color.height) {
        return Err(Error::SizeMismatch {
            message: format!(
                "A is {}x{}, B is {}x{}",
                a.color.width, a.color.height, b.color.width, b.color.height
            ),
        });
    }
    for (name, s) in [("A", a), ("B", b)] {
        if let Some(d) = &s.depth {
            if (d.width, d.height) != (s.color.width, s.color.height) {
                return Err(Error::SizeMismatch {
                    message: format!("{name}: depth size differs from its colour"),
                });
            }
        }
    }
    let (ca, cb) = (
        to_top_down(&a.color, a.conv.row_order),
        to_top_down(&b.color, b.conv.row_order),
    );
    let (psnr_db, max_color_diff) = color_error(&ca, &cb);
    let mut cmp = Comparison {
        psnr_db,
        max_color_diff,
        depth_max_abs: None,
        depth_max_rel: None,
        mask_disagreement: None,
        pixels: ca.data.len() / 3,
        suspicion: None,
    };
    let za = a.depth.as_ref().map(|d| view_z(d, a.storage, &a.conv));
    if let (Some(za), Some(db)) = (&za, &b.depth) {
        let (abs, rel, disagree, _) = depth_error(za, &view_z(db, b.storage, &b.conv));
        cmp.depth_max_abs = Some(abs);
        cmp.depth_max_rel = Some(rel);
        cmp.mask_disagreement = Some(disagree);
    }
    cmp.suspicion = diagnose(a, b, &ca, za.as_deref(), &cmp);
    let diff = RgbImage {
        width: ca.width,
        height: ca.height,
        data: ca
            .data
            .iter()
            .zip(&cb.data)
            .map(|(x, y)| ((*x as i32 - *y as i32).unsigned_abs() * 8).min(255) as u8)
            .collect(),
    };
    Ok((cmp, diff))
}

/// Try the other readings of B's conventions; name one that fits much better than the declared.
/// (GL and Vulkan NDC ranges give the same window depth for the same planes, so stored window
/// depth cannot tell them apart; NDC z stored in place of window depth, and a reversed-Z
/// mismatch, can be told.)
fn diagnose(_a: &Side, b: &Side, ca: &RgbImage, za: Option<&[f64]>, declared: &Comparison) -> Option<String> {
    let other_rows = match b.conv.row_order {
        RowOrder::BottomUp => RowOrder::TopDown,
        RowOrder::TopDown => RowOrder::BottomUp,
    };
    let (flipped_psnr, _) = color_error(ca, &to_top_down(&b.color, other_rows));
    if flipped_psnr > declared.psnr_db + 10.0 {
        return Some(format!(
            "B's rows look flipped: read as {other_rows:?} it matches at {flipped_psnr:.1} dB (declared {:?}: {:.1} dB)",
            b.conv.row_order, declared.psnr_db
        ));
    }
    let (za, db, DepthStorage::Device(planes)) = (za?, b.depth.as_ref()?, b.storage) else {
        return None;
    };
    let declared_rel = declared.depth_max_rel.unwrap_or(f64::INFINITY);
    let fits = |depth: &DepthMap, conv: &Conventions| {
        let (_, rel, disagree, both) = depth_error(za, &view_z(depth, DepthStorage::Device(planes), conv));
        (both > 0 && disagree * 100 <= both).then_some(rel)
    };
    // NDC z in [-1, 1] stored where window depth is declared: window = (z + 1) / 2.
    let as_window = DepthMap {
        width: db.width,
        height: db.height,
        data: db.data.iter().map(|v| 0.5 * (v + 1.0)).collect(),
    };
    let toggled = Conventions {
        reversed_z: !b.conv.reversed_z,
        ..b.conv
    };
    let readings = [
        (
            fits(&as_window, &b.conv),
            "GL NDC z in [-1, 1] stored instead of window depth".to_string(),
        ),
        (
            fits(db, &toggled),
            format!("reversed-Z {} (declared {})", toggled.reversed_z, b.conv.reversed_z),
        ),
    ];
    let best = readings
        .into_iter()
        .filter_map(|(rel, what)| rel.map(|r| (r, what)))
        .min_by(|x, y| x.0.total_cmp(&y.0));
    match best {
        Some((rel, what)) if rel * 100.0 < declared_rel && declared_rel > 1e-4 => Some(format!(
            "B's depth fits {what} (max rel error {rel:.2e}) far better than as declared ({declared_rel:.2e})"
        )),
        _ => None,
    }
}
