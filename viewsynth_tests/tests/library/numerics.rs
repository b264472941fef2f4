//! Numerics over the f32/f64 range through the library's passes (issue 23): depth and focal
//! values that cannot be used are refused by name, and every view is finite where it is valid;
//! the output rule invalidates non-finite depth.

use viewsynth::io::DepthMap;
use viewsynth::stereo::gather::CyclopeanOutputs;
use viewsynth::stereo::gather::CyclopeanParams;
use viewsynth::stereo::FrameDepth;
use viewsynth_tests::assert_no_failures;

const W: u32 = 32;
const H: u32 = 24;

/// Depth values a library caller can put in a `DepthMap` by hand that every pass must refuse
/// (the loaders make them holes): subnormals, below 1e-6, above 1e6, up to f32::MAX.
const UNUSABLE: [f32; 9] = [1e-45, 1e-40, 1e-38, 1e-7, 1.5e6, 1e38, f32::MAX, -1e-40, -1e38];

/// Overwrites every third depth value with `v` (the rest keeps the scene, so the pass has
/// neighbours of ordinary depth next to the extreme one).
fn plant(depth: &mut DepthMap, v: f32) {
    depth.data.iter_mut().step_by(3).for_each(|z| *z = v);
}

/// Whether `res` is a refusal naming depth (not a panic, not a run).
fn refused_naming_depth<T>(res: viewsynth::Result<T>) -> Result<(), String> {
    match res {
        Ok(_) => Err("accepted".into()),
        Err(e) if e.to_string().contains("depth") && e.to_string().contains("usable") => Ok(()),
        Err(e) => Err(format!("refused without naming depth: {e}")),
    }
}

/// Pixels the mask marks valid whose depth is not finite (every plane the view has).
fn valid_non_finite(v: &viewsynth::view::ViewOutput) -> usize {
    match (&v.depth, &v.mask) {
        (Some(d), Some(m)) => d
            .data
            .iter()
            .zip(&m.data)
            .filter(|(z, m)| **m != 0 && !z.is_finite())
            .count(),
        _ => 0,
    }
}

#[test]
fn library_passes_refuse_unusable_depth_and_are_finite_where_valid() {
    use viewsynth::cyclopean::forward::ForwardWarp;
    use viewsynth::cyclopean::splat::SplatParams;
    use viewsynth::cyclopean::{self, CyclopeanInput, CyclopeanPass};
    use viewsynth::depth::clear_unusable_depth;
    use viewsynth::refocus::{self, BreakRule, Method, OutputSet, RefocusInput, RefocusSource};
    use viewsynth::reproject::{self, ReprojectInput};
    use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
    use viewsynth::stitch::{self, faces::scene_faces, OdsRig, Side, StitchInput, StitchParams};
    use viewsynth::view::ViewOutput;

    let g = viewsynth_tests::gpu();
    let conv = viewsynth::convention::Conventions::default();
    let mut failures = Vec::new();
    let mut cases = 0;
    let check = |tag: String, views: Vec<viewsynth::Result<ViewOutput>>, failures: &mut Vec<String>| {
        for v in views {
            match v {
                Ok(v) if valid_non_finite(&v) > 0 => {
                    failures.push(format!("{tag}: {} valid pixels not finite", valid_non_finite(&v)))
                }
                Ok(v) if !v.finite_where_valid() => failures.push(format!("{tag}: finite_where_valid false")),
                Ok(_) => {}
                Err(e) => failures.push(format!("{tag}: cleared input refused: {e}")),
            }
        }
    };

    // Refocus, both GPU methods and the twin: the source refused, then run once cleared.
    let base = viewsynth_tests::synthetic(W, H);
    for v in UNUSABLE {
        let mut depth = base.depth.clone();
        plant(&mut depth, v);
        cases += 1;
        if let Err(e) = refused_naming_depth(RefocusSource::new(base.rgb.clone(), depth.clone(), base.k)) {
            failures.push(format!("refocus source {v:e}: {e}"));
        }
        // Built field by field (the fields are public): the renderer and the twin check too.
        let raw = RefocusSource {
            rgb: base.rgb.clone(),
            depth: depth.clone(),
            k: base.k,
        };
        let target = base.camera();
        for method in [Method::Fullscreen, Method::Mesh] {
            let input = RefocusInput {
                source: &raw,
                target: &target,
                rule: BreakRule::default(),
                method,
                outputs: OutputSet::default(),
                rgb_everywhere: false,
                conv,
            };
            cases += 2;
            for (side, res) in [
                ("gpu", refocus::pass::gpu(&g, &input)),
                ("twin", refocus::pass::reference(&input)),
            ] {
                if let Err(e) = refused_naming_depth(res) {
                    failures.push(format!("refocus {method:?} {side} {v:e}: {e}"));
                }
            }
        }
        clear_unusable_depth(&mut depth.data);
        let src = RefocusSource::new(base.rgb.clone(), depth, base.k).unwrap();
        // Target focal lengths at the bounds of the intrinsics (1e-3 and 1e6 px).
        for scale in [1.0, 1e-3 / base.k.fx, 1e6 / base.k.fx] {
            let mut target = src.camera();
            target.k.fx *= scale;
            target.k.fy *= scale;
            for method in [Method::Fullscreen, Method::Mesh] {
                let input = RefocusInput {
                    source: &src,
                    target: &target,
                    rule: BreakRule::default(),
                    method,
                    outputs: OutputSet::default(),
                    rgb_everywhere: false,
                    conv,
                };
                cases += 1;
                check(
                    format!("refocus {method:?} {v:e} scale {scale:e}"),
                    vec![refocus::pass::gpu(&g, &input), refocus::pass::reference(&input)],
                    &mut failures,
                );
            }
        }
    }
    // Subnormal and out-of-range focal lengths are refused by name, source and target alike.
    for f in [5e-324, 1e-40, 1e-4, 1.1e6, 1e300] {
        cases += 2;
        let mut k = base.k;
        k.fx = f;
        match RefocusSource::new(base.rgb.clone(), base.depth.clone(), k) {
            Err(e) if e.to_string().contains("fx") => {}
            other => failures.push(format!("source fx {f:e}: {:?}", other.err())),
        }
        let mut target = base.camera();
        target.k.fy = f;
        let input = RefocusInput {
            source: &base,
            target: &target,
            rule: BreakRule::default(),
            method: Method::Fullscreen,
            outputs: OutputSet::default(),
            rgb_everywhere: false,
            conv,
        };
        match refocus::pass::gpu(&g, &input) {
            Err(e) if e.to_string().contains("fy") => {}
            other => failures.push(format!("target fy {f:e}: {:?}", other.err())),
        }
    }

    // Cyclopean: seed, refine, splat-gather (twin and GPU) and the forward warp, either eye.
    let (frame0, mid, _) = scene_frame(&StereoRig::demo(W, H), conv, FrameDepth::ViewZ);
    let passes = [
        CyclopeanPass::Gather(CyclopeanParams::seed(3.0)),
        CyclopeanPass::Gather(CyclopeanParams {
            method: viewsynth::stereo::gather::Method::Refine { steps: 4 },
            ..CyclopeanParams::seed(3.0)
        }),
        CyclopeanPass::Splat(SplatParams::default()),
    ];
    for v in UNUSABLE {
        for eye in 0..2 {
            let mut frame = frame0.clone();
            let e = if eye == 0 { &mut frame.left } else { &mut frame.right };
            plant(&mut e.depth, v);
            for pass in passes {
                let input = CyclopeanInput {
                    frame: &frame,
                    mid: &mid,
                    pass,
                    outputs: CyclopeanOutputs::default(),
                };
                cases += 2;
                for (side, res) in [
                    ("gpu", cyclopean::pass::gpu(&g, &input)),
                    ("twin", cyclopean::pass::reference(&input)),
                ] {
                    if let Err(e) = refused_naming_depth(res) {
                        failures.push(format!("cyclopean {pass:?} {side} eye {eye} {v:e}: {e}"));
                    }
                }
            }
            cases += 1;
            if let Err(e) = refused_naming_depth(ForwardWarp::new(&g, &frame, &BreakRule::default())) {
                failures.push(format!("cyclopean forward eye {eye} {v:e}: {e}"));
            }
            for e in [&mut frame.left, &mut frame.right] {
                clear_unusable_depth(&mut e.depth.data);
            }
            for pass in passes {
                let input = CyclopeanInput {
                    frame: &frame,
                    mid: &mid,
                    pass,
                    outputs: CyclopeanOutputs::default(),
                };
                cases += 1;
                check(
                    format!("cyclopean {pass:?} eye {eye} {v:e}"),
                    vec![cyclopean::pass::gpu(&g, &input), cyclopean::pass::reference(&input)],
                    &mut failures,
                );
            }
            cases += 1;
            let fwd = ForwardWarp::new(&g, &frame, &BreakRule::default()).and_then(|mut f| f.render(&mid));
            check(
                format!("cyclopean forward eye {eye} {v:e}"),
                vec![fwd.map(|(o, _)| ViewOutput::from_cyclopean(&o, mid.width, mid.height, None))],
                &mut failures,
            );
        }
    }
    // Disparity frames: tiny and huge disparities and focal lengths at the bounds become holes
    // where f B / d leaves the usable range, never refused, never valid-and-NaN.
    {
        use viewsynth::stereo::disparity_frame::{disparity_frame, DisparityRig};
        for focal in [1e-3, 1.0, 1e6] {
            let mut disp = DepthMap::new(W, H, vec![4.0; (W * H) as usize]).unwrap();
            for (i, z) in disp.data.iter_mut().enumerate() {
                *z = [1e-40, 1e-38, 1e-7, 1e38, f32::MAX, 4.0][i % 6];
            }
            let rgb = base.rgb.clone();
            let (frame, mid) = disparity_frame(
                (rgb.clone(), disp.clone()),
                (rgb, disp),
                &DisparityRig::middle(focal, 0.1),
                conv,
            )
            .unwrap();
            for pass in passes {
                let input = CyclopeanInput {
                    frame: &frame,
                    mid: &mid,
                    pass,
                    outputs: CyclopeanOutputs::default(),
                };
                cases += 1;
                check(
                    format!("disparity frame focal {focal:e} {pass:?}"),
                    vec![cyclopean::pass::gpu(&g, &input), cyclopean::pass::reference(&input)],
                    &mut failures,
                );
            }
        }
    }

    // Reproject: shift, shift-scan and gather3d, view Z and device depth sources.
    for kind in [FrameDepth::ViewZ, FrameDepth::Device] {
        let cases0 = viewsynth_lab::eval::reproject::scene_cases(W, H, 0.2, conv, kind).unwrap();
        let case = &cases0[0];
        for v in UNUSABLE {
            let mut source = case.source.clone();
            plant(&mut source.depth, v);
            for params in viewsynth_lab::eval::reproject::methods() {
                let input = ReprojectInput {
                    source: &source,
                    geometry: &case.geometry,
                    params,
                };
                cases += 2;
                for (side, res) in [
                    ("gpu", reproject::pass::gpu(&g, &input)),
                    ("twin", reproject::pass::reference(&input)),
                ] {
                    if let Err(e) = refused_naming_depth(res) {
                        failures.push(format!("reproject {kind:?} {:?} {side} {v:e}: {e}", params.method));
                    }
                }
            }
            clear_unusable_depth(&mut source.depth.data);
            for params in viewsynth_lab::eval::reproject::methods() {
                let input = ReprojectInput {
                    source: &source,
                    geometry: &case.geometry,
                    params,
                };
                cases += 1;
                check(
                    format!("reproject {kind:?} {:?} {v:e}", params.method),
                    vec![reproject::pass::gpu(&g, &input), reproject::pass::reference(&input)],
                    &mut failures,
                );
            }
        }
    }

    // Stitch (colour only): refused on any face of either eye, and runs once cleared.
    let rig = OdsRig::demo();
    let (l0, r0) = (
        scene_faces(&rig, Side::Left, 8, 100.0).unwrap(),
        scene_faces(&rig, Side::Right, 8, 100.0).unwrap(),
    );
    let params = StitchParams {
        method: stitch::Method::ALL[0],
        overlap_deg: 5.0,
        width: 32,
        height: 16,
    };
    for v in UNUSABLE {
        for face in [0, 5] {
            let mut l = l0.clone();
            plant(&mut l.faces[face].depth, v);
            let input = StitchInput {
                left: &l,
                right: &r0,
                params,
                outputs: viewsynth::output::OutputSet::RGB_DEPTH,
                conv,
            };
            cases += 2;
            for (side, res) in [
                ("gpu", stitch::pass::gpu(&g, &input)),
                ("twin", stitch::pass::reference(&input)),
            ] {
                if let Err(e) = refused_naming_depth(res) {
                    failures.push(format!("stitch face {face} {side} {v:e}: {e}"));
                }
            }
            clear_unusable_depth(&mut l.faces[face].depth.data);
            let input = StitchInput {
                left: &l,
                right: &r0,
                params,
                outputs: viewsynth::output::OutputSet::RGB_DEPTH,
                conv,
            };
            cases += 1;
            check(
                format!("stitch face {face} {v:e}"),
                vec![stitch::pass::gpu(&g, &input), stitch::pass::reference(&input)],
                &mut failures,
            );
        }
    }
    assert_no_failures(failures, cases);
}

#[test]
fn output_rule_invalidates_non_finite_depth() {
    use viewsynth::view::clear_non_finite;
    let mut depth = vec![1.0, f32::NAN, f32::INFINITY, -f32::INFINITY, 2.0, f32::NAN];
    let mut mask = vec![255, 255, 1, 0, 255, 0];
    // Two valid pixels had non-finite depth; the two already invalid are not counted.
    assert_eq!(clear_non_finite(Some(&mut depth), Some(&mut mask)), 2);
    assert_eq!(mask, vec![255, 0, 0, 0, 255, 0]);
    assert!(depth.iter().all(|z| z.is_finite()));
    assert_eq!(depth, vec![1.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    // Without depth there is nothing to test: the mask is left alone.
    let mut mask = vec![255; 3];
    assert_eq!(clear_non_finite(None, Some(&mut mask)), 0);
    assert_eq!(mask, vec![255; 3]);
}
