//! The backend-neutral passes (src/pass/): every parameter block laid out as the GL compiler
//! lays out its GLSL mirror; GL against Vulkan for every full-screen pass under all eight
//! conventions; the commands' `--backend vulkan` runs writing what their GL runs write; and
//! those runs clean under the Khronos validation layer. A missing Vulkan loader, driver or
//! validation layer fails these tests, never skips them.
//!
//! GL-vs-Vulkan bounds (the issue of record's agreement rule, `eval::backends`): masks differ
//! on at most 0.5 % of pixels, colour within one level on at least 99.5 %, depth within 1e-4
//! relative on at least 99.5 % of the pixels valid in both. Why they hold: both executors run
//! the same GLSL on the same f32 inputs (images in the same memory rows, parameter blocks of
//! identical bytes), so the outputs differ only where the two compilers (Mesa's GLSL front end
//! against glslang + SPIR-V to NIR) order or fuse f32 arithmetic differently. Each pass's own
//! GPU-vs-f64 derivation (viewsynth_tests/tests/library/{reproject,scene,stitch,cyclopean/gather}.rs) bounds either
//! backend's distance to the twin by e (depth: 3e-5 reproject, 2e-5 scene and gather), so two
//! backends are within 2e of each other, inside 1e-4; a decision (mask, surface, rounding tie)
//! flips only for values within a few ulp of a threshold, which the twin tests put at under
//! 0.1 % of pixels per backend. Measured values are printed.
use std::collections::BTreeSet;
use viewsynth::convention::Conventions;
use viewsynth::cyclopean::forward::{ForwardParams, ForwardWarp};
use viewsynth::cyclopean::splat::{EdgeSnapBlock, SplatBlock, SplatGatherBlock, SplatParams, SplatRenderer};
use viewsynth::pass::shaders::{ShiftDepth, StitchBlend};
use viewsynth::pass::{Device, ParamBlock, ProgramKind, ShaderProgram};
use viewsynth::refocus::{BreakRule, RefocusParams};
use viewsynth::reproject::render::ShiftParams;
use viewsynth::reproject::{self, ReprojectInput};
use viewsynth::scene::render::{GlCamera, RaytraceParams, SceneRenderer};
use viewsynth::stereo::gather::gpu::{CyclopeanRenderer, GatherParams};
use viewsynth::stereo::gather::{CyclopeanOutputs, CyclopeanParams, Method};
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;
use viewsynth::stitch::faces::scene_faces;
use viewsynth::stitch::render::StitchBlock;
use viewsynth::stitch::{self, Method as StitchMethod, OdsRig, Side, StitchInput, StitchParams};
use viewsynth::view::ViewOutput;
use viewsynth::vulkan::VkExecutor;
use viewsynth_lab::eval::backends::{backend_diff, BackendDiff};
use viewsynth_lab::eval::reproject::{methods, scene_cases};
use viewsynth_tests::gpu;
use viewsynth_tests::vulkan;

/// Rust offsets and size against what the GL compiler reports for `P`'s block in `program`.
fn check_block<P: ParamBlock>(program: ProgramKind) {
    let g = gpu();
    let built = ShaderProgram::new(Conventions::default(), program).build(&g).unwrap();
    let (size, members) = built
        .uniform_block_layout(P::BLOCK)
        .unwrap_or_else(|| panic!("{}: no uniform block {}", program.name(), P::BLOCK));
    // std140 rounds a block's size up to a multiple of 16 bytes.
    assert_eq!(
        size,
        std::mem::size_of::<P>().div_ceil(16) * 16,
        "{}: block size",
        P::BLOCK
    );
    assert_eq!(members.len(), P::FIELDS.len(), "{}: members {members:?}", P::BLOCK);
    for (name, offset) in &members {
        let name = name.strip_suffix("[0]").unwrap_or(name);
        let rust = P::FIELDS
            .iter()
            .find(|(f, _)| *f == name)
            .unwrap_or_else(|| panic!("{}: GLSL member {name} has no Rust field", P::BLOCK));
        assert_eq!(rust.1, *offset, "{}: offset of {name}", P::BLOCK);
    }
}

/// A program and the check of its parameter block.
type LayoutCheck = (ProgramKind, fn(ProgramKind));

/// Every program's parameter-block check, one row per program (a switch does not change the
/// block): a program added to the shader library without its row here fails
/// `every_registered_program_has_a_layout_check` (the add-a-pass recipe, ARCHITECTURE.md).
fn layout_checks() -> Vec<LayoutCheck> {
    let mut checks: Vec<LayoutCheck> = vec![
        (
            ProgramKind::CyclopeanGather {
                depth_is_device: true,
                refine: true,
                blend_soft: true,
            },
            check_block::<GatherParams>,
        ),
        (
            ProgramKind::ReprojectShift {
                depth: ShiftDepth::Device,
                scan: false,
                scan_margin: 1,
            },
            check_block::<ShiftParams>,
        ),
        (
            ProgramKind::Stitch {
                method: StitchBlend::Reproject,
                reproject_steps: 3,
            },
            check_block::<StitchBlock>,
        ),
        (ProgramKind::SceneRaytrace, check_block::<RaytraceParams>),
        (ProgramKind::CyclopeanSplat, check_block::<SplatBlock>),
        (ProgramKind::CyclopeanEdgeSnap, check_block::<EdgeSnapBlock>),
        (ProgramKind::CyclopeanSplatGather, check_block::<SplatGatherBlock>),
        (ProgramKind::CyclopeanSplatEdges, check_block::<SplatGatherBlock>),
        (ProgramKind::CyclopeanForward, check_block::<ForwardParams>),
        (
            ProgramKind::RefocusFullscreen {
                want_rgb: true,
                rgb_everywhere: false,
            },
            check_block::<RefocusParams>,
        ),
        (
            ProgramKind::CyclopeanFill,
            check_block::<viewsynth::cyclopean::fill::FillParams>,
        ),
        (
            ProgramKind::CyclopeanTemporalReproject { winner: true },
            check_block::<viewsynth::cyclopean::temporal::TemporalParams>,
        ),
        (
            ProgramKind::CyclopeanTemporalCompose,
            check_block::<viewsynth::cyclopean::temporal::TemporalParams>,
        ),
    ];
    for stage in viewsynth::pass::shaders::MatcherStage::ALL {
        checks.push((
            ProgramKind::CyclopeanMatcher(stage),
            check_block::<viewsynth::stereo::matcher::gpu::MatcherParams>,
        ));
    }
    checks.extend([
        (
            ProgramKind::RefocusMeshBoundary { want_rgb: true },
            check_block::<RefocusParams> as fn(ProgramKind),
        ),
        (
            ProgramKind::RefocusMeshInterior { want_rgb: true },
            check_block::<RefocusParams>,
        ),
        (ProgramKind::RefocusColourEverywhere, check_block::<RefocusParams>),
        (
            ProgramKind::CyclopeanDensify,
            check_block::<viewsynth::stereo::densify::DensifyParams>,
        ),
    ]);
    checks
}

#[test]
fn every_parameter_block_has_the_layout_the_gl_compiler_reports() {
    for (program, check) in layout_checks() {
        check(program);
    }
}

#[test]
fn every_registered_program_has_a_layout_check() {
    let checked: BTreeSet<&str> = layout_checks().iter().map(|(p, _)| p.name()).collect();
    let missing: BTreeSet<&str> = ShaderProgram::all(Conventions::default())
        .iter()
        .map(|p| p.kind.name())
        .filter(|name| !checked.contains(name))
        .collect();
    assert!(
        missing.is_empty(),
        "programs of the shader library without a parameter-block check in layout_checks(): {missing:?}"
    );
}

fn devices() -> (Device, Device) {
    (Device::gl(&gpu()).unwrap(), VkExecutor::device(&vulkan()).unwrap())
}

fn assert_agree(tag: &str, d: &BackendDiff) {
    println!("{tag}: {d:?}");
    assert!(d.agrees(), "{tag}: GL and Vulkan differ beyond the bounds: {d:?}");
}

#[test]
fn reproject_shift_scan_and_gather3d_agree_between_gl_and_vulkan_under_every_convention() {
    let (gl, vk) = devices();
    for conv in Conventions::all() {
        for kind in [FrameDepth::Device, FrameDepth::ViewZ] {
            for case in scene_cases(96, 72, 0.2, conv, kind).unwrap() {
                for params in methods() {
                    let input = ReprojectInput {
                        source: &case.source,
                        geometry: &case.geometry,
                        params,
                    };
                    let a = reproject::pass::gpu(&gl, &input).unwrap();
                    let b = reproject::pass::gpu(&vk, &input).unwrap();
                    let tag = format!("{} {} {}", conv.label(), case.name, params.method.label());
                    assert_agree(&tag, &backend_diff(&a, &b));
                }
            }
        }
    }
}

#[test]
fn scene_ray_tracer_agrees_between_gl_and_vulkan_under_every_convention() {
    let (gl, vk) = devices();
    let scene = viewsynth::world::builtin("demo").unwrap();
    let rig = StereoRig::demo(120, 90);
    for conv in Conventions::all() {
        let (frame, _, _) = scene_frame(&rig, conv, FrameDepth::Device);
        let cam = GlCamera {
            view: frame.left.view,
            proj: frame.left.proj,
            width: 120,
            height: 90,
            conv,
        };
        let a = SceneRenderer::new(&gl, &scene).unwrap().render(&cam).unwrap().0;
        let b = SceneRenderer::new(&vk, &scene).unwrap().render(&cam).unwrap().0;
        let view = |img: &viewsynth::scene::render::SceneImage, depth: &viewsynth::io::DepthMap| ViewOutput {
            width: 120,
            height: 90,
            color: Some(img.color.clone()),
            depth: Some(depth.clone()),
            mask: None,
            timing: None,
            exact: None,
        };
        let tag = conv.label();
        assert_agree(
            &format!("scene {tag} view Z"),
            &backend_diff(&view(&a, &a.view_z), &view(&b, &b.view_z)),
        );
        assert_agree(
            &format!("scene {tag} device depth"),
            &backend_diff(&view(&a, &a.device_depth), &view(&b, &b.device_depth)),
        );
    }
}

#[test]
fn stitch_methods_agree_between_gl_and_vulkan_under_every_convention() {
    let (gl, vk) = devices();
    let rig = OdsRig::demo();
    let fov = 90.0 + 2.0 * 10.0;
    let left = scene_faces(&rig, Side::Left, 48, fov).unwrap();
    let right = scene_faces(&rig, Side::Right, 48, fov).unwrap();
    for conv in Conventions::all() {
        for method in StitchMethod::ALL {
            let input = StitchInput {
                left: &left,
                right: &right,
                params: StitchParams {
                    method,
                    overlap_deg: 10.0,
                    width: 128,
                    height: 64,
                },
                outputs: viewsynth::output::OutputSet::RGB_DEPTH,
                conv,
            };
            let a = stitch::pass::gpu(&gl, &input).unwrap();
            let b = stitch::pass::gpu(&vk, &input).unwrap();
            assert_agree(&format!("stitch {} {method:?}", conv.label()), &backend_diff(&a, &b));
        }
    }
}

/// The splat-gather method (edge snap, splat with atomics, gather listing edge pixels, indirect
/// edge pass rewriting the colour) on both executors, under every convention and both depth
/// kinds, with and without colour (no colour: no edge pass). Its twin check on Vulkan is in
/// viewsynth_tests/tests/library/cyclopean/real_pairs.rs.
#[test]
fn splat_gather_agrees_between_gl_and_vulkan_under_every_convention() {
    let (gl, vk) = devices();
    for conv in Conventions::all() {
        for kind in [FrameDepth::Device, FrameDepth::ViewZ] {
            let (frame, mid, _) = scene_frame(&StereoRig::demo(96, 72), conv, kind);
            for outputs in [
                CyclopeanOutputs::default(),
                CyclopeanOutputs {
                    color: false,
                    depth: true,
                },
            ] {
                let render = |d: &Device| {
                    let (out, _) = SplatRenderer::new(d, &frame, SplatParams::default(), outputs)
                        .unwrap()
                        .render(&mid)
                        .unwrap();
                    ViewOutput::from_cyclopean(&out, mid.width, mid.height, None)
                };
                let (a, b) = (render(&gl), render(&vk));
                assert_eq!(a.color.is_some(), outputs.color);
                assert_agree(
                    &format!("splat-gather {} {kind:?} colour {}", conv.label(), outputs.color),
                    &backend_diff(&a, &b),
                );
            }
        }
    }
}

/// The forward warp (both eyes' depth meshes, vertex pulling, a depth test per the conventions,
/// the GL NDC range through VK_EXT_depth_clip_control) on both executors, every convention.
#[test]
fn forward_warp_agrees_between_gl_and_vulkan_under_every_convention() {
    let (gl, vk) = devices();
    for conv in Conventions::all() {
        for kind in [FrameDepth::Device, FrameDepth::ViewZ] {
            let (frame, mid, _) = scene_frame(&StereoRig::demo(96, 72), conv, kind);
            let render = |d: &Device| {
                let (out, _) = ForwardWarp::new(d, &frame, &BreakRule::default())
                    .unwrap()
                    .render(&mid)
                    .unwrap();
                ViewOutput::from_cyclopean(&out, mid.width, mid.height, None)
            };
            let (a, b) = (render(&gl), render(&vk));
            assert!(a.valid().unwrap().iter().filter(|v| **v).count() * 2 > a.width as usize * a.height as usize);
            assert_agree(&format!("forward {} {kind:?}", conv.label()), &backend_diff(&a, &b));
        }
    }
}

/// One more frame of every pass creates nothing on either API: no pipeline, memory allocation,
/// descriptor pool, command buffer or fence on Vulkan (and no device or queue wait), no GL
/// object (`Gpu::live_objects`): the executors cache programs, pipelines and targets, and
/// renderers keep their images. The Vulkan counterpart of ../shared/tools/gl-calls.
#[test]
fn a_steady_state_frame_creates_nothing_on_either_api() {
    let g = gpu();
    let v = vulkan();
    let devices = [Device::gl(&g).unwrap(), VkExecutor::device(&v).unwrap()];
    let conv = Conventions::all()[5];
    let (frame, mid, _) = scene_frame(&StereoRig::demo(64, 48), conv, FrameDepth::Device);
    let mut moved = StereoRig::demo(64, 48);
    moved.head.position[0] += 0.05;
    let next_frame = scene_frame(&moved, conv, FrameDepth::Device).0;
    let case = scene_cases(64, 48, 0.2, conv, FrameDepth::Device).unwrap().remove(0);
    let rig = OdsRig::demo();
    let (left, right) = (
        scene_faces(&rig, Side::Left, 32, 110.0).unwrap(),
        scene_faces(&rig, Side::Right, 32, 110.0).unwrap(),
    );
    let scene = viewsynth::world::builtin("demo").unwrap();
    let cam = GlCamera {
        view: frame.left.view,
        proj: frame.left.proj,
        width: 64,
        height: 48,
        conv,
    };
    for d in &devices {
        type Frame<'a> = Box<dyn FnMut() + 'a>;
        let mut gather = CyclopeanRenderer::new(d, &frame, CyclopeanParams::seed(3.0)).unwrap();
        let mut splat = SplatRenderer::new(d, &frame, SplatParams::default(), CyclopeanOutputs::default()).unwrap();
        let mut forward = ForwardWarp::new(d, &frame, &BreakRule::default()).unwrap();
        let mut sequence_splat =
            SplatRenderer::new(d, &frame, SplatParams::default(), CyclopeanOutputs::default()).unwrap();
        let mut shift =
            viewsynth::reproject::render::Reprojector::new(d, &case.source, &case.geometry, methods()[0]).unwrap();
        let mut stitch = viewsynth::stitch::render::StitchRenderer::new(d, &left, &right).unwrap();
        let mut tracer = SceneRenderer::new(d, &scene).unwrap();
        let mut matcher = viewsynth::stereo::matcher::Matcher::new(d, 64, 48, 8).unwrap();
        // The first pair uploads the matcher's images; the frames below rewrite them.
        let (matched, _) = matcher.estimate(&frame.left.color, &frame.right.color).unwrap();
        // The densify pass (issue 38) on those disparities: its first eye uploads the inputs.
        let mut densifier = viewsynth::stereo::densify::Densifier::new(d).unwrap();
        drop(
            densifier
                .densify(&matched, &frame.left.color, viewsynth::stereo::densify::OtherEye::LEFT)
                .unwrap(),
        );
        // The checked semi-global matcher (issue 48: census stages and the trust stage in its
        // run), with and without confidence: its first pair uploads the images.
        let mut checked = viewsynth::stereo::matcher::Matcher::checked(d, 64, 48, 8).unwrap();
        for with_confidence in [false, true] {
            drop(
                checked
                    .estimate_checked(&frame.left.color, &frame.right.color, with_confidence)
                    .unwrap(),
            );
        }
        let source = viewsynth_tests::synthetic(64, 48);
        let targets = viewsynth::refocus::manifest::TargetSpec {
            scales: vec![0.5, 1.0, 2.0],
            size: None,
            principal: None,
        }
        .targets(&source.camera())
        .unwrap();
        let refocuser = |method| {
            viewsynth::refocus::Refocuser::new(d, &source, &BreakRule::default(), method, Default::default(), conv)
                .unwrap()
        };
        let (mut fullscreen, mut mesh) = (
            refocuser(viewsynth::refocus::Method::Fullscreen),
            refocuser(viewsynth::refocus::Method::Mesh),
        );
        // The fill's input: a splat-gather view. Its first fill uploads the images; the frames
        // below rewrite them (the first rewrite sizes the flight's staging arena).
        let view = splat.render(&mid).unwrap().0;
        let mut filler = viewsynth::cyclopean::fill::Filler::new(d).unwrap();
        drop(filler.fill(&view, mid.width, mid.height).unwrap());
        // The temporal accumulation: the first pushes upload the history and the current frame,
        // make the scratch images and size the flights' staging for six rewrites a push (the
        // history's three are queued after each run). Measured: the fifth push and later make
        // nothing; with one warm-up push fewer, the first counted one made one Vulkan allocation.
        let mut temporal = viewsynth::cyclopean::temporal::Accumulator::new(d, 1.0, 0.02, conv).unwrap();
        for _ in 0..3 {
            drop(temporal.push(&view, &mid).unwrap());
        }
        let stitch_params = StitchParams {
            method: StitchMethod::Reproject,
            overlap_deg: 10.0,
            width: 64,
            height: 32,
        };
        let frames: Vec<(&str, Frame)> = vec![
            ("gather", Box::new(|| drop(gather.render(&mid).unwrap()))),
            ("splat-gather", Box::new(|| drop(splat.render(&mid).unwrap()))),
            (
                // A sequence's next frame: the eyes rewritten in place, then rendered.
                "splat-gather, next frame of a sequence",
                Box::new(|| {
                    sequence_splat.set_frame(&next_frame).unwrap();
                    drop(sequence_splat.render(&mid).unwrap());
                }),
            ),
            ("forward", Box::new(|| drop(forward.render(&mid).unwrap()))),
            (
                "fill",
                Box::new(|| drop(filler.fill(&view, mid.width, mid.height).unwrap())),
            ),
            (
                "temporal accumulation",
                Box::new(|| drop(temporal.push(&view, &mid).unwrap())),
            ),
            ("reproject shift", Box::new(|| drop(shift.render().unwrap()))),
            ("stitch", Box::new(|| drop(stitch.render(&stitch_params).unwrap()))),
            ("ray tracer", Box::new(|| drop(tracer.render(&cam).unwrap()))),
            (
                // With and without the confidence: two output sets on the same flights.
                "stereo matcher and its confidence",
                Box::new(|| {
                    drop(matcher.estimate(&frame.left.color, &frame.right.color).unwrap());
                    drop(
                        matcher
                            .estimate_with_confidence(&frame.left.color, &frame.right.color)
                            .unwrap(),
                    );
                }),
            ),
            (
                "densify",
                Box::new(|| {
                    drop(
                        densifier
                            .densify(&matched, &frame.left.color, viewsynth::stereo::densify::OtherEye::LEFT)
                            .unwrap(),
                    )
                }),
            ),
            (
                "checked matcher",
                Box::new(|| {
                    for with_confidence in [false, true] {
                        drop(
                            checked
                                .estimate_checked(&frame.left.color, &frame.right.color, with_confidence)
                                .unwrap(),
                        );
                    }
                }),
            ),
            (
                // The batch's frame: a new source of the same size, every target in flight at once.
                "refocus batch frame",
                Box::new(|| {
                    fullscreen.set_source(&source).unwrap();
                    let pending: Vec<_> = targets.iter().map(|t| fullscreen.submit(t).unwrap()).collect();
                    pending.into_iter().for_each(|p| drop(p.wait().unwrap()));
                }),
            ),
            (
                "refocus mesh targets",
                Box::new(|| targets.iter().for_each(|t| drop(mesh.render(t).unwrap()))),
            ),
        ];
        for (name, mut frame) in frames {
            frame();
            let (gl_before, vk_before) = (g.live_objects(), v.census());
            frame();
            frame();
            assert_eq!(g.live_objects(), gl_before, "{name} on {:?}: GL objects", d.api());
            assert_eq!(v.census(), vk_before, "{name} on {:?}: Vulkan objects", d.api());
        }
    }
    assert_eq!(v.census().wait_idles, 0);
}

#[test]
fn cyclopean_gather_renders_on_one_shared_device_for_every_convention() {
    // The renderer's images are freed with it and the device's caches stay bounded: many
    // renderers on one Vulkan device in a row (as `report` and reproject's gather3d make them).
    let vk = VkExecutor::device(&vulkan()).unwrap();
    for conv in Conventions::all() {
        let (frame, mid, _) = scene_frame(&StereoRig::demo(64, 48), conv, FrameDepth::ViewZ);
        let params = CyclopeanParams {
            method: Method::Refine { steps: 2 },
            ..CyclopeanParams::seed(3.0)
        };
        let (out, _) = CyclopeanRenderer::new(&vk, &frame, params)
            .unwrap()
            .render(&mid)
            .unwrap();
        assert!(out.sources.iter().filter(|s| **s != 0).count() * 2 > out.sources.len());
    }
}

/// A write queued for an image (Vulkan defers `write_image` to the next submission) must not
/// land in another image after the first is freed and its id given to the next upload. It did:
/// a temporal accumulator dropped after its last frame left its history rewrite queued, and the
/// next accumulator's fresh history took the id and the stale texels. Here: a 2x1 colour image
/// rewritten to red, freed unsubmitted, then the fill's own upload of a view must read as given.
#[test]
fn a_write_queued_for_a_freed_image_does_not_reach_the_next_image() {
    use viewsynth::cyclopean::fill::Filler;
    use viewsynth::io::{DepthMap, RgbImage};
    use viewsynth::pass::{Format, ImageData};
    use viewsynth::stereo::gather::CyclopeanOutput;
    let device = VkExecutor::device(&vulkan()).unwrap();
    let rgba = |c: [u8; 4]| [c, c].concat();
    let black = rgba([0, 0, 0, 255]);
    let stale = device
        .upload(&ImageData {
            width: 2,
            height: 1,
            format: Format::Rgba8,
            bytes: &black,
            label: "probe",
        })
        .unwrap();
    device.write_image(&stale, &rgba([255, 0, 0, 255])).unwrap();
    drop(stale);
    let view = CyclopeanOutput {
        color: Some(RgbImage::new(2, 1, vec![10, 20, 30, 40, 50, 60]).unwrap()),
        depth: Some(DepthMap::new(2, 1, vec![1.0, 1.0]).unwrap()),
        sources: vec![1, 1],
    };
    let out = Filler::new(&device).unwrap().fill(&view, 2, 1).unwrap();
    assert_eq!(
        out.color.unwrap().data,
        [10, 20, 30, 40, 50, 60],
        "the rendered pixels pass through the fill as uploaded"
    );
}

/// An output a run did not give back, found by the backend-neutral `Rendered::take`, is an
/// error of the API the run was on: "Vulkan error" on Vulkan (it said "OpenGL error" there
/// before issue 45), the GL message unchanged on GL.
#[test]
fn a_missing_output_is_an_error_of_the_backend_the_run_was_on() {
    let (gl, vk) = devices();
    for (device, want) in [
        (&vk, "Vulkan error: a pass: output 0 was not rendered"),
        (&gl, "OpenGL error: a pass: output 0 was not rendered"),
    ] {
        // A run with no target reads nothing back.
        let mut out = device.run(None, &[]).unwrap();
        let e = out.take(0, "a pass").unwrap_err().to_string();
        assert_eq!(e, want);
    }
}

/// The stereo matcher has no command of its own (the commands run under the layer in the
/// command line's `vulkan::passes::every_vulkan_pass_runs_clean_under_the_validation_layer`):
/// its Vulkan test (real pairs, one matcher reused across two pairs) runs again in a child of
/// this test binary under VK_LAYER_KHRONOS_validation. Any validation message fails, and the
/// loader's own log proves the layer was inserted, so a missing layer cannot pass silently.
#[test]
fn the_matcher_runs_clean_under_the_validation_layer() {
    let test = "cyclopean::matcher::matcher_gpu_pass_is_its_twin_on_real_pairs_on_vulkan";
    let text = viewsynth_tests::run_clean_under_validation_layer(
        test,
        std::process::Command::new(std::env::current_exe().unwrap()).args([
            test,
            "--exact",
            "--nocapture",
            "--test-threads",
            "1",
        ]),
    );
    assert!(text.contains("1 passed"), "{test} did not run:\n{text}");
}
