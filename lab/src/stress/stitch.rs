//! stitch under stress: the three methods on the GPU against the f64 stitch.
//!
//! Bound (derived in viewsynth_tests/tests/library/stitch.rs): sample positions agree to ~1e-5 face px, so
//! bilinear colour moves by < 0.01 level except where f32 and f64 take a discrete choice apart
//! (nearest depth texel on a half-pixel tie, the band edge, the on-ray test, the agreement
//! test): at most 0.5 % of pixels may be off by more than one level. The output is colour only.

use super::{GpuPixels, RefPixels, StressOptions, StressRow, Tally, Tolerance};
use viewsynth::convention::Conventions;
use viewsynth::error::Result;
use viewsynth::pass::Device;
use viewsynth::stitch::faces::scene_faces;
use viewsynth::stitch::reference::stitch_reference;
use viewsynth::stitch::render::StitchRenderer;
use viewsynth::stitch::{FaceSet, Method, OdsRig, Side, StitchParams};

const TOL: Tolerance = Tolerance::new(1.0, 0.0, 5e-3);

struct Case {
    tag: String,
    left: FaceSet,
    right: FaceSet,
    overlap_deg: f64,
    width: u32,
    height: u32,
}

fn faces(rig: &OdsRig, n: u32, overlap_deg: f64) -> Result<(FaceSet, FaceSet)> {
    let fov = 90.0 + 2.0 * overlap_deg;
    Ok((
        scene_faces(rig, Side::Left, n, fov)?,
        scene_faces(rig, Side::Right, n, fov)?,
    ))
}

fn sweep(device: &Device, case: &str, cases: &[Case], note: &str) -> Result<StressRow> {
    let mut tally = Tally::default();
    for c in cases {
        for conv in [Conventions::default(), Conventions::all()[7]] {
            let mut renderer = StitchRenderer::with_conventions(device, &c.left, &c.right, conv)?;
            for method in Method::ALL {
                let params = StitchParams {
                    method,
                    overlap_deg: c.overlap_deg,
                    width: c.width,
                    height: c.height,
                };
                let (tb, _) = renderer.render(&params)?;
                let half = (c.width * c.height * 3) as usize;
                for (eye, set, data) in [("L", &c.left, &tb.data[..half]), ("R", &c.right, &tb.data[half..])] {
                    let reference = stitch_reference(set, &params)?;
                    let n = reference.len();
                    tally.add(
                        &format!("{} {} {} {eye}", c.tag, conv.label(), method.label()),
                        &GpuPixels {
                            valid: vec![true; n],
                            class: None,
                            depth: None,
                            rgb: data,
                        },
                        &RefPixels {
                            valid: vec![true; n],
                            class: None,
                            ties: None,
                            depth: None,
                            rgb: &reference,
                        },
                        &TOL,
                    );
                }
            }
        }
    }
    Ok(StressRow::from_tally("stitch", case, tally, TOL, note))
}

/// The stress rows of stitch: each case's GPU output against the f64 reference.
pub fn rows(device: &Device, opts: StressOptions) -> Result<Vec<StressRow>> {
    let (n, w, h) = if opts.quick { (48, 128, 64) } else { (128, 512, 256) };
    let rig = OdsRig::demo();
    let mut rows = Vec::new();
    let case = |tag: &str, rig: &OdsRig, overlap: f64, w: u32, h: u32| -> Result<Case> {
        let (left, right) = faces(rig, n, overlap)?;
        Ok(Case {
            tag: tag.to_string(),
            left,
            right,
            overlap_deg: overlap,
            width: w,
            height: h,
        })
    };

    rows.push(sweep(
        device,
        "overlap 0.25 and 40 deg (FOV 90.5 and 170)",
        &[case("0.25deg", &rig, 0.25, w, h)?, case("40deg", &rig, 40.0, w, h)?],
        "",
    )?);

    let zero = OdsRig { ipd: 0.0, ..rig };
    rows.push(sweep(
        device,
        "zero IPD",
        &[case("ipd0", &zero, 10.0, w, h)?],
        "all face eyes at the centre: the seed's dd = 0",
    )?);

    let mut c = case("patches", &rig, 10.0, w, h)?;
    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 0.0];
    for set in [&mut c.left, &mut c.right] {
        for face in &mut set.faces {
            let fw = face.depth.width as usize;
            for (i, z) in face.depth.data.iter_mut().enumerate() {
                let (x, y) = (i % fw, i / fw);
                if (x / 4 + y / 4) % 3 == 0 {
                    *z = bad[(x / 4 + 5 * (y / 4)) % bad.len()];
                }
            }
        }
    }
    rows.push(sweep(
        device,
        "NaN / +-Inf / negative / zero face depth patches",
        &[c],
        "invalid depth is background (the seed's far guess)",
    )?);

    rows.push(sweep(
        device,
        "equirect 1x1 and 3x2, faces 2x2",
        &[case("1x1", &rig, 10.0, 1, 1)?, case("3x2", &rig, 10.0, 3, 2)?, {
            let (left, right) = (
                scene_faces(&rig, Side::Left, 2, 110.0)?,
                scene_faces(&rig, Side::Right, 2, 110.0)?,
            );
            Case {
                tag: "faces2".into(),
                left,
                right,
                overlap_deg: 10.0,
                width: 16,
                height: 8,
            }
        }],
        "",
    )?);

    let max = device.max_image_side();
    let c = case("big", &rig, 10.0, 2, 2)?;
    let r = StitchRenderer::new(device, &c.left, &c.right).and_then(|mut r| {
        r.render(&StitchParams {
            method: Method::Blend,
            overlap_deg: 10.0,
            width: max + 1,
            height: 1,
        })
        .map(|_| ())
    });
    rows.push(super::refocus::refused("stitch", max + 1, max, r));
    Ok(rows)
}
