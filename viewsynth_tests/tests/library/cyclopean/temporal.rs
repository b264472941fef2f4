//! Temporal accumulation (src/cyclopean/temporal.rs): the GPU passes against their f64 twin on
//! both executors under every convention, on a head moving sideways and forward past the
//! built-in scene, one eye's depth emptied so each middle view has disocclusion holes.
//!
//! Bounds, from the numerics. The passes pick texels by the same rule as the twin (floor of the
//! window position, nearest distance, first texel in row order at a tie), in f32 where the twin
//! is f64. A texel's window position is three 4x4 products of values below ~10^3 from f32
//! inputs: its error is below 1e-4 px, so a texel whose f64 position lies within 1e-3 px of a
//! pixel edge may land on either side, and two texels reaching one pixel at distances within
//! 1e-5 relative (f32 eps times the products' growth) may swap. Those pixels are listed from
//! the twin's own geometry (below) and excused; every other pixel must carry the twin's source
//! bits exactly, its depth within 1e-5 relative, its colour within one level (a blend in f32
//! against f64 may round the other way at a half level; with alpha 1 colour is exact). The
//! excused pixels must stay under 5 % of the frame, so that the comparison keeps its power:
//! they cluster (a wall facing the camera puts a whole texel row at one window y, so a row
//! inside the band excuses its pixels at once); 2.5 % at most when written.

use viewsynth::camera::mat4;
use viewsynth::convention::{Conventions, RowOrder};
use viewsynth::cyclopean::temporal::{Accumulator, FROM_HISTORY};
use viewsynth::cyclopean::temporal_reference::{carried, TemporalAccumulator};
use viewsynth::pass::Device;
use viewsynth::stereo::gather::gpu::CyclopeanRenderer;
use viewsynth::stereo::gather::{CyclopeanOutput, CyclopeanParams, Method};
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::{FrameDepth, MiddleCamera};
use viewsynth_lab::eval::image_check::{self, Plane};
use viewsynth_tests::gpu;

/// Middle views of the scene from a head at `at` (right eye's depth emptied: holes), rendered
/// on GL whatever device accumulates them.
fn frames(conv: Conventions) -> Vec<(CyclopeanOutput, MiddleCamera)> {
    let g = gpu();
    let params = CyclopeanParams {
        method: Method::Refine { steps: 3 },
        ..CyclopeanParams::seed(3.0)
    };
    [[0.13, 0.0, 0.0], [0.0, 0.0, 0.0], [-0.07, 0.02, -0.11]]
        .into_iter()
        .map(|at| {
            let mut rig = StereoRig::demo(160, 120);
            rig.ipd = 0.2;
            rig.head = viewsynth::camera::Pose::at(at);
            let (mut frame, mid, _) = scene_frame(&rig, conv, FrameDepth::Device);
            let far = conv.clear_depth() as f32;
            frame.right.depth.data.iter_mut().for_each(|z| *z = far);
            let (out, _) = CyclopeanRenderer::new(&g, &frame, params)
                .unwrap()
                .render(&mid)
                .unwrap();
            (out, mid)
        })
        .collect()
}

/// Pixels of `mid` where f32 may choose another history texel than f64: reached by a texel of
/// `prev` within 1e-3 px of a pixel edge (the pixels either side), or by two texels at
/// distances within 1e-5 relative but not equal (equal ones are equal in f32 too here: the
/// scene's walls face the camera and the head does not turn, so a wall's view Z is its
/// distance plus the head's offset, exact in both).
fn ambiguous(prev: &CyclopeanOutput, prev_mid: &MiddleCamera, mid: &MiddleCamera, conv: Conventions) -> Vec<bool> {
    let (pw, ph) = (prev_mid.width as usize, prev_mid.height as usize);
    let (w, h) = (mid.width as i64, mid.height as i64);
    let inv_proj = mat4::inverse(&prev_mid.proj).unwrap();
    let inv_view = mat4::inverse(&prev_mid.view).unwrap();
    let vp = mat4::mul(&mid.proj, &mid.view);
    let mut out = vec![false; (w * h) as usize];
    let mut landed: Vec<Vec<f64>> = vec![Vec::new(); (w * h) as usize];
    let depth = &prev.depth.as_ref().unwrap().data;
    for y in 0..ph {
        let y_mem = if conv.row_order == RowOrder::BottomUp {
            ph - 1 - y
        } else {
            y
        };
        for x in 0..pw {
            let d = depth[y * pw + x] as f64;
            if !carried(prev, prev.depth.as_ref().unwrap(), x, y, pw, ph, 0.02) {
                continue;
            }
            let ndc = [
                (x as f64 + 0.5) / pw as f64 * 2.0 - 1.0,
                (y_mem as f64 + 0.5) / ph as f64 * 2.0 - 1.0,
            ];
            let p = mat4::transform_point(&inv_proj, [ndc[0], ndc[1], 0.5]);
            let world = mat4::transform_point(&inv_view, [p[0] / -p[2] * d, p[1] / -p[2] * d, -d]);
            let clip = mat4::transform(&vp, [world[0], world[1], world[2], 1.0]);
            if clip[3] <= 0.0 {
                continue;
            }
            let wx = (clip[0] / clip[3] * 0.5 + 0.5) * w as f64;
            let wy = (clip[1] / clip[3] * 0.5 + 0.5) * h as f64;
            let near_edge = |v: f64| (v - v.round()).abs() < 1e-3;
            let (tx, ty) = (wx.floor() as i64, wy.floor() as i64);
            let to_rows = |ym: i64| {
                if conv.row_order == RowOrder::BottomUp {
                    h - 1 - ym
                } else {
                    ym
                }
            };
            for (dx, dy) in [(0, 0), (-1, 0), (1, 0), (0, -1), (0, 1)] {
                let (cx, cy) = (tx + dx, ty + dy);
                if cx < 0 || cy < 0 || cx >= w || cy >= h {
                    continue;
                }
                let i = (to_rows(cy) * w + cx) as usize;
                if (dx, dy) == (0, 0) {
                    landed[i].push(-mat4::transform_point(&mid.view, world)[2]);
                }
                if (dx != 0 && near_edge(wx))
                    || (dy != 0 && near_edge(wy))
                    || ((dx, dy) == (0, 0) && (near_edge(wx) || near_edge(wy)))
                {
                    out[i] = true;
                }
            }
        }
    }
    for (i, zs) in landed.iter_mut().enumerate() {
        zs.sort_by(f64::total_cmp);
        if zs
            .windows(2)
            .take(1)
            .any(|p| p[1] != p[0] && p[1] - p[0] <= 1e-5 * p[0])
        {
            out[i] = true;
        }
    }
    out
}

/// The frames are rendered before `device` is made: a GL context made after another is
/// current in its place.
fn check(device: impl FnOnce() -> Device, api: &str) {
    let cases: Vec<_> = Conventions::all()
        .into_iter()
        .map(|conv| (conv, frames(conv)))
        .collect();
    let device = &device();
    let mut worst = 0.0f64;
    for (k, (conv, seq)) in cases.into_iter().enumerate() {
        for alpha in [1.0, 0.5] {
            let tag = format!("{api} conv{k} alpha {alpha}");
            let mut gpu_acc = Accumulator::new(device, alpha, 0.02, conv).unwrap();
            let mut twin = TemporalAccumulator::new(alpha, 0.02, conv).unwrap();
            let mut prev: Option<(CyclopeanOutput, MiddleCamera)> = None;
            let mut filled = 0;
            for (n, (view, mid)) in seq.iter().enumerate() {
                let g = gpu_acc.push(view, mid).unwrap();
                let t = twin.push(view, mid).unwrap();
                let excused = match &prev {
                    Some((p, pm)) => ambiguous(p, pm, mid, conv),
                    None => vec![false; t.sources.len()],
                };
                let (gc, tc) = (&g.color().unwrap().data, &t.color().unwrap().data);
                let (gz, tz) = (&g.depth().unwrap().data, &t.depth().unwrap().data);
                let mut bad = Vec::new();
                for i in 0..t.sources.len() {
                    if excused[i] {
                        continue;
                    }
                    let dc = (0..3)
                        .map(|c| (gc[3 * i + c] as i32 - tc[3 * i + c] as i32).abs())
                        .max()
                        .unwrap();
                    let dz = (gz[i] - tz[i]).abs() as f64 / (tz[i].abs() as f64).max(1e-30);
                    let level = if alpha == 1.0 { 0 } else { 1 };
                    if g.sources[i] != t.sources[i] || dc > level || (dz > 1e-5 && gz[i] != tz[i]) {
                        bad.push(i);
                    }
                }
                filled += t.sources.iter().filter(|s| **s == FROM_HISTORY).count();
                let share = excused.iter().filter(|e| **e).count() as f64 / excused.len() as f64;
                worst = worst.max(share);
                let (w, h) = (mid.width, mid.height);
                image_check::ensure(
                    bad.is_empty() && share < 0.05,
                    &format!("temporal {tag} frame {n}"),
                    w,
                    h,
                    &[
                        ("color", Plane::Rgb(gc), Plane::Rgb(tc)),
                        ("depth", Plane::Depth(gz), Plane::Depth(tz)),
                        ("sources", Plane::Mask(&g.sources), Plane::Mask(&t.sources)),
                    ],
                    format!(
                        "{tag} frame {n}: {} pixels differ from the twin beyond the bounds (first {:?}), {:.2} % excused",
                        bad.len(),
                        bad.first(),
                        share * 100.0
                    ),
                );
                prev = Some((t, *mid));
            }
            // The case must exercise the history: it fills holes in frames 1 and 2.
            assert!(filled > 200, "{tag}: only {filled} pixels filled from the history");
        }
    }
    println!("{api}: largest excused share {:.3} %", worst * 100.0);
}

#[test]
fn temporal_passes_match_their_twin_on_gl_under_every_convention() {
    check(|| Device::gl(&gpu()).unwrap(), "GL");
}

#[cfg(feature = "vulkan")]
#[test]
fn temporal_passes_match_their_twin_on_vulkan_under_every_convention() {
    check(
        || viewsynth::vulkan::VkExecutor::device(&viewsynth_tests::vulkan()).unwrap(),
        "Vulkan",
    );
}

/// Without a history the first frame passes through unchanged on the device, and a reset
/// forgets the history; a frame of another size than its camera is refused by name.
#[test]
fn temporal_first_frame_passes_through_and_reset_forgets() {
    let conv = Conventions::default();
    let seq = frames(conv);
    let device = Device::gl(&gpu()).unwrap();
    let mut acc = Accumulator::new(&device, 1.0, 0.02, conv).unwrap();
    let first = acc.push(&seq[0].0, &seq[0].1).unwrap();
    assert_eq!(first.color, seq[0].0.color);
    assert_eq!(first.sources, seq[0].0.sources);
    let second = acc.push(&seq[1].0, &seq[1].1).unwrap();
    assert!(second.sources.contains(&FROM_HISTORY), "the history fills holes");
    acc.reset();
    let again = acc.push(&seq[1].0, &seq[1].1).unwrap();
    assert_eq!(
        again.sources, seq[1].0.sources,
        "after a reset nothing comes from history"
    );
    let mut small = seq[1].1;
    small.width -= 1;
    let Err(err) = acc.push(&seq[1].0, &small) else {
        panic!("a size mismatch is refused")
    };
    let err = err.to_string();
    assert!(err.contains("159x120"), "{err}");
    assert!(Accumulator::new(&device, 0.0, 0.02, conv).is_err());
    assert!(Accumulator::new(&device, 1.0, f64::NAN, conv).is_err());
}
