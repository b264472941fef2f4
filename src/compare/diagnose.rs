//! Which reading of B's conventions fits A: flipped rows (colour PSNR over all pixels), then
//! B's depth read every wrong way a renderer's depth is commonly read: reversed-Z toggled, GL NDC
//! z stored as window depth, linear depth declared device or device depth declared linear, and
//! (by fits over all pixels) depth in other units, window depth under unknown planes, and
//! disparity (a line in 1 / Z) in place of depth.
//!
//! Every reading is scored by its agreement: the share of the compared pixels holding depth on
//! either side where both hold it and agree within 1 %. A share over all pixels does not move
//! with one pixel, nor with the image size: the maxima this check once used named reversed-Z at
//! 320x240 and said nothing at 640x480, where one pixel at an edge decided.

use super::{color_error, stored_top_down, to_top_down, view_z, Comparison, Side};
use crate::convention::{Conventions, RowOrder};
use crate::depth::DepthEncoding;
use crate::io::{DepthMap, RgbImage};

/// Two readings agree at a pixel within this relative difference.
const AGREE_REL: f64 = 1e-2;
/// A reading is named when it agrees on at least this share of the pixels ...
const NAMED_AGREEMENT: f64 = 0.5;
/// ... and on this much more of them than the declared reading.
const NAMED_GAIN: f64 = 0.25;

/// The share of the selected pixels with depth on either side where both agree within 1 %.
fn agreement(za: &[f64], zb: &[f64], selected: &[bool]) -> f64 {
    let (mut either, mut agree) = (0usize, 0usize);
    for ((a, b), _) in za.iter().zip(zb).zip(selected).filter(|(_, s)| **s) {
        if a.is_nan() && b.is_nan() {
            continue;
        }
        either += 1;
        if (a - b).abs() <= AGREE_REL * a.abs() {
            agree += 1;
        }
    }
    agree as f64 / either.max(1) as f64
}

/// Name a reading of B's conventions that fits much better than the declared one.
pub(super) fn diagnose(
    a: &Side,
    b: &Side,
    ca: &RgbImage,
    za: Option<&[f64]>,
    selected: &[bool],
    declared: &Comparison,
) -> Option<String> {
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
    let (za, db) = (za?, b.depth.as_ref()?);
    let declared_agreement = agreement(za, &view_z(db, b.storage, &b.conv), selected);
    if declared_agreement >= 1.0 - NAMED_GAIN {
        return None;
    }
    let score = |zb: Vec<f64>| agreement(za, &zb, selected);
    let named = |what: String, share: f64| {
        (share >= NAMED_AGREEMENT && share >= declared_agreement + NAMED_GAIN).then(|| {
            format!(
                "B's depth fits {what}: {:.1} % of the pixels agree with A within 1 %, {:.1} % as declared",
                share * 100.0,
                declared_agreement * 100.0
            )
        })
    };
    let best = exact_readings(a, b, db)
        .into_iter()
        .map(|(what, storage, conv, depth)| (what, score(view_z(&depth, storage, &conv))))
        .max_by(|x, y| x.1.total_cmp(&y.1));
    if let Some(found) = best.and_then(|(what, share)| named(what, share)) {
        return Some(found);
    }
    // No exact reading: fit B's stored values over all pixels as a line in Z and in 1 / Z.
    let stored = stored_top_down(db, b.conv.row_order);
    fitted_readings(za, &stored, selected)
        .into_iter()
        .map(|(what, zb)| (what, score(zb)))
        .max_by(|x, y| x.1.total_cmp(&y.1))
        .and_then(|(what, share)| named(what, share))
}

/// The wrong readings with a known conversion: (what, storage, conventions, depth as stored).
fn exact_readings(a: &Side, b: &Side, db: &DepthMap) -> Vec<(String, DepthEncoding, Conventions, DepthMap)> {
    let mut out = Vec::new();
    match b.storage {
        DepthEncoding::Device { .. } => {
            let toggled = Conventions {
                reversed_z: !b.conv.reversed_z,
                ..b.conv
            };
            out.push((
                format!(
                    "reversed-Z {} (declared {}; --b-reversed-z)",
                    toggled.reversed_z, b.conv.reversed_z
                ),
                b.storage,
                toggled,
                db.clone(),
            ));
            // GL NDC z in [-1, 1] stored where window depth is declared: window = (z + 1) / 2.
            // (GL and Vulkan NDC ranges give the same window depth for the same planes, so
            // stored window depth cannot tell --b-ndc apart; NDC z stored in its place can.)
            let as_window = DepthMap {
                width: db.width,
                height: db.height,
                data: db.data.iter().map(|v| 0.5 * (v + 1.0)).collect(),
            };
            out.push((
                "GL NDC z in [-1, 1] stored instead of window depth (--b-ndc)".to_string(),
                b.storage,
                b.conv,
                as_window,
            ));
            out.push((
                "view distance in metres, not device depth (--b-depth-kind view-z)".to_string(),
                DepthEncoding::ViewZ,
                b.conv,
                db.clone(),
            ));
        }
        DepthEncoding::ViewZ => {
            if let DepthEncoding::Device { planes } = a.storage {
                for reversed_z in [false, true] {
                    out.push((
                        format!(
                            "device depth under --near {} --far {}, reversed-Z {reversed_z} (--b-depth-kind device)",
                            planes.near, planes.far
                        ),
                        a.storage,
                        Conventions { reversed_z, ..b.conv },
                        db.clone(),
                    ));
                }
            }
        }
        _ => {}
    }
    out
}

/// Readings fitted over all pixels: B's stored value as a line in A's Z (linear depth in other
/// units) and as a line in 1 / Z (window depth under other planes, or disparity).
fn fitted_readings(za: &[f64], stored: &[f64], selected: &[bool]) -> Vec<(String, Vec<f64>)> {
    let pairs: Vec<(f64, f64)> = za
        .iter()
        .zip(stored)
        .zip(selected)
        .filter(|((z, v), s)| **s && z.is_finite() && v.is_finite())
        .map(|((z, v), _)| (*z, *v))
        .collect();
    let mut out = Vec::new();
    let (zs, vs): (Vec<f64>, Vec<f64>) = pairs.iter().copied().unzip();
    if let Some((c, k)) = robust_line(&zs, &vs).filter(|(_, k)| *k != 0.0) {
        let zb = stored.iter().map(|v| positive((v - c) / k)).collect();
        out.push((
            format!("linear depth in other units: stored = {k:.4} x metres + {c:.3}"),
            zb,
        ));
    }
    let inv: Vec<f64> = zs.iter().map(|z| 1.0 / z).collect();
    if let Some((c, k)) = robust_line(&inv, &vs).filter(|(_, k)| *k != 0.0) {
        let zb = stored.iter().map(|v| positive(k / (v - c))).collect();
        let in_unit_range = vs.iter().all(|v| (-1e-6..=1.0 + 1e-6).contains(v));
        let what = if in_unit_range {
            // w = c + k / Z: standard Z has k < 0 and w(near) = 0, reversed-Z k > 0, w(near) = 1.
            let (reversed, near) = if k < 0.0 {
                (false, -k / c)
            } else {
                (true, k / (1.0 - c))
            };
            format!(
                "window depth written with other planes: reversed-Z {reversed}, near ~{near:.4} m \
                 (--b-depth-kind device, --near/--far, --b-reversed-z)"
            )
        } else {
            format!("disparity, not depth: stored = {k:.4} / Z + {c:.3} (a line in 1 / Z)")
        };
        out.push((what, zb));
    }
    out
}

fn positive(z: f64) -> f64 {
    if z.is_finite() && z > 0.0 {
        z
    } else {
        f64::NAN
    }
}

/// y = c + k x by least squares, refitted once without the points whose residual is over three
/// times the median residual (edges and stray pixels); None for fewer than 3 points or no
/// spread in x.
fn robust_line(xs: &[f64], ys: &[f64]) -> Option<(f64, f64)> {
    let fit = |keep: &dyn Fn(usize) -> bool| -> Option<(f64, f64)> {
        let (mut n, mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (_, (x, y)) in xs.iter().zip(ys).enumerate().filter(|(i, _)| keep(*i)) {
            n += 1.0;
            sx += x;
            sy += y;
            sxx += x * x;
            sxy += x * y;
        }
        let det = n * sxx - sx * sx;
        if n < 3.0 || det.abs() <= f64::EPSILON * n * sxx {
            return None;
        }
        let k = (n * sxy - sx * sy) / det;
        Some(((sy - k * sx) / n, k))
    };
    let (c, k) = fit(&|_| true)?;
    let residual = |i: usize| (ys[i] - c - k * xs[i]).abs();
    let mut r: Vec<f64> = (0..xs.len()).map(residual).collect();
    let mid = r.len() / 2;
    let median = *r.select_nth_unstable_by(mid, f64::total_cmp).1;
    fit(&|i| residual(i) <= 3.0 * median).or(Some((c, k)))
}
