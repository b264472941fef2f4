//! Size limits come from the context: every capability accepts sides up to
//! `gpu.max_image_side()` (GL_MAX_TEXTURE_SIZE and viewport; 16384 on llvmpipe, 32768 on NVIDIA)
//! and refuses one past it with the same message: the parameter, the size and the limit.
//! One-row images keep the oversized cases cheap.

use viewsynth::camera::stereo::Eye;
use viewsynth::camera::{gl_projection, Intrinsics, PinholeCamera, Pose};
use viewsynth::convention::{Conventions, DepthPlanes};
use viewsynth::cyclopean::forward::ForwardWarp;
use viewsynth::depth::DepthEncoding;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::refocus::{BreakRule, Method as RefocusMethod, OutputSet, RefocusSource, Refocuser};
use viewsynth::reproject::render::Reprojector;
use viewsynth::reproject::{Geometry, Method, ReprojectParams, ReprojectSource, ShiftModel};
use viewsynth::scene::render::{GlCamera, SceneRenderer};
use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
use viewsynth::stereo::gather::CyclopeanParams;
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;
use viewsynth::stitch::faces::scene_faces;
use viewsynth::stitch::render::StitchRenderer;
use viewsynth::stitch::{Method as StitchMethod, OdsRig, Side, StitchParams};
use viewsynth::world::builtin;
use viewsynth::Error;
use viewsynth_tests::gpu;

/// The one refusal: `invalid <name>: <w>x<h> exceeds this GPU's limit of <limit>`; returns the
/// parameter name.
fn assert_refused(r: Result<(), Error>, w: u32, h: u32, limit: u32) -> String {
    let e = r.expect_err("one past the context's limit must be refused").to_string();
    let rest = e.strip_prefix("invalid ").unwrap_or_else(|| panic!("{e}"));
    let (name, rest) = rest.split_once(": ").unwrap_or_else(|| panic!("{e}"));
    assert_eq!(
        rest.strip_prefix(&format!("{w}x{h} exceeds this GPU's limit of {limit}"))
            .map(|_| ()),
        Some(()),
        "{e}"
    );
    name.to_string()
}

fn k(w: u32, h: u32) -> Intrinsics {
    Intrinsics {
        fx: 100.0,
        fy: 100.0,
        cx: (w as f64 - 1.0) / 2.0,
        cy: (h as f64 - 1.0) / 2.0,
    }
}

#[test]
fn refocus_output_one_past_the_limit_is_refused() {
    let g = gpu();
    let max = g.max_image_side();
    let src = RefocusSource::new(
        RgbImage::new(4, 3, vec![90; 36]).unwrap(),
        DepthMap::new(4, 3, vec![2.0; 12]).unwrap(),
        k(4, 3),
    )
    .unwrap();
    let mut r = Refocuser::new(
        &g,
        &src,
        &BreakRule::default(),
        RefocusMethod::Fullscreen,
        OutputSet::default(),
        Conventions::default(),
    )
    .unwrap();
    let target = |w| PinholeCamera {
        k: k(w, 1),
        width: w,
        height: 1,
    };
    assert_eq!(
        assert_refused(r.render(&target(max + 1)).map(|_| ()), max + 1, 1, max),
        "output size"
    );
    // The limit itself renders.
    r.render(&target(max)).expect("a side equal to the limit renders");
}

#[test]
fn refocus_source_limit_is_the_context_limit_less_the_grid_ring() {
    let g = gpu();
    let max = viewsynth::refocus::max_source_side(&viewsynth::pass::Device::gl(&g).unwrap());
    assert_eq!(max, g.max_image_side() - 1);
    let w = max + 1;
    let src = RefocusSource::new(
        RgbImage::new(w, 1, vec![7; 3 * w as usize]).unwrap(),
        DepthMap::new(w, 1, vec![1.0; w as usize]).unwrap(),
        k(w, 1),
    )
    .expect("the source itself has no GPU limit");
    let e = Refocuser::new(
        &g,
        &src,
        &BreakRule::default(),
        RefocusMethod::Fullscreen,
        OutputSet::default(),
        Conventions::default(),
    )
    .map(|_| ())
    .expect_err("one past the source limit")
    .to_string();
    assert!(e.starts_with(&format!("invalid source size: {w}x1")), "{e}");
    assert!(e.contains(&max.to_string()), "names the limit {max}: {e}");
}

#[test]
fn cyclopean_middle_view_one_past_the_limit_is_refused_by_both_renderers() {
    let g = gpu();
    let max = g.max_image_side();
    let rig = StereoRig::demo(16, 12);
    let (frame, mut mid, _) = scene_frame(&rig, Conventions::default(), FrameDepth::ViewZ);
    (mid.width, mid.height) = (max + 1, 1);
    let mut gather = CyclopeanRenderer::new(&g, &frame, CyclopeanParams::seed(3.0)).unwrap();
    assert_eq!(
        assert_refused(gather.render(&mid).map(|_| ()), max + 1, 1, max),
        "middle size"
    );
    let mut forward = ForwardWarp::new(&g, &frame, &BreakRule::default()).unwrap();
    assert_eq!(
        assert_refused(forward.render(&mid).map(|_| ()), max + 1, 1, max),
        "middle size"
    );
}

#[test]
fn reproject_source_one_past_the_limit_is_refused() {
    let g = gpu();
    let max = g.max_image_side();
    let w = max + 1;
    let src = ReprojectSource {
        color: RgbImage::new(w, 1, vec![50; 3 * w as usize]).unwrap(),
        depth: DepthMap::new(w, 1, vec![2.0; w as usize]).unwrap(),
        depth_kind: DepthEncoding::ViewZ,
        conv: Conventions::default(),
    };
    let geometry = Geometry::Rig {
        camera: PinholeCamera {
            k: k(w, 1),
            width: w,
            height: 1,
        },
        shift: ShiftModel::rectified(10.0, 0.0, 0.0, Some(Eye::Left), Some(Eye::Right)).unwrap(),
    };
    let r = Reprojector::new(&g, &src, &geometry, ReprojectParams::new(Method::ShiftScan)).map(|_| ());
    assert_eq!(assert_refused(r, w, 1, max), "source size");
}

#[test]
fn stitch_equirect_one_past_the_limit_is_refused() {
    let g = gpu();
    let max = g.max_image_side();
    let rig = OdsRig::demo();
    let (l, r) = (
        scene_faces(&rig, Side::Left, 4, 100.0).unwrap(),
        scene_faces(&rig, Side::Right, 4, 100.0).unwrap(),
    );
    let mut s = StitchRenderer::new(&g, &l, &r).unwrap();
    let params = |width, height| StitchParams {
        method: StitchMethod::Blend,
        overlap_deg: 5.0,
        width,
        height,
    };
    let refused = s.render(&params(max + 1, 1)).map(|_| ());
    assert_eq!(assert_refused(refused, max + 1, 2, max), "equirect size");
    // The top-bottom image has 2 h rows: h = max / 2 + 1 is one past it.
    let h = max / 2 + 1;
    assert_eq!(
        assert_refused(s.render(&params(1, h)).map(|_| ()), 1, 2 * h, max),
        "equirect size"
    );
}

#[test]
fn scene_camera_one_past_the_limit_is_refused() {
    let g = gpu();
    let max = g.max_image_side();
    let mut r = SceneRenderer::new(&g, &builtin("demo").unwrap()).unwrap();
    let cam = PinholeCamera {
        k: k(max + 1, 1),
        width: max + 1,
        height: 1,
    };
    let conv = Conventions::default();
    let glc = GlCamera {
        view: Pose::yawed(0.0, [0.0, 0.0, 0.0]).gl_view(),
        proj: gl_projection(&cam, &DepthPlanes { near: 0.1, far: 50.0 }, &conv),
        width: max + 1,
        height: 1,
        conv,
    };
    assert_eq!(
        assert_refused(r.render(&glc).map(|_| ()), max + 1, 1, max),
        "camera size"
    );
}
