//! reproject under stress: shift walk, shift scan and 3-D gather against the f64 reference.
//!
//! Bounds (derived as in viewsynth_tests/tests/library/reproject.rs):
//! - depth: q = 1/Z interpolated along a segment at t = (u - f0) / (f1 - f0); the f32 error of
//!   u - f0 (~6e-5 px over a >= 0.5 px segment) moves q by <= tau_rel q 1.2e-4 = 6e-6 q, plus a
//!   few eps: 1e-5 for view Z and disparity. Device depth adds the cancellation of
//!   q = alpha d + beta: 8 eps Z_max / near except under reversed-Z with the [0, 1] range (as
//!   cyclopean); at near/far 1e-7 under standard Z that is lost by design.
//! - decisions (mask, or another surface won): 0.1 % of pixels; colour > 1 level: 0.1 %.
//!
//! Constants are generic (IPD 0.2011 m, doffs 3.4771, ...): round ones map source columns
//! exactly onto target pixel centres or texel borders, where f32 and f64 break ties apart.
//! Ties that remain by nature (a 100 km surface moving by less than an f32 ulp) are counted
//! apart (`shift_ties`).

use super::refocus::refused;
use super::{test_texture, GpuPixels, RefPixels, StressOptions, StressRow, Tally, Tolerance, EPS32};
use crate::eval::reproject::methods;
use viewsynth::camera::stereo::{Eye, StereoParams};
use viewsynth::camera::{Intrinsics, PinholeCamera};
use viewsynth::convention::{Conventions, DepthPlanes};
use viewsynth::depth::DepthEncoding;
use viewsynth::error::Result;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::pass::Device;
use viewsynth::reproject::reference::reproject_reference;
use viewsynth::reproject::render::Reprojector;
use viewsynth::reproject::{Geometry, ReprojectSource, ShiftModel};
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;

const VIEW_Z_BOUND: f64 = 1e-5;

/// The view-Z bound for images `w` wide: the f32 error of u - f0 grows with |u| (~w eps), so the
/// t error over a >= 0.5 px segment is ~4 w eps and q moves by tau_rel times that (x 2 margin).
fn view_z_bound(w: u32) -> f64 {
    VIEW_Z_BOUND.max(2.0 * 0.05 * 4.0 * w as f64 * EPS32)
}

struct Case {
    tag: String,
    source: ReprojectSource,
    geometry: Geometry,
}

fn sweep(device: &Device, case: &str, cases: &[Case], tol: Tolerance, note: &str) -> Result<StressRow> {
    let mut tally = Tally::default();
    for c in cases {
        for params in methods() {
            let reference = reproject_reference(&c.source, &c.geometry, &params)?;
            let (out, _) = Reprojector::new(device, &c.source, &c.geometry, params)?.render()?;
            tally.add(
                &format!("{} {}", c.tag, params.method.label()),
                &GpuPixels {
                    valid: out.mask.iter().map(|m| *m != 0).collect(),
                    class: None,
                    depth: out.depth.as_ref().map(|d| d.data.as_slice()),
                    rgb: &out.color.as_ref().expect("colour requested").data,
                },
                &RefPixels {
                    valid: reference.mask.clone(),
                    class: None,
                    ties: shift_ties(&c.source, &c.geometry),
                    depth: Some(&reference.depth),
                    rgb: &reference.color,
                },
                &tol,
            );
        }
    }
    Ok(StressRow::from_tally("reproject", case, tally, tol, note))
}

/// Target pixels that a forward-mapped source column hits within f32 rounding (8 eps |u|):
/// whether a segment ending there covers the pixel is a tie (e.g. a 100 km surface moves by less
/// than an f32 ulp of its column).
fn shift_ties(src: &ReprojectSource, geometry: &Geometry) -> Option<Vec<bool>> {
    let Geometry::Rig { shift, .. } = geometry else {
        return None;
    };
    let (w, h) = (src.depth.width as usize, src.depth.height as usize);
    let q = src.inverse_depths();
    let mut ties = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let Some(q) = q[y * w + x] else { continue };
            let u = shift.forward(x as f64, q);
            let r = u.round();
            if (u - r).abs() <= 8.0 * EPS32 * u.abs().max(1.0) && r >= 0.0 && r < w as f64 {
                ties[y * w + r as usize] = true;
            }
        }
    }
    Some(ties)
}

/// Left -> right on the built-in scene with the given planes (device depth) or view Z.
fn scene_case(w: u32, h: u32, ipd: f64, planes: DepthPlanes, conv: Conventions, kind: FrameDepth) -> Result<Case> {
    let mut rig = StereoRig::demo(w, h);
    rig.ipd = ipd;
    rig.planes = planes;
    let (frame, _, _) = scene_frame(&rig, conv, kind);
    Ok(Case {
        tag: format!("{} {kind:?}", conv.label()),
        source: ReprojectSource {
            color: frame.left.color,
            depth: frame.left.depth,
            depth_kind: DepthEncoding::with_planes(kind.into(), planes)?,
            conv,
        },
        geometry: Geometry::Rig {
            camera: rig.camera,
            shift: ShiftModel::rectified(rig.camera.k.fx, ipd, 0.0, Some(Eye::Left), Some(Eye::Right))?,
        },
    })
}

/// A synthetic source: test texture, depth from `depth`, stored as `kind`.
fn synthetic(
    w: u32,
    h: u32,
    kind: DepthEncoding,
    conv: Conventions,
    depth: impl Fn(u32, u32) -> f32,
) -> Result<ReprojectSource> {
    let data = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| depth(x, y))
        .collect();
    Ok(ReprojectSource {
        color: RgbImage::new(w, h, test_texture(w, h))?,
        depth: DepthMap::new(w, h, data)?,
        depth_kind: kind,
        conv,
    })
}

fn rig_camera(w: u32, h: u32) -> PinholeCamera {
    PinholeCamera {
        k: Intrinsics {
            fx: 0.8 * w as f64,
            fy: 0.8 * w as f64,
            cx: (w as f64 - 1.0) / 2.0,
            cy: (h as f64 - 1.0) / 2.0,
        },
        width: w,
        height: h,
    }
}

fn seed_shift(w: u32, separation: f64, convergence: f64) -> Result<ShiftModel> {
    Ok(ShiftModel::seed(
        &StereoParams::new(separation, convergence)?,
        w,
        Some(Eye::Left),
        Some(Eye::Right),
    ))
}

/// The stress rows of reproject: each case's GPU output against the f64 reference.
pub fn rows(device: &Device, opts: StressOptions) -> Result<Vec<StressRow>> {
    let (w, h) = if opts.quick { (96, 72) } else { (256, 192) };
    let all = Conventions::all();
    let two = [Conventions::default(), all[7]];
    let mut rows = Vec::new();
    let view_z = Tolerance::new(VIEW_Z_BOUND, 1e-3, 1e-3);

    for near in [0.05, 1e-5] {
        let planes = DepthPlanes { near, far: 100.0 };
        for precise in [false, true] {
            let convs: Vec<Conventions> = all
                .iter()
                .copied()
                .filter(|c| c.float_depth_keeps_relative_precision() == precise)
                .collect();
            let z_max = 8.0;
            let b = if precise {
                VIEW_Z_BOUND + 16.0 * EPS32
            } else {
                VIEW_Z_BOUND + 8.0 * EPS32 * (1.0 + z_max / near)
            };
            let by_design = !precise && b > 1e-4;
            let tol = if by_design {
                Tolerance::lost_by_design(b)
            } else {
                Tolerance::new(b, 1e-3, 1e-3)
            };
            let cases = convs
                .iter()
                .map(|&c| scene_case(w, h, 0.2011, planes, c, FrameDepth::Device))
                .collect::<Result<Vec<_>>>()?;
            let note = if by_design {
                format!(
                    "precision lost by design: f32 device depth holds Z to ~eps Z / near = {:.1} % at {z_max} m",
                    100.0 * EPS32 * z_max / near
                )
            } else {
                String::new()
            };
            rows.push(sweep(
                device,
                &format!(
                    "device depth, near/far {:.0e}, {}",
                    near / 100.0,
                    if precise {
                        "reversed-Z [0,1]"
                    } else {
                        "standard Z or GL range"
                    }
                ),
                &cases,
                tol,
                &note,
            )?);
        }
    }

    let plane = |conv| synthetic(w, h, DepthEncoding::ViewZ, conv, |x, _| 2.0 + 0.01 * x as f32);
    let mut cases = Vec::new();
    for conv in two {
        for (label, shift) in [
            ("S=0", seed_shift(w, 0.0, 1.0)?),
            (
                "B=0",
                ShiftModel::rectified(100.0, 0.0, 0.0, Some(Eye::Left), Some(Eye::Right))?,
            ),
        ] {
            cases.push(Case {
                tag: format!("{} {label}", conv.label()),
                source: plane(conv)?,
                geometry: Geometry::Rig {
                    camera: rig_camera(w, h),
                    shift,
                },
            });
        }
    }
    rows.push(sweep(
        device,
        "zero separation / zero IPD",
        &cases,
        view_z,
        "the identity",
    )?);

    let mut cases = Vec::new();
    for conv in two {
        for c in [1e-9, 1e6] {
            cases.push(Case {
                tag: format!("{} c={c:e}", conv.label()),
                source: plane(conv)?,
                geometry: Geometry::Rig {
                    camera: rig_camera(w, h),
                    shift: seed_shift(w, 0.05, c)?,
                },
            });
        }
    }
    rows.push(sweep(
        device,
        "convergence 1e-9 m and 1000 km",
        &cases,
        view_z,
        "x moves by S (1 - c / Z): a constant shift at c -> 0, huge parallax at c >> Z",
    )?);

    let mut cases = Vec::new();
    for conv in two {
        cases.push(Case {
            tag: conv.label(),
            source: synthetic(w, h, DepthEncoding::ViewZ, conv, |x, _| {
                if x < w / 2 {
                    0.001 * (1.0 + 0.01 * x as f32)
                } else {
                    1e5 * (1.0 + 0.001 * x as f32)
                }
            })?,
            geometry: Geometry::Rig {
                camera: rig_camera(w, h),
                shift: ShiftModel::rectified(0.8 * w as f64, 1e-5, 0.0, Some(Eye::Left), Some(Eye::Right))?,
            },
        });
    }
    rows.push(sweep(
        device,
        "depth 1 mm and 100 km in one frame",
        &cases,
        view_z,
        "baseline 10 um: the 1 mm half moves ~0.8 px, the 100 km half ~1e-8 px (below an f32 ulp: a tie)",
    )?);

    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -3.0, 0.0];
    let mut cases = Vec::new();
    for conv in two {
        cases.push(Case {
            tag: conv.label(),
            source: synthetic(w, h, DepthEncoding::ViewZ, conv, |x, y| {
                if (x / 5 + y / 5) % 3 == 0 {
                    bad[((x / 5 + 7 * (y / 5)) as usize) % bad.len()]
                } else {
                    2.0 + 0.01 * x as f32
                }
            })?,
            geometry: Geometry::Rig {
                camera: rig_camera(w, h),
                shift: ShiftModel::rectified(0.8 * w as f64, 0.1, 0.0, Some(Eye::Left), Some(Eye::Right))?,
            },
        });
        // Middlebury-style disparity with 0 (unknown), negative, NaN and +inf (invalid) values.
        // Generic (not round) constants: round ones put forward-mapped columns exactly on pixel
        // centres (d = 5 + 0.05 x maps x = 20 onto 14), where f32 and f64 break ties apart.
        let kind = DepthEncoding::Disparity {
            focal_px: 0.8 * w as f64,
            baseline: 0.1037,
            doffs: 3.4771,
        };
        cases.push(Case {
            tag: format!("{} disparity", conv.label()),
            source: synthetic(w, h, kind, conv, |x, y| match (x + 2 * y) % 7 {
                0 => 0.0,
                1 => -2.0,
                2 => f32::NAN,
                3 => f32::INFINITY,
                _ => 5.0 + 0.0513 * x as f32,
            })?,
            geometry: Geometry::Rig {
                camera: rig_camera(w, h),
                shift: ShiftModel::rectified(0.8 * w as f64, 0.1037, 3.4771, Some(Eye::Left), Some(Eye::Right))?,
            },
        });
    }
    rows.push(sweep(
        device,
        "NaN / +-Inf / negative / zero depth and disparity (points behind the camera)",
        &cases,
        view_z,
        "invalid source depth is never drawn: a hole in the mask",
    )?);

    let max = device.max_image_side();
    let mut cases = Vec::new();
    for (sw, sh) in [(2, 1), (max, 2)] {
        cases.push(Case {
            tag: format!("{sw}x{sh}"),
            source: synthetic(sw, sh, DepthEncoding::ViewZ, all[7], |x, _| 1.0 + 1e-4 * x as f32)?,
            geometry: Geometry::Rig {
                camera: rig_camera(sw, sh),
                shift: ShiftModel::rectified(0.8 * sw as f64, 0.01, 0.0, Some(Eye::Left), Some(Eye::Right))?,
            },
        });
    }
    rows.push(sweep(
        device,
        &format!("2x1 and {max}x2 images"),
        &cases,
        Tolerance::new(view_z_bound(max), 1e-3, 1e-3),
        "a row needs 2 columns: 1-wide sources are refused",
    )?);
    let r = synthetic(max + 1, 1, DepthEncoding::ViewZ, all[7], |_, _| 1.0).and_then(|src| {
        let geometry = Geometry::Rig {
            camera: rig_camera(max + 1, 1),
            shift: ShiftModel::rectified(1.0, 0.01, 0.0, Some(Eye::Left), Some(Eye::Right))?,
        };
        Reprojector::new(device, &src, &geometry, methods()[0]).map(|_| ())
    });
    rows.push(refused("reproject", max + 1, max, r));
    Ok(rows)
}
