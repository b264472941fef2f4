//! refocus under stress: both GPU paths, two opposite conventions, against the f64 reference.
//!
//! Bounds (derived; the accuracy tests on real frames measure <= 1.14e-6):
//! - depth: 1/Z is interpolated over the triangle in f32 from three corner values with weights
//!   from f32 cell coordinates: a few ulp of q each (~4 eps) plus the weight error times the
//!   relative q spread across a kept cell (<= tau_rel = 5 %, plus the 0.2 m absolute rule at
//!   small depth): well under 16 eps = 1e-6; the bound is 32 eps = 1.9e-6, independent of the
//!   depth scale (the path works in relative terms, so 1 mm and 100 km are alike).
//! - decisions: a target pixel within f32 rounding of a triangle edge or of the half-pixel ring
//!   may fall on the other side: 0.1 % of pixels (mask IoU >= 0.999 as in the accuracy tests).
//! - colour: f32 bilinear weights move the value by < 0.01 level; > 1 level only on rounding
//!   ties that the tie window does not cover: 0.1 %.

use super::{test_texture, GpuPixels, RefPixels, StressOptions, StressRow, Tally, Tolerance, EPS32};
use viewsynth::camera::{Intrinsics, PinholeCamera};
use viewsynth::convention::Conventions;
use viewsynth::error::Result;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::pass::Device;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::reference::refocus_reference;
use viewsynth::refocus::{BreakRule, Method, OutputSet, RefocusSource, Refocuser};

const TOL: Tolerance = Tolerance::new(32.0 * EPS32, 1e-3, 1e-3);

fn source(w: u32, h: u32, depth: impl Fn(u32, u32) -> f32) -> Result<RefocusSource> {
    let k = Intrinsics {
        fx: 0.8 * w as f64,
        fy: 0.8 * w as f64,
        cx: (w as f64 - 1.0) / 2.0,
        cy: (h as f64 - 1.0) / 2.0,
    };
    let depth = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| depth(x, y))
        .collect();
    RefocusSource::new(RgbImage::new(w, h, test_texture(w, h))?, DepthMap::new(w, h, depth)?, k)
}

/// Run `src` at `scales` through both paths under two opposite conventions, pooled into a row.
fn sweep(device: &Device, case: &str, src: &RefocusSource, scales: &[f64], note: &str) -> Result<StressRow> {
    let rule = BreakRule::default();
    let targets = TargetSpec {
        scales: scales.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&src.camera())?;
    let mut tally = Tally::default();
    let references: Vec<_> = targets.iter().map(|t| refocus_reference(src, &rule, t)).collect();
    for method in [Method::Fullscreen, Method::Mesh] {
        for conv in [Conventions::default(), Conventions::all()[7]] {
            let mut r = Refocuser::new(device, src, &rule, method, OutputSet::default(), conv)?;
            for ((t, reference), s) in targets.iter().zip(&references).zip(scales) {
                let out = r.render(t)?;
                let (rgb, depth, mask) = (
                    out.rgb.as_ref().expect("rgb requested"),
                    out.depth.as_ref().expect("depth requested"),
                    out.mask.as_ref().expect("mask requested"),
                );
                tally.add(
                    &format!("s={s} {method:?} {}", conv.label()),
                    &GpuPixels {
                        valid: mask.data.iter().map(|m| *m != 0).collect(),
                        class: None,
                        depth: Some(&depth.data),
                        rgb: &rgb.data,
                    },
                    &RefPixels {
                        valid: reference.mask.clone(),
                        class: None,
                        ties: Some(ties(src, t)),
                        depth: Some(&reference.depth),
                        rgb: &reference.rgb,
                    },
                    &TOL,
                );
            }
        }
    }
    Ok(StressRow::from_tally("refocus", case, tally, TOL, note))
}

/// Target pixels whose exact source point lies on a grid line or a cell diagonal (within f64
/// rounding of the mapping): which closed triangle owns them is a tie that f32 and f64 may break
/// differently (e.g. scale 3 maps every third pixel onto exact thirds of a cell).
fn ties(src: &RefocusSource, t: &PinholeCamera) -> Vec<bool> {
    const EPS: f64 = 1e-9;
    let near = |a: f64| (a - a.round()).abs() < EPS;
    let mut out = Vec::with_capacity((t.width * t.height) as usize);
    for y in 0..t.height {
        for x in 0..t.width {
            let [u, v] = viewsynth::refocus::source_point(&src.k, &t.k, x as f64, y as f64);
            let (fu, fv) = (u - u.floor(), v - v.floor());
            out.push(near(2.0 * u) || near(2.0 * v) || (fu - fv).abs() < EPS || (fu + fv - 1.0).abs() < EPS);
        }
    }
    out
}

/// The stress rows of refocus: each case's GPU output against the f64 reference.
pub fn rows(device: &Device, opts: StressOptions) -> Result<Vec<StressRow>> {
    let (w, h) = if opts.quick { (96, 72) } else { (320, 240) };
    let mut rows = Vec::new();

    let cam = viewsynth::world::demo_camera(w, h);
    let (rgb, depth) = viewsynth::world::render(&cam);
    let demo = RefocusSource::new(rgb, depth, cam.k)?;
    rows.push(sweep(
        device,
        "focal scales 0.05 .. 20 (built-in scene)",
        &demo,
        &[0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 10.0, 20.0],
        "",
    )?);

    let src = source(w, h, |x, _| {
        if x < w / 2 {
            0.001 * (1.0 + 0.002 * x as f32)
        } else {
            1e5 * (1.0 + 0.001 * x as f32)
        }
    })?;
    rows.push(sweep(
        device,
        "depth 1 mm and 100 km in one frame",
        &src,
        &[0.05, 0.5, 1.0, 2.0, 20.0],
        "near/far 1e-8; the paths interpolate 1/Z relative to the cell, so scale does not matter",
    )?);

    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 0.0, -0.0];
    let src = source(w, h, |x, y| {
        let patch = (x / 8 + 3 * (y / 8)) as usize;
        if (x / 8 + y / 8) % 2 == 0 {
            bad[patch % bad.len()]
        } else {
            1.0 + 0.002 * x as f32
        }
    })?;
    rows.push(sweep(
        device,
        "NaN / +-Inf / negative / zero depth patches (and points behind the camera)",
        &src,
        &[0.7, 1.0, 1.9],
        "invalid depth is a hole: never drawn, never interpolated",
    )?);

    let src = source(w, h, |x, y| {
        // Inverse depth affine in the image (a plane) going from 1 m to ~1 km across the frame:
        // rays graze it towards the right edge.
        let t = (x as f64 + 0.3 * y as f64) / (w as f64 + 0.3 * h as f64);
        (1.0 / (1.0 - 0.999 * t)) as f32
    })?;
    rows.push(sweep(
        device,
        "grazing slanted plane (1 m .. 1 km)",
        &src,
        &[0.5, 1.0, 2.0],
        "the break rule cuts where neighbours differ > 5 %",
    )?);

    let src = source(w, h, |x, y| if x % 5 == 2 && y % 5 == 2 { 0.5 } else { 10.0 })?;
    rows.push(sweep(
        device,
        "single-pixel foreground objects",
        &src,
        &[0.5, 1.0, 3.0],
        "an isolated pixel has no kept triangle: a hole at its place",
    )?);

    let src = source(w, h, |_, _| 2.0)?;
    rows.push(sweep(
        device,
        "constant depth (near plane = far plane)",
        &src,
        &[0.5, 1.0, 2.0],
        "degenerate depth range of the mesh pass",
    )?);

    let src = source(1, 1, |_, _| 2.5)?;
    rows.push(sweep(device, "1x1 image", &src, &[0.5, 1.0, 2.0], "")?);

    // The context's limit, less one: the grid's border ring (refocus::max_source_side).
    let max = viewsynth::refocus::max_source_side(device);
    let src = source(max, 2, |x, _| 1.0 + 1e-4 * x as f32)?;
    rows.push(sweep(
        device,
        &format!("{max}x2 image (largest side)"),
        &src,
        &[0.5, 1.0],
        "",
    )?);

    let too_big = source(max + 1, 1, |_, _| 1.0).and_then(|src| {
        Refocuser::new(
            device,
            &src,
            &BreakRule::default(),
            Method::Fullscreen,
            OutputSet::default(),
            Conventions::default(),
        )
        .map(|_| ())
    });
    rows.push(refused("refocus", max + 1, max, too_big));

    // The output side: the context's limit itself is allowed, one past it refused.
    let limit = device.max_image_side();
    let too_big = source(4, 3, |_, _| 1.0).and_then(|src| {
        let mut target = src.camera();
        (target.width, target.height) = (limit + 1, 1);
        Refocuser::new(
            device,
            &src,
            &BreakRule::default(),
            Method::Fullscreen,
            OutputSet::default(),
            Conventions::default(),
        )?
        .render(&target)
        .map(|_| ())
    });
    rows.push(refused("refocus", limit + 1, limit, too_big));
    Ok(rows)
}

/// The rule for an image one past the context's largest side `limit`: refused with a message
/// naming the size and the limit.
pub(crate) fn refused(capability: &'static str, side: u32, limit: u32, r: Result<()>) -> StressRow {
    let case = format!("{side} px side (one past the largest, {limit})");
    match r {
        Err(e) if e.to_string().contains(&side.to_string()) && e.to_string().contains(&limit.to_string()) => {
            StressRow::rule(capability, case, true, format!("refused: {e}"))
        }
        Err(e) => StressRow::rule(
            capability,
            case,
            false,
            format!("refused without naming the size and the limit: {e}"),
        ),
        Ok(()) => StressRow::rule(capability, case, false, "accepted: should be refused (or tiled)"),
    }
}
