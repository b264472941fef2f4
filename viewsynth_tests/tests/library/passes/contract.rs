//! The pass/twin contract (`<capability>::pass::{gpu, reference}`): each side's view is exactly
//! what its renderer or twin returns when called directly (same bytes, no numerics of its own),
//! the GPU view carries its timing and the twin view its unrounded values, and both sides leave
//! out the same planes when an output is not asked for.

use viewsynth::convention::Conventions;
use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
use viewsynth::cyclopean::splat_reference::splat_reference;
use viewsynth::cyclopean::{self, CyclopeanInput, CyclopeanPass};
use viewsynth::refocus::reference::refocus_reference;
use viewsynth::refocus::{self, BreakRule, Method, OutputSet, RefocusInput, Refocuser};
use viewsynth::reproject::reference::reproject_reference;
use viewsynth::reproject::render::Reprojector;
use viewsynth::reproject::{self, ReprojectInput, ReprojectOutputs, ReprojectParams};
use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
use viewsynth::stereo::gather::reference::cyclopean_reference;
use viewsynth::stereo::gather::{CyclopeanOutputs, CyclopeanParams};
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;
use viewsynth::stitch::faces::scene_faces;
use viewsynth::stitch::reference::stitch_reference;
use viewsynth::stitch::render::StitchRenderer;
use viewsynth::stitch::{self, OdsRig, Side, StitchInput, StitchParams};
use viewsynth::view::ViewOutput;
use viewsynth_lab::eval::reproject::scene_cases;
use viewsynth_tests::{gpu, synthetic};

/// A convention other than the default, so the input's conventions reach the GPU side.
fn other_conventions() -> Conventions {
    *Conventions::all().last().unwrap()
}

/// Same size and the same bytes in every plane (depth compared bit for bit).
fn assert_same(tag: &str, a: &ViewOutput, b: &ViewOutput) {
    assert_eq!((a.width, a.height), (b.width, b.height), "{tag}: size");
    assert_eq!(
        a.color.as_ref().map(|c| &c.data),
        b.color.as_ref().map(|c| &c.data),
        "{tag}: colour"
    );
    let bits = |v: &ViewOutput| {
        v.depth
            .as_ref()
            .map(|d| d.data.iter().map(|z| z.to_bits()).collect::<Vec<_>>())
    };
    assert_eq!(bits(a), bits(b), "{tag}: depth");
    assert_eq!(
        a.mask.as_ref().map(|m| &m.data),
        b.mask.as_ref().map(|m| &m.data),
        "{tag}: mask"
    );
    let exact = |v: &ViewOutput| v.exact.as_ref().map(|e| (e.color.clone(), e.depth.clone()));
    assert_eq!(exact(a), exact(b), "{tag}: exact values");
}

#[test]
fn refocus_pass_and_twin_are_the_renderer_and_the_twin() {
    let g = gpu();
    let src = synthetic(96, 72);
    let mut target = src.camera();
    target.k.fx *= 1.5;
    target.k.fy *= 1.5;
    for method in [Method::Fullscreen, Method::Mesh] {
        let input = RefocusInput {
            source: &src,
            target: &target,
            rule: BreakRule::default(),
            method,
            outputs: OutputSet::default(),
            rgb_everywhere: false,
            conv: other_conventions(),
        };
        let direct = Refocuser::new(&g, &src, &input.rule, method, input.outputs, input.conv)
            .unwrap()
            .render(&target)
            .unwrap();
        let view = refocus::pass::gpu(&g, &input).unwrap();
        assert_same("refocus gpu", &view, &ViewOutput::from_refocus(&direct));
        assert!(view.timing.is_some() && view.exact.is_none());
        let twin = refocus::pass::reference(&input).unwrap();
        let r = refocus_reference(&src, &input.rule, &target);
        assert_same("refocus twin", &twin, &ViewOutput::from_refocus_reference(&r));
        assert!(twin.timing.is_none() && twin.exact.is_some());
    }
    // Depth only: both sides leave colour and mask out.
    let input = RefocusInput {
        source: &src,
        target: &target,
        rule: BreakRule::default(),
        method: Method::Fullscreen,
        outputs: OutputSet::parse("depth").unwrap(),
        rgb_everywhere: false,
        conv: Conventions::default(),
    };
    for v in [
        refocus::pass::gpu(&g, &input).unwrap(),
        refocus::pass::reference(&input).unwrap(),
    ] {
        assert!(v.color.is_none() && v.mask.is_none() && v.depth.is_some());
    }
}

#[test]
fn cyclopean_pass_and_twin_are_the_renderers_and_the_twins() {
    let g = gpu();
    let conv = other_conventions();
    let (frame, mid, _) = scene_frame(&StereoRig::demo(96, 72), conv, FrameDepth::Device);
    let (w, h) = (mid.width, mid.height);
    let outputs = CyclopeanOutputs::default();
    let gather = CyclopeanParams::seed(3.0);
    let splat = SplatParams::default();
    let input = |pass| CyclopeanInput {
        frame: &frame,
        mid: &mid,
        pass,
        outputs,
    };
    let (out, _) = CyclopeanRenderer::new(&g, &frame, gather)
        .unwrap()
        .render(&mid)
        .unwrap();
    let gather_in = input(CyclopeanPass::Gather(gather));
    assert_same(
        "gather gpu",
        &cyclopean::pass::gpu(&g, &gather_in).unwrap(),
        &ViewOutput::from_cyclopean(&out, w, h, None),
    );
    let r = cyclopean_reference(&frame, &mid, &gather).unwrap();
    assert_same(
        "gather twin",
        &cyclopean::pass::reference(&gather_in).unwrap(),
        &ViewOutput::from_cyclopean_reference(&r, w, h),
    );
    let (out, _) = SplatRenderer::new(&g, &frame, splat, outputs)
        .unwrap()
        .render(&mid)
        .unwrap();
    let splat_in = input(CyclopeanPass::Splat(splat));
    assert_same(
        "splat gpu",
        &cyclopean::pass::gpu(&g, &splat_in).unwrap(),
        &ViewOutput::from_cyclopean(&out, w, h, None),
    );
    let r = splat_reference(&frame, &mid, &splat).unwrap();
    assert_same(
        "splat twin",
        &cyclopean::pass::reference(&splat_in).unwrap(),
        &ViewOutput::from_cyclopean_reference(&r, w, h),
    );
    // Colour only: both sides leave depth out and keep the source bits.
    let colour_only = CyclopeanInput {
        outputs: CyclopeanOutputs {
            color: true,
            depth: false,
        },
        ..gather_in
    };
    for v in [
        cyclopean::pass::gpu(&g, &colour_only).unwrap(),
        cyclopean::pass::reference(&colour_only).unwrap(),
    ] {
        assert!(v.color.is_some() && v.depth.is_none() && v.mask.is_some());
    }
}

#[test]
fn reproject_pass_and_twin_are_the_renderer_and_the_twin() {
    let g = gpu();
    let cases = scene_cases(96, 72, 0.2, other_conventions(), FrameDepth::ViewZ).unwrap();
    for case in &cases {
        for params in viewsynth_lab::eval::reproject::methods() {
            let input = ReprojectInput {
                source: &case.source,
                geometry: &case.geometry,
                params,
            };
            let r = reproject_reference(&case.source, &case.geometry, &params).unwrap();
            let (out, _) = Reprojector::new(&g, &case.source, &case.geometry, params)
                .unwrap()
                .render()
                .unwrap();
            let tag = format!("{} {}", case.name, params.method.label());
            assert_same(
                &tag,
                &reproject::pass::gpu(&g, &input).unwrap(),
                &ViewOutput::from_reproject(&out, r.width, r.height, None),
            );
            assert_same(
                &tag,
                &reproject::pass::reference(&input).unwrap(),
                &ViewOutput::from_reproject_reference(&r),
            );
        }
    }
    let case = &cases[0];
    let input = ReprojectInput {
        source: &case.source,
        geometry: &case.geometry,
        params: ReprojectParams {
            outputs: ReprojectOutputs {
                color: false,
                depth: true,
            },
            ..viewsynth_lab::eval::reproject::methods()[0]
        },
    };
    for v in [
        reproject::pass::gpu(&g, &input).unwrap(),
        reproject::pass::reference(&input).unwrap(),
    ] {
        assert!(v.color.is_none() && v.depth.is_some() && v.mask.is_some());
    }
}

#[test]
fn stitch_pass_and_twin_are_the_renderer_and_the_twin() {
    let g = gpu();
    let rig = OdsRig::demo();
    let (l, r) = (
        scene_faces(&rig, Side::Left, 48, 100.0).unwrap(),
        scene_faces(&rig, Side::Right, 48, 100.0).unwrap(),
    );
    for method in stitch::Method::ALL {
        let input = StitchInput {
            left: &l,
            right: &r,
            params: StitchParams {
                method,
                overlap_deg: 5.0,
                width: 128,
                height: 64,
            },
            outputs: viewsynth::output::OutputSet::RGB,
            conv: other_conventions(),
        };
        let (image, _) = StitchRenderer::with_conventions(&g, &l, &r, input.conv)
            .unwrap()
            .render(&input.params)
            .unwrap();
        let view = stitch::pass::gpu(&g, &input).unwrap();
        assert_same("stitch gpu", &view, &ViewOutput::color_only(image, None));
        assert_eq!((view.width, view.height), (128, 128), "top-bottom stereo");
        let both: Vec<[f64; 3]> = stitch_reference(&l, &input.params)
            .unwrap()
            .into_iter()
            .chain(stitch_reference(&r, &input.params).unwrap())
            .collect();
        assert_same(
            "stitch twin",
            &stitch::pass::reference(&input).unwrap(),
            &ViewOutput::from_color_f64(128, 128, &both),
        );
    }
}
