//! Outputs must not depend on the conventions (NDC depth range, reversed-Z, row order): every
//! pass of the library ([`PassCase::all`] but the matcher, which takes no conventions) under all
//! eight combinations, at sizes where pixel centres fall on scene edges (320 x 240, 64 x 48: the
//! demo floor meets the wall exactly on row 172 / 34), odd sizes and wide ones, against the same
//! pass under the GL defaults on the same device. The eyes' depth is view Z, so every convention
//! gets the same input bits and any difference is the pass's own.
//!
//! The rule: coverage identical on every pixel (mask, or depth > 0 where a view has no mask),
//! colour within 1 level on every pixel, depth within [`depth_bound`] or, where a pass picks
//! between two samples ([`picks_between_samples`]), within the step to a neighbouring pixel
//! ([`neighbour_step`]). Passes that
//! work in window depth internally (cyclopean, reproject) round it in f32: a relative depth error
//! of about 2^-24 * z / near per rounding for standard Z (dz / z = dd * z (f - n) / (f n)), far
//! less for reversed-Z; with near 0.05 m and z <= 8 m, 4 roundings (encode, decode,
//! interpolation, test) make 3.8e-5. Elsewhere (scene, refocus, stitch) the same f32 arithmetic
//! in another order: 1e-6. The scene must also have no crack ([`cracks`]).
//!
//! With the eyes' depth stored as device depth under each convention
//! (`VIEWSYNTH_SWEEP_DEPTH=device`) the inputs themselves differ by f32 rounding, and a threshold
//! test on them can go either way: the forward warp's break rule on a floor row whose depth ratio
//! sits at the threshold (65 x 49, reversed-Z), one or two pixels of the reprojection scans. That
//! run is a diagnostic, not part of the rule.

use viewsynth::convention::Conventions;
use viewsynth::pass::Device;
use viewsynth::stereo::FrameDepth;
use viewsynth::view::ViewOutput;
use viewsynth_lab::passes::{PassCase, PassInputs};
use viewsynth_tests::gpu;

/// Relative depth agreement: 4 f32 roundings of window depth at z / near = 160 under standard Z
/// where the pass reads device depth, 1e-6 (reordered f32 arithmetic) otherwise.
fn depth_bound(case: &PassCase) -> f64 {
    match case {
        PassCase::Refocus(_) | PassCase::Scene | PassCase::Stitch(_) => 1e-6,
        _ => 4.0 * 2f64.powi(-24) * 160.0,
    }
}

/// Sizes: the two where the demo floor/wall edge lands on a pixel centre, odd and prime ones,
/// portrait, and the two common large ones.
const SIZES: [(u32, u32); 12] = [
    (63, 47),
    (64, 48),
    (65, 49),
    (97, 131),
    (127, 95),
    (160, 120),
    (320, 240),
    (321, 239),
    (640, 480),
    (641, 479),
    (1280, 720),
    (1919, 1079),
];

#[derive(Default, Debug)]
struct Diff {
    coverage: usize,
    colour: usize,
    colour_worst: i32,
    depth: usize,
    depth_worst: f64,
    first: Option<(usize, &'static str)>,
}

fn coverage(v: &ViewOutput) -> Option<Vec<bool>> {
    v.valid()
        .or_else(|| v.depth.as_ref().map(|d| d.data.iter().map(|z| *z > 0.0).collect()))
}

/// Whether `case` may resolve a near-tie between two samples the other way under another
/// convention ([`neighbour_step`]): passes with a depth test or a splat's nearest-first rule. The
/// gather and reproject passes trace the same rays under every convention (issue 47: their pixel
/// rays come from the clip x, y, w rows), so with view-Z inputs they get no such allowance.
fn picks_between_samples(case: &PassCase, kind: FrameDepth) -> bool {
    match case {
        PassCase::Cyclopean { .. } | PassCase::Reproject(_) => kind == FrameDepth::Device,
        _ => true,
    }
}

fn diff(a: &ViewOutput, b: &ViewOutput, bound: f64, picks: bool) -> Diff {
    let mut d = Diff::default();
    assert_eq!((a.width, a.height), (b.width, b.height));
    let n = a.width as usize * a.height as usize;
    let (ca, cb) = (coverage(a), coverage(b));
    assert_eq!(ca.is_some(), cb.is_some(), "the same planes");
    if let (Some(ca), Some(cb)) = (&ca, &cb) {
        for i in 0..n {
            if ca[i] != cb[i] {
                d.coverage += 1;
                d.first.get_or_insert((i, "coverage"));
            }
        }
    }
    if let (Some(x), Some(y)) = (&a.color, &b.color) {
        for (i, (p, q)) in x.data.chunks_exact(3).zip(y.data.chunks_exact(3)).enumerate() {
            let worst = p
                .iter()
                .zip(q)
                .map(|(u, v)| (*u as i32 - *v as i32).abs())
                .max()
                .unwrap();
            d.colour_worst = d.colour_worst.max(worst);
            if worst > 1 {
                d.colour += 1;
                d.first.get_or_insert((i, "colour"));
            }
        }
    }
    if let (Some(x), Some(y)) = (&a.depth, &b.depth) {
        for i in 0..n {
            let both = match (&ca, &cb) {
                (Some(p), Some(q)) => p[i] && q[i],
                _ => true,
            };
            if !both {
                continue;
            }
            let (za, zb) = (x.data[i] as f64, y.data[i] as f64);
            let rel = if za == zb {
                0.0
            } else {
                (za - zb).abs() / za.abs().max(zb.abs())
            };
            let allowed = if picks { bound.max(neighbour_step(b, i)) } else { bound };
            if rel.is_nan() || rel > allowed {
                d.depth += 1;
                d.first.get_or_insert((i, "depth"));
            }
            d.depth_worst = d.depth_worst.max(if rel.is_nan() { f64::INFINITY } else { rel });
        }
    }
    d
}

/// Pixels of the scene view with no surface whose neighbours above and below (or left and right)
/// both have one. The built-in demo scene has no gap narrower than a pixel at these sizes (its
/// misses are the regions past the wall's edges), so each such pixel is a crack between surfaces
/// that share an edge, like the floor meeting the wall.
fn cracks(v: &ViewOutput) -> Vec<(usize, usize)> {
    let (w, h) = (v.width as usize, v.height as usize);
    let z = &v.depth.as_ref().expect("the scene writes view Z").data;
    let hit = |x: usize, y: usize| z[y * w + x] > 0.0;
    let mut out = Vec::new();
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            if !hit(x, y) && ((hit(x, y - 1) && hit(x, y + 1)) || (hit(x - 1, y) && hit(x + 1, y))) {
                out.push((x, y));
            }
        }
    }
    out
}

/// The largest relative depth step from pixel `i` of `v` to a 4-neighbour with depth. A pass that
/// decides between two samples (the depth test between overlapping triangles of a warped mesh,
/// the steps of a gather or walk) may resolve a near-tie the other way under another convention's
/// arithmetic; it then returns the neighbouring sample of the same surface, which differs by at
/// most this step. Coverage and colour stay exact: such a pixel keeps its surface.
fn neighbour_step(v: &ViewOutput, i: usize) -> f64 {
    let (w, h) = (v.width as usize, v.height as usize);
    let z = &v.depth.as_ref().expect("depth compared").data;
    let (x, y) = (i % w, i / w);
    let here = z[i] as f64;
    let mut step = 0f64;
    for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
        let (nx, ny) = (x as i64 + dx, y as i64 + dy);
        if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
            continue;
        }
        let n = z[ny as usize * w + nx as usize] as f64;
        if n > 0.0 && n.is_finite() && here > 0.0 {
            step = step.max((n - here).abs() / n.max(here));
        }
    }
    step
}

/// Every pass at `sizes` under every convention against the GL defaults; a list of failures.
fn sweep(device: &Device, sizes: &[(u32, u32)], cases: &[PassCase], kind: FrameDepth) -> Vec<String> {
    let mut failures = Vec::new();
    for &(w, h) in sizes {
        let inputs: Vec<PassInputs> = Conventions::all()
            .into_iter()
            .map(|c| PassInputs::with_depth(w, h, c, kind).unwrap())
            .collect();
        for case in cases {
            let mut base: Option<Vec<ViewOutput>> = None;
            // The largest differences from the GL defaults over every convention and view, printed
            // (`--nocapture`) so a change's effect is measured, not only passed.
            let (mut colour_worst, mut depth_worst) = (0, 0f64);
            for inp in &inputs {
                let views = case.frame(device, inp).unwrap()().unwrap();
                if *case == PassCase::Scene {
                    let cracks = cracks(&views[0]);
                    if !cracks.is_empty() {
                        failures.push(format!(
                            "{w}x{h} scene {}: {} pixels without a surface between two with one, first {:?}",
                            inp.conv.label(),
                            cracks.len(),
                            cracks[0]
                        ));
                    }
                }
                let Some(b) = &base else {
                    base = Some(views);
                    continue;
                };
                for (k, (v, bv)) in views.iter().zip(b).enumerate() {
                    let d = diff(v, bv, depth_bound(case), picks_between_samples(case, kind));
                    colour_worst = colour_worst.max(d.colour_worst);
                    depth_worst = depth_worst.max(d.depth_worst);
                    if d.coverage + d.colour + d.depth > 0 {
                        let (i, what) = d.first.unwrap();
                        failures.push(format!(
                            "{w}x{h} {kind:?} {} view {k} {}: {} coverage, {} colour > 1 (worst {}), {} depth beyond \
                             {:.1e} (worst {:.1e}); first {what} at ({}, {})",
                            case.name(),
                            inp.conv.label(),
                            d.coverage,
                            d.colour,
                            d.colour_worst,
                            d.depth,
                            depth_bound(case),
                            d.depth_worst,
                            i % v.width as usize,
                            i / v.width as usize
                        ));
                    }
                }
            }
            println!(
                "{w}x{h} {kind:?} {}: worst over conventions: colour {colour_worst} levels, depth {depth_worst:.1e} relative",
                case.name()
            );
        }
    }
    failures
}

/// Every pass but the matcher; `VIEWSYNTH_SWEEP_PASS=<substring of the row name>` narrows the
/// sweep while investigating one pass.
fn cases() -> Vec<PassCase> {
    let only = std::env::var("VIEWSYNTH_SWEEP_PASS").unwrap_or_default();
    PassCase::all()
        .into_iter()
        .filter(|c| *c != PassCase::Matcher && only.split(',').any(|o| c.name().contains(o)))
        .collect()
}

fn run_sweep(device: &Device, what: &str) {
    let t0 = std::time::Instant::now();
    // The two largest sizes run the passes whose cost is per output pixel and cheap on llvmpipe
    // (scene, refocus fullscreen, reproject, cyclopean seed); the rest run at every other size.
    let (small, large) = SIZES.split_at(SIZES.len() - 2);
    let kind = match std::env::var("VIEWSYNTH_SWEEP_DEPTH").as_deref() {
        Ok("device") => FrameDepth::Device,
        _ => FrameDepth::ViewZ,
    };
    let mut failures = sweep(device, small, &cases(), kind);
    let cheap: Vec<PassCase> = cases()
        .into_iter()
        .filter(|c| {
            matches!(
                c,
                PassCase::Scene | PassCase::Refocus(viewsynth::refocus::Method::Fullscreen) | PassCase::Reproject(_)
            ) || *c == (PassCase::Cyclopean { steps: 0 })
        })
        .collect();
    failures.extend(sweep(device, large, &cheap, kind));
    println!("{what}: convention sweep in {:.1} s", t0.elapsed().as_secs_f64());
    assert!(
        failures.is_empty(),
        "{what}: {} views depend on the conventions:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn every_pass_gives_the_same_view_under_every_convention_at_every_size_on_gl() {
    run_sweep(&Device::gl(&gpu()).unwrap(), "GL");
}

#[test]
#[cfg(feature = "vulkan")]
fn every_pass_gives_the_same_view_under_every_convention_at_every_size_on_vulkan() {
    let v = viewsynth_tests::vulkan();
    run_sweep(&viewsynth::vulkan::VkExecutor::device(&v).unwrap(), "Vulkan");
}
