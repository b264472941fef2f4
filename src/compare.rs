//! `viewsynth compare`: our outputs against another renderer's (e.g. a Vulkan renderer's colour
//! and device depth), after converting conventions: row order, NDC depth range, reversed-Z and
//! device vs linear depth. Reports colour PSNR, depth errors and mask agreement, writes a diff
//! image, and names a convention that fits far better than the declared one (a flipped or
//! mis-ranged input).

use crate::convention::{Conventions, RowOrder};
use crate::depth::{DepthEncoding, DepthKind};
use crate::error::{Error, Result};
use crate::io::{DepthMap, Mask, RgbImage};
use crate::metrics;

/// One side: colour and optional depth as stored in its files (rows in `conv.row_order`).
pub struct Side {
    /// Colour, 8-bit RGB.
    pub color: RgbImage,
    /// Depth as stored in the file, decoded per `storage`; None compares colour only.
    pub depth: Option<DepthMap>,
    /// What the depth holds (view distance is refused: no rays here).
    pub storage: DepthEncoding,
    /// NDC depth range, reversed-Z and row order the side was rendered under.
    pub conv: Conventions,
}

/// The differences between two renderings, as printed and written to JSON by `compare`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Comparison {
    /// Colour PSNR over the compared pixels; infinite (written "inf") when identical.
    #[serde(serialize_with = "infinite_as_string")]
    pub psnr_db: f64,
    /// Colour RMSE in 8-bit levels over the compared pixels' samples.
    pub color_rmse: f64,
    /// Largest per-sample colour difference, 8-bit levels.
    pub max_color_diff: u8,
    /// Over pixels valid in both (after conversion to view Z).
    pub depth_max_abs: Option<f64>,
    /// Largest relative view-Z difference |A - B| / A, over pixels valid in both.
    pub depth_max_rel: Option<f64>,
    /// Pixels valid in exactly one side.
    pub mask_disagreement: Option<usize>,
    /// Pixels compared: all, or those of the mask.
    pub pixels: usize,
    /// A reading of B's conventions that fits far better than the declared one, if any.
    pub suspicion: Option<String>,
    /// The diff image is |A - B| times this, so the largest difference is white (255) and none
    /// saturates: 255 / max_color_diff, or 1 when A and B are identical.
    pub diff_scale: f64,
}

/// JSON has no infinity: serde_json would write null. Writes "inf" / "-inf" instead.
fn infinite_as_string<S: serde::Serializer>(v: &f64, s: S) -> std::result::Result<S::Ok, S::Error> {
    if v.is_infinite() {
        s.serialize_str(if *v > 0.0 { "inf" } else { "-inf" })
    } else {
        s.serialize_f64(*v)
    }
}

fn optional_infinite_as_string<S: serde::Serializer>(v: &Option<f64>, s: S) -> std::result::Result<S::Ok, S::Error> {
    match v {
        Some(v) => infinite_as_string(v, s),
        None => s.serialize_none(),
    }
}

/// Pass/fail limits for `compare` in CI; unset limits are not checked.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Thresholds {
    /// Largest colour RMSE allowed, 8-bit levels.
    pub max_color_rmse: Option<f64>,
    /// Smallest colour PSNR allowed, dB (inf: identical colour required).
    #[serde(serialize_with = "optional_infinite_as_string")]
    pub min_psnr_db: Option<f64>,
    /// Largest relative view-Z error allowed over pixels valid in both.
    pub max_depth_rel: Option<f64>,
}

impl Thresholds {
    /// Refuses a negative or non-finite RMSE / depth limit and a NaN PSNR limit, naming the option.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("max-colour-rmse", self.max_color_rmse),
            ("max-depth-rel", self.max_depth_rel),
        ] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(Error::param(name, format!("{v}: must be finite and >= 0")));
            }
        }
        if let Some(v) = self.min_psnr_db.filter(|v| v.is_nan()) {
            return Err(Error::param("min-psnr", format!("{v} is not a number")));
        }
        Ok(())
    }

    /// The limits `c` breaks, each as a sentence with the measured value.
    pub fn broken(&self, c: &Comparison) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(max) = self.max_color_rmse.filter(|max| c.color_rmse > *max) {
            out.push(format!("colour RMSE {:.4} > {max} levels", c.color_rmse));
        }
        if let Some(min) = self.min_psnr_db.filter(|min| c.psnr_db < *min) {
            out.push(format!("PSNR {:.2} dB < {min} dB", c.psnr_db));
        }
        if let Some(max) = self.max_depth_rel {
            match c.depth_max_rel {
                Some(rel) if rel > max => out.push(format!("max relative depth error {rel:.3e} > {max:e}")),
                Some(_) => {}
                None => out.push("max relative depth error: no depth was compared".into()),
            }
        }
        out
    }
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
fn view_z(depth: &DepthMap, storage: DepthEncoding, conv: &Conventions) -> Vec<f64> {
    let bytes: Vec<u8> = crate::gpu::pixels::f32_to_bytes(&depth.data);
    let rows = conv.row_order.convert_rows(bytes, depth.width as usize * 4);
    crate::gpu::pixels::bytes_to_f32(&rows)
        .into_iter()
        .map(|d| storage.view_z(conv, d as f64, 1.0).unwrap_or(f64::NAN))
        .collect()
}

/// (PSNR, RMSE in levels, max difference) over the selected pixels.
fn color_error(a: &RgbImage, b: &RgbImage, selected: &[bool]) -> (f64, f64, u8) {
    let (mut sq, mut max, mut n) = (0.0, 0u8, 0usize);
    for ((x, y), _) in a
        .data
        .chunks_exact(3)
        .zip(b.data.chunks_exact(3))
        .zip(selected)
        .filter(|(_, s)| **s)
    {
        for (x, y) in x.iter().zip(y) {
            let d = x.abs_diff(*y);
            sq += f64::from(d) * f64::from(d);
            max = max.max(d);
            n += 1;
        }
    }
    let mse = sq / n.max(1) as f64;
    (metrics::psnr_from_mse(mse), mse.sqrt(), max)
}

fn depth_error(a: &[f64], b: &[f64], selected: &[bool]) -> (f64, f64, usize, usize) {
    let (mut abs, mut rel, mut disagree, mut both) = (0f64, 0f64, 0, 0);
    for ((x, y), _) in a.iter().zip(b).zip(selected).filter(|(_, s)| **s) {
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
    compare_masked(a, b, None)
}

/// [`compare`] over the pixels where `mask` (top-down, the images' size) is nonzero; the diff
/// image is black elsewhere.
pub fn compare_masked(a: &Side, b: &Side, mask: Option<&Mask>) -> Result<(Comparison, RgbImage)> {
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
    let pixels = selected.iter().filter(|s| **s).count();
    if pixels == 0 {
        return Err(Error::param("mask", "selects no pixel: nothing to compare"));
    }
    let (ca, cb) = (
        to_top_down(&a.color, a.conv.row_order),
        to_top_down(&b.color, b.conv.row_order),
    );
    let (psnr_db, color_rmse, max_color_diff) = color_error(&ca, &cb, &selected);
    let diff_scale = if max_color_diff == 0 {
        1.0
    } else {
        255.0 / f64::from(max_color_diff)
    };
    let mut cmp = Comparison {
        psnr_db,
        color_rmse,
        max_color_diff,
        depth_max_abs: None,
        depth_max_rel: None,
        mask_disagreement: None,
        pixels,
        suspicion: None,
        diff_scale,
    };
    let za = a.depth.as_ref().map(|d| view_z(d, a.storage, &a.conv));
    if let (Some(za), Some(db)) = (&za, &b.depth) {
        let (abs, rel, disagree, both) = depth_error(za, &view_z(db, b.storage, &b.conv), &selected);
        // No pixel with depth on both sides (all NaN, say) compares nothing: no error is
        // measured, so a depth limit fails ("no depth was compared") instead of passing at 0.
        if both > 0 {
            cmp.depth_max_abs = Some(abs);
            cmp.depth_max_rel = Some(rel);
        }
        cmp.mask_disagreement = Some(disagree);
    }
    cmp.suspicion = diagnose(b, &ca, za.as_deref(), &selected, &cmp);
    let data = ca
        .data
        .chunks_exact(3)
        .zip(cb.data.chunks_exact(3))
        .zip(&selected)
        .flat_map(|((x, y), s)| {
            let d = |i: usize| {
                if *s {
                    (f64::from(x[i].abs_diff(y[i])) * diff_scale).round() as u8
                } else {
                    0
                }
            };
            [d(0), d(1), d(2)]
        })
        .collect();
    let diff = RgbImage {
        width: ca.width,
        height: ca.height,
        data,
    };
    Ok((cmp, diff))
}

/// Try the other readings of B's conventions; name one that fits much better than the declared.
/// (GL and Vulkan NDC ranges give the same window depth for the same planes, so stored window
/// depth cannot tell them apart; NDC z stored in place of window depth, and a reversed-Z
/// mismatch, can be told.)
fn diagnose(b: &Side, ca: &RgbImage, za: Option<&[f64]>, selected: &[bool], declared: &Comparison) -> Option<String> {
    let other_rows = match b.conv.row_order {
        RowOrder::BottomUp => RowOrder::TopDown,
        RowOrder::TopDown => RowOrder::BottomUp,
    };
    let (flipped_psnr, _, _) = color_error(ca, &to_top_down(&b.color, other_rows), selected);
    if flipped_psnr > declared.psnr_db + 10.0 {
        return Some(format!(
            "B's rows look flipped: read as {} it matches at {flipped_psnr:.1} dB (declared {}: {:.1} dB)",
            other_rows.name(),
            b.conv.row_order.name(),
            declared.psnr_db
        ));
    }
    let (za, db, DepthEncoding::Device { planes }) = (za?, b.depth.as_ref()?, b.storage) else {
        return None;
    };
    let declared_rel = declared.depth_max_rel.unwrap_or(f64::INFINITY);
    let fits = |depth: &DepthMap, conv: &Conventions| {
        let (_, rel, disagree, both) =
            depth_error(za, &view_z(depth, DepthEncoding::Device { planes }, conv), selected);
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
