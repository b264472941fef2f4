//! The stereo camera model under stress (CPU): what a vertex shader computes in f32 from the
//! matrices the model uploads, against f64; parallax; vergence of near-parallel gazes.
//!
//! Bounds (derived):
//! - device depth round trip (f32 projection of a point at view distance Z, stored in a float
//!   depth buffer, read back as Z in f64): under standard Z, and under reversed-Z with the GL
//!   [-1, 1] range, the stored value approaches a constant (1, resp. ndc -1) and its absolute
//!   precision eps limits 1/Z to eps / near: relative error 8 eps (1 + Z / near). Only reversed-Z
//!   with the [0, 1] range stores ~ near / Z with relative precision: 8 eps. Points beyond what
//!   the lossy forms resolve collapse onto the far value (background): counted as decisions and
//!   allowed there by design.
//! - parallax S (1 - c / Z) in f32: c / Z and the subtraction each round: |error| <= 3 eps
//!   S (1 + c / Z); the bound is 4 eps in units of S (1 + c / Z).
//! - vergence: the closed form's own bound (camera::vergence, 1.8e-7 relative where den >= 1e-8);
//!   nearer-parallel gazes take the documented fallback (max depth), never NaN.

use super::{Stats, StressOptions, StressRow, Tolerance, EPS32};
use viewsynth::camera::stereo::{mono_projection_gl, parallax, CullingKind, Frustum, StereoCullingFrustum};
use viewsynth::camera::vergence::{resolve_fixation, DepthRange, FixationSource, GazeRay};
use viewsynth::convention::{Conventions, DepthPlanes, NdcDepthRange, RowOrder};
use viewsynth::error::Result;

fn depth_conventions() -> Vec<Conventions> {
    Conventions::all()
        .into_iter()
        .filter(|c| c.row_order == RowOrder::BottomUp)
        .collect()
}

/// Window depth of view distance `z` as the GPU computes and stores it (f32 throughout).
fn window_depth_f32(m: &[f32; 16], conv: &Conventions, z: f64) -> f32 {
    let ze = -(z as f32);
    let zc = m[10] * ze + m[14];
    let wc = m[11] * ze + m[15];
    let ndc = zc / wc;
    match conv.ndc_depth {
        NdcDepthRange::MinusOneToOne => 0.5 * ndc + 0.5,
        NdcDepthRange::ZeroToOne => ndc,
    }
}

fn depth_round_trip(planes: DepthPlanes, conv: Conventions, samples: usize) -> Result<StressRow> {
    let frustum = Frustum::from_fov_y(60f64.to_radians(), 1.5)?;
    let m = mono_projection_gl(&frustum, &planes, &conv)?.map(|v| v as f32);
    let far_eff = if planes.far.is_finite() { planes.far } else { 1e7 };
    let clear = conv.clear_depth() as f32;
    let (mut errs, mut collapsed, mut non_finite) = (Vec::new(), 0usize, 0usize);
    let (mut worst, mut worst_z) = (0f64, 0f64);
    for i in 0..samples {
        let z = planes.near * (far_eff / planes.near).powf(i as f64 / (samples - 1) as f64);
        let d = window_depth_f32(&m, &conv, z);
        if !d.is_finite() {
            non_finite += 1;
            continue;
        }
        if d == clear && z < planes.far {
            collapsed += 1;
            continue;
        }
        let ndc = match conv.ndc_depth {
            NdcDepthRange::MinusOneToOne => 2.0 * d as f64 - 1.0,
            NdcDepthRange::ZeroToOne => d as f64,
        };
        let back = planes.view_z_of_ndc_z(&conv, ndc);
        let rel = (back - z).abs() / z;
        if !rel.is_finite() {
            non_finite += 1;
            continue;
        }
        if rel > worst {
            (worst, worst_z) = (rel, z);
        }
        errs.push(rel);
    }
    let lossy = !conv.float_depth_keeps_relative_precision();
    let bound = if lossy {
        8.0 * EPS32 * (1.0 + far_eff / planes.near)
    } else {
        8.0 * EPS32
    };
    let by_design = lossy && bound > 1e-3;
    let tol = if by_design {
        Tolerance::lost_by_design(bound)
    } else {
        Tolerance::new(bound, 0.0, 0.0)
    };
    let stats = Stats::of(errs);
    let pass = non_finite == 0 && (by_design || (collapsed == 0 && stats.is_none_or(|s| s.max <= bound)));
    let note = if by_design {
        format!(
            "precision lost by design: {collapsed} of {samples} distances collapse onto the far value; \
             relative error reaches {:.0e} at {worst_z:.3e} m; use reversed-Z with [0,1]",
            worst
        )
    } else {
        String::new()
    };
    Ok(StressRow {
        capability: "camera",
        case: format!(
            "device depth round trip, near {:e} far {:e} ({})",
            planes.near,
            planes.far,
            conv.label().trim_end_matches("-bu")
        ),
        pixels: samples,
        decisions: collapsed,
        ties: 0,
        colour_off: 0,
        depth_rel: stats,
        non_finite,
        tolerance: tol,
        worst: format!("Z = {worst_z:.3e} m"),
        pass,
        note,
    })
}

/// Points on the near plane store exactly the near value; nearer ones fall outside the depth
/// range and points on or behind the eye plane get clip w <= 0: the GPU clips both before any
/// division, so nothing non-finite reaches a depth buffer. The screen-window culling frustum
/// rejects points behind its apex.
fn near_plane_row() -> Result<StressRow> {
    let frustum = Frustum::from_fov_y(60f64.to_radians(), 1.5)?;
    let planes = DepthPlanes { near: 0.05, far: 100.0 };
    let mut broken = Vec::new();
    for conv in depth_conventions() {
        let m = mono_projection_gl(&frustum, &planes, &conv)?.map(|v| v as f32);
        let tag = conv.label();
        let near_value = conv.ndc_z_near_far().0;
        let near_window = match conv.ndc_depth {
            NdcDepthRange::MinusOneToOne => 0.5 * near_value + 0.5,
            NdcDepthRange::ZeroToOne => near_value,
        };
        let d = window_depth_f32(&m, &conv, planes.near) as f64;
        if (d - near_window).abs() > 2.0 * EPS32 {
            broken.push(format!("{tag}: Z = near stores {d}, not {near_window}"));
        }
        let d = window_depth_f32(&m, &conv, 0.999 * planes.near) as f64;
        if (0.0..=1.0).contains(&d) {
            broken.push(format!("{tag}: Z = 0.999 near stores {d}, inside the depth range"));
        }
        for z in [0.0f32, -1.0, -1e6] {
            let w = m[11] * -z + m[15];
            if w > 0.0 {
                broken.push(format!("{tag}: Z = {z} has clip w = {w} > 0"));
            }
        }
    }
    let params = viewsynth::camera::stereo::StereoParams::new(0.03, 2.0)?;
    let cull = StereoCullingFrustum::new(&frustum, &params, CullingKind::ScreenWindow);
    if [[0.0, 0.0, -1.0], [0.0, 0.0, -1e6], [0.0, 0.0, 0.0]]
        .iter()
        .any(|p| cull.contains(*p))
    {
        broken.push("the screen-window culling frustum holds a point behind the eye".into());
    }
    Ok(StressRow::rule(
        "camera",
        "near plane and behind the camera (4 depth conventions, culling)",
        broken.is_empty(),
        if broken.is_empty() {
            "Z = near stores the near value (2 eps); nearer falls outside [0,1]; Z <= 0 gets w <= 0 (clipped); culled"
                .to_string()
        } else {
            broken.join("; ")
        },
    ))
}

fn parallax_row() -> StressRow {
    let mut errs = Vec::new();
    let (mut non_finite, mut worst, mut worst_case) = (0usize, 0f64, String::new());
    let depths: Vec<f64> = (0..=80).map(|i| 1e-3 * 10f64.powf(i as f64 / 10.0)).collect();
    for s in [0.0, 1e-6, 0.03, 0.1] {
        for c in [1e-12, 1e-9, 1e-3, 1.0, 10.0, 1e3] {
            for &z in depths.iter().chain([f64::INFINITY].iter()) {
                let Ok(p64) = parallax(s, c, z) else {
                    non_finite += 1;
                    continue;
                };
                let (s32, c32, z32) = (s as f32, c as f32, z as f32);
                let p32 = s32 * (1.0 - c32 / z32);
                if !p32.is_finite() {
                    non_finite += 1;
                    continue;
                }
                let scale = s * (1.0 + c / z);
                let e = if scale == 0.0 {
                    (p32 as f64 - p64).abs()
                } else {
                    (p32 as f64 - p64).abs() / scale
                };
                if e > worst {
                    (worst, worst_case) = (e, format!("S={s} c={c} Z={z:.3e}"));
                }
                errs.push(e);
            }
        }
    }
    let n = errs.len() + non_finite;
    let tol = Tolerance::new(4.0 * EPS32, 0.0, 0.0);
    let stats = Stats::of(errs);
    // Behind the camera / on the eye: no image position exists, so the model refuses.
    let refused = [0.0, -1.0, f64::NAN].iter().all(|&z| parallax(0.03, 1.0, z).is_err());
    StressRow {
        capability: "camera",
        case: "parallax S (1 - c/Z): S 0..0.1 (zero IPD), c 1e-12..1e3, Z 1 mm..100 km and inf".into(),
        pixels: n,
        decisions: 0,
        ties: 0,
        colour_off: 0,
        depth_rel: stats,
        non_finite,
        tolerance: tol,
        worst: worst_case,
        pass: non_finite == 0 && stats.is_none_or(|s| s.max <= tol.depth_rel) && refused,
        note: format!(
            "error in units of S (1 + c/Z); S = 0 gives exactly 0; Z <= 0 or NaN {}",
            if refused {
                "is refused with an error"
            } else {
                "was NOT refused"
            }
        ),
    }
}

fn vergence_row() -> Result<StressRow> {
    let range = DepthRange::new(0.05, 1e4)?;
    let ipd: f64 = 0.064;
    let (mut errs, mut fallbacks, mut non_finite, mut worst, mut wrong_rule) =
        (Vec::new(), Vec::new(), 0usize, (0f64, String::new()), 0usize);
    let mut n = 0;
    // Symmetric gazes fixating at distance D straight ahead, from 5 cm to beyond the range, then
    // exactly parallel, diverging by 1e-9 rad, and both eyes at one point (zero IPD).
    let mut cases: Vec<(String, f64, f64)> = [0.05, 0.3, 1.0, 10.0, 100.0, 650.0, 5e3, 1e5, 1e8]
        .iter()
        .map(|&d| (format!("D={d:e}"), ipd, (0.5 * ipd).atan2(d)))
        .collect();
    cases.push(("parallel".into(), ipd, 0.0));
    cases.push(("diverging 1e-9 rad".into(), ipd, -1e-9));
    cases.push(("zero IPD".into(), 0.0, 0.01));
    for (tag, b, half_angle) in cases {
        n += 1;
        let left = GazeRay {
            origin: [-0.5 * b, 0.0, 0.0],
            direction: [half_angle.sin(), 0.0, -half_angle.cos()],
        };
        let right = GazeRay {
            origin: [0.5 * b, 0.0, 0.0],
            direction: [-half_angle.sin(), 0.0, -half_angle.cos()],
        };
        let f = resolve_fixation(&left, &right, &range, None, None)?;
        if !(f.depth.is_finite() && f.point.iter().all(|v| v.is_finite())) {
            non_finite += 1;
            continue;
        }
        match f.source {
            FixationSource::Vergence => {
                let truth = 0.5 * b / half_angle.tan();
                let e = (f.depth - truth).abs() / truth;
                if e > worst.0 {
                    worst = (e, tag.clone());
                }
                errs.push(e);
            }
            FixationSource::MaxDepth(reason) => {
                if f.depth != range.max() {
                    wrong_rule += 1;
                }
                fallbacks.push(format!("{tag}: {reason:?}"));
            }
            other => {
                wrong_rule += 1;
                fallbacks.push(format!("{tag}: unexpected {other:?}"));
            }
        }
    }
    let tol = Tolerance::new(1.8e-7, 0.0, 0.0);
    let stats = Stats::of(errs);
    Ok(StressRow {
        capability: "camera",
        case: "vergence fixation: D 5 cm..1e8 m, parallel, diverging, zero IPD".into(),
        pixels: n,
        decisions: wrong_rule,
        ties: 0,
        colour_off: 0,
        depth_rel: stats,
        non_finite,
        tolerance: tol,
        worst: worst.1,
        pass: non_finite == 0 && wrong_rule == 0 && stats.is_none_or(|s| s.max <= tol.depth_rel),
        note: format!("fallback to max depth: {}", fallbacks.join("; ")),
    })
}

/// The stress rows of the camera model (stereo projections, vergence) against its f64 closed forms.
pub fn rows(opts: StressOptions) -> Result<Vec<StressRow>> {
    let samples = if opts.quick { 2000 } else { 20000 };
    let mut rows = Vec::new();
    for planes in [
        DepthPlanes { near: 0.05, far: 100.0 },
        DepthPlanes { near: 1e-3, far: 1e4 },
        DepthPlanes {
            near: 1e-3,
            far: f64::INFINITY,
        },
    ] {
        for conv in depth_conventions() {
            rows.push(depth_round_trip(planes, conv, samples)?);
        }
    }
    rows.push(near_plane_row()?);
    rows.push(parallax_row());
    rows.push(vergence_row()?);
    Ok(rows)
}
