//! Which reading of B's depth fits A (B's colour is checked in `colour_check.rs`): B's depth
//! read every wrong way a renderer's depth is commonly read: reversed-Z toggled, GL NDC z stored
//! as window depth (and the reverse), an infinite far plane read as finite, other planes than
//! A's, linear depth declared device or device depth declared linear, and (by fits over all
//! pixels) depth in other units, window depth under unknown planes, and disparity (a line in
//! 1 / Z) in place of depth.
//!
//! Every reading is scored by its agreement: the share of the compared pixels holding depth on
//! either side where both hold it and agree within the tolerance (1 %, or the share gate's
//! per-pixel threshold when that is tighter: a reading that passes the check must not fail
//! the gate on every pixel, as an infinite far plane read with far 1000 did). A share over all
//! pixels does not move with one pixel, nor with the image size: the maxima this check once
//! used named reversed-Z at 320x240 and said nothing at 640x480, where one pixel at an edge
//! decided.

use super::{stored_top_down, view_z, Side};
use crate::convention::{DepthPlanes, NdcDepthRange};
use crate::depth::DepthEncoding;
use crate::field::{Field, Message};
use crate::msg;

/// Two readings agree at a pixel within this relative difference, at most.
pub(super) const AGREE_REL: f64 = 1e-2;
/// A reading is named when it agrees on at least this share of the pixels ...
const NAMED_AGREEMENT: f64 = 0.5;
/// ... and on this much more of them than the declared reading.
const NAMED_GAIN: f64 = 0.25;

/// The share of the selected pixels with depth on either side where both agree within
/// `tolerance` (relative).
fn agreement(za: &[f64], zb: &[f64], selected: &[bool], tolerance: f64) -> f64 {
    let (mut either, mut agree) = (0usize, 0usize);
    for ((a, b), _) in za.iter().zip(zb).zip(selected).filter(|(_, s)| **s) {
        if a.is_nan() && b.is_nan() {
            continue;
        }
        either += 1;
        if (a - b).abs() <= tolerance * a.abs() {
            agree += 1;
        }
    }
    agree as f64 / either.max(1) as f64
}

/// A plane as the CLI takes it.
fn plane(v: f64) -> String {
    if v.is_infinite() {
        "inf".into()
    } else {
        format!("{v}")
    }
}

/// Name a reading of B's depth that fits much better than the declared one.
pub(super) fn diagnose(a: &Side, b: &Side, za: Option<&[f64]>, selected: &[bool], tolerance: f64) -> Option<String> {
    let (za, db) = (za?, b.depth.as_ref()?);
    let declared_agreement = agreement(za, &view_z(db, b.storage, &b.conv, b.ndc_z), selected, tolerance);
    if declared_agreement >= 1.0 - NAMED_GAIN {
        return None;
    }
    let score = |zb: Vec<f64>| agreement(za, &zb, selected, tolerance);
    let named = |what: Message, share: f64| {
        (share >= NAMED_AGREEMENT && share >= declared_agreement + NAMED_GAIN).then(|| {
            format!(
                "B's depth fits {what}: {:.1} % of the pixels agree with A within {}, {:.1} % as declared",
                share * 100.0,
                super::thresholds::relative(tolerance),
                declared_agreement * 100.0
            )
        })
    };
    let best = exact_readings(a, b)
        .into_iter()
        .map(|(what, r)| {
            (
                what,
                score(view_z(db, r.storage, &b.conv_with(r.reversed_z, r.ndc), r.ndc_z)),
            )
        })
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

/// One way to read B's depth file.
struct Reading {
    storage: DepthEncoding,
    reversed_z: bool,
    ndc: NdcDepthRange,
    ndc_z: bool,
}

impl Side {
    fn conv_with(&self, reversed_z: bool, ndc_depth: NdcDepthRange) -> crate::convention::Conventions {
        crate::convention::Conventions {
            reversed_z,
            ndc_depth,
            ..self.conv
        }
    }
}

/// The wrong readings with a known conversion: (what, with the options that declare it).
fn exact_readings(a: &Side, b: &Side) -> Vec<(Message, Reading)> {
    let mut out = Vec::new();
    let same = |storage| Reading {
        storage,
        reversed_z: b.conv.reversed_z,
        ndc: b.conv.ndc_depth,
        ndc_z: b.ndc_z,
    };
    match b.storage {
        DepthEncoding::Device { planes } => {
            let reversed_z = !b.conv.reversed_z;
            out.push((
                msg![
                    format!(
                        "reversed-Z {reversed_z} (declared {}; {} ",
                        b.conv.reversed_z,
                        if reversed_z { "add" } else { "drop" }
                    ),
                    Field::BReversedZ,
                    ")"
                ],
                Reading {
                    reversed_z,
                    ..same(b.storage)
                },
            ));
            if b.ndc_z {
                out.push((
                    msg![
                        "window depth, not NDC z (",
                        Field::BDepthKind,
                        " device, without ",
                        Field::BNdc,
                        ")"
                    ],
                    Reading {
                        ndc_z: false,
                        ..same(b.storage)
                    },
                ));
            } else {
                // GL NDC z in [-1, 1] stored where window depth is declared. (Window depth is
                // the same function of Z under either NDC range: only stored NDC z tells them
                // apart.)
                out.push((
                    msg![
                        "GL NDC z in [-1, 1] stored instead of window depth (",
                        Field::BDepthKind,
                        " ndc ",
                        Field::BNdc,
                        " gl)"
                    ],
                    Reading {
                        ndc_z: true,
                        ndc: NdcDepthRange::MinusOneToOne,
                        ..same(b.storage)
                    },
                ));
            }
            if planes.far.is_finite() {
                out.push((
                    msg![
                        "an infinite far plane (",
                        Field::BFar,
                        format!(" inf; declared {})", planes.far)
                    ],
                    same(DepthEncoding::Device {
                        planes: DepthPlanes {
                            far: f64::INFINITY,
                            ..planes
                        },
                    }),
                ));
            }
            if let DepthEncoding::Device { planes: pa } = a.storage {
                if pa != planes {
                    out.push((
                        msg![
                            "A's planes (",
                            Field::BNear,
                            format!(" {} ", plane(pa.near)),
                            Field::BFar,
                            format!(
                                " {}; declared {} / {})",
                                plane(pa.far),
                                plane(planes.near),
                                plane(planes.far)
                            )
                        ],
                        same(a.storage),
                    ));
                }
            }
            out.push((
                msg![
                    "view distance in metres, not device depth (",
                    Field::BDepthKind,
                    " view-z)"
                ],
                Reading {
                    ndc_z: false,
                    ..same(DepthEncoding::ViewZ)
                },
            ));
        }
        DepthEncoding::ViewZ => {
            if let DepthEncoding::Device { planes } = a.storage {
                for reversed_z in [false, true] {
                    out.push((
                        msg![
                            format!("device depth under A's planes, reversed-Z {reversed_z} ("),
                            device_planes(plane(planes.near), plane(planes.far), reversed_z),
                            ")"
                        ],
                        Reading {
                            reversed_z,
                            ..same(a.storage)
                        },
                    ));
                }
            }
        }
        _ => {}
    }
    out
}

/// B's options for device depth under `near`/`far`: `--b-depth-kind device --b-near N --b-far F`
/// and `--b-reversed-z` when `reversed_z`.
fn device_planes(near: String, far: String, reversed_z: bool) -> Message {
    let m = msg![
        Field::BDepthKind,
        " device ",
        Field::BNear,
        format!(" {near} "),
        Field::BFar,
        format!(" {far}")
    ];
    match reversed_z {
        true => msg![m, " ", Field::BReversedZ],
        false => m,
    }
}

/// Readings fitted over all pixels: B's stored value as a line in A's Z (linear depth in other
/// units) and as a line in 1 / Z (window depth under other planes, or disparity).
fn fitted_readings(za: &[f64], stored: &[f64], selected: &[bool]) -> Vec<(Message, Vec<f64>)> {
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
            msg![format!(
                "linear depth in other units: stored = {k:.4} x metres + {c:.3}"
            )],
            zb,
        ));
    }
    let inv: Vec<f64> = zs.iter().map(|z| 1.0 / z).collect();
    if let Some((c, k)) = robust_line(&inv, &vs).filter(|(_, k)| *k != 0.0) {
        let zb = stored.iter().map(|v| positive(k / (v - c))).collect();
        let in_unit_range = vs.iter().all(|v| (-1e-6..=1.0 + 1e-6).contains(v));
        let what = if in_unit_range {
            // w = c + k / Z: standard Z has k < 0, w(near) = 0 and w(far) = 1; reversed-Z has
            // k > 0, w(near) = 1 and w(far) = 0. A far plane past 1e6 near is infinite.
            let (reversed, near, far) = if k < 0.0 {
                (false, -k / c, k / (1.0 - c))
            } else {
                (true, k / (1.0 - c), -k / c)
            };
            let far = if far > 0.0 && far < 1e6 * near {
                format!("{far:.4}")
            } else {
                "inf".into()
            };
            msg![
                format!(
                    "window depth written with other planes: reversed-Z {reversed}, near ~{near:.4} m, far ~{far} ("
                ),
                device_planes(format!("{near:.4}"), far, reversed),
                ")"
            ]
        } else {
            msg![format!(
                "disparity, not depth: stored = {k:.4} / Z + {c:.3} (a line in 1 / Z)"
            )]
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
