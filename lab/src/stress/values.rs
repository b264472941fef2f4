//! Value sweeps over the whole f32/f64 range, for every GPU capability: depth values from the
//! smallest subnormal to `f32::MAX` (and negative), focal lengths from subnormal to 1e300. Each
//! value goes in two ways:
//!
//! - *as a loader gives it*: after [`clear_unusable_depth`] (values outside [1e-6, 1e6] are
//!   holes), run on the GPU and by the f64 twin through the pass contract (`<capability>::pass`);
//! - *raw*, as a library caller could build it: the pass's input check must refuse an unusable
//!   value on both sides alike ([`viewsynth::depth::check_usable_depth`]), never run it.
//!
//! The rule enforced: a pixel is valid only if its outputs are finite, on the GPU and in the
//! twin, so the NaN/Inf column counts valid pixels with a non-finite depth (0 to pass), and a
//! row fails on runs where the GPU and the twin disagree on refusing. Where both ran, the
//! GPU-vs-twin errors are held to [`TOL`].

use super::{GpuPixels, RefPixels, StressOptions, StressRow, Tally, Tolerance};
use viewsynth::convention::Conventions;
use viewsynth::cyclopean::forward::ForwardWarp;
use viewsynth::cyclopean::splat::SplatParams;
use viewsynth::cyclopean::{self, CyclopeanInput, CyclopeanPass};
use viewsynth::depth::clear_unusable_depth;
use viewsynth::error::Result;
use viewsynth::io::DepthMap;
use viewsynth::pass::Device;
use viewsynth::refocus::{self, BreakRule, Method, OutputSet, RefocusInput, RefocusSource};
use viewsynth::reproject::{self, ReprojectInput};
use viewsynth::stereo::gather::{CyclopeanOutputs, CyclopeanParams};
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;
use viewsynth::stitch::{self, faces::scene_faces, OdsRig, Side, StitchInput, StitchParams};
use viewsynth::view::ViewOutput;

/// Depth values swept: subnormals, the f32 normal range's ends, the usable range's edges.
pub const DEPTH_VALUES: [f32; 16] = [
    1e-45,
    1e-40,
    f32::MIN_POSITIVE,
    1e-30,
    1e-7,
    1e-6,
    1e-3,
    1.0,
    1e3,
    1e6,
    1.5e6,
    1e20,
    1e38,
    f32::MAX,
    -1e-40,
    -1e38,
];

/// Source focal lengths swept (px): subnormal and huge ones are refused, the bounds run.
pub const FOCAL_VALUES: [f64; 7] = [5e-324, 1e-40, 1e-3, 1.0, 1e3, 1e6, 1e300];

/// GPU against twin where both ran: 1e-3 relative depth (surfaces 1e12 apart in one frame are not
/// a precision case: the precision rows bound that), and at most 2 % of pixels decided apart or
/// a colour level off (the planted values make an edge at every third pixel).
const TOL: Tolerance = Tolerance::new(1e-3, 0.02, 0.02);

/// The counts of one sweep row.
#[derive(Default)]
struct Sweep {
    tally: Tally,
    /// Valid pixels with a non-finite depth, GPU and twin together.
    valid_non_finite: usize,
    /// Runs the GPU and the twin answered differently (one refused, the other ran).
    split: usize,
    /// Raw unusable inputs that a side accepted (must be refused).
    accepted_raw: usize,
    /// Runs refused on both sides alike (raw unusable values, out-of-range focal lengths).
    refused: usize,
    runs: usize,
    first_bad: Option<String>,
}

impl Sweep {
    fn bad(&mut self, what: String) {
        self.first_bad.get_or_insert(what);
    }

    /// A raw input with an unusable value: both sides must refuse it.
    fn refuse(&mut self, tag: &str, gpu: Result<ViewOutput>, twin: Result<ViewOutput>) {
        self.runs += 1;
        match (gpu.is_err(), twin.is_err()) {
            (true, true) => self.refused += 1,
            _ => {
                self.accepted_raw += 1;
                self.bad(format!("{tag}: accepted raw"));
            }
        }
    }

    /// Both sides of one run: refused alike, or run and compared.
    fn compare(&mut self, tag: &str, gpu: Result<ViewOutput>, twin: Result<ViewOutput>) {
        self.runs += 1;
        let (g, t) = match (gpu, twin) {
            (Ok(g), Ok(t)) => (g, t),
            (Err(_), Err(_)) => {
                self.refused += 1;
                return;
            }
            _ => {
                self.split += 1;
                self.bad(format!("{tag}: GPU and twin disagree on refusing"));
                return;
            }
        };
        for v in [&g, &t] {
            let bad = valid_non_finite(v);
            if bad > 0 {
                self.valid_non_finite += bad;
                self.bad(format!("{tag}: {bad} valid pixels not finite"));
            }
        }
        let n = g.width as usize * g.height as usize;
        let all = vec![true; n];
        let (Some(gc), Some(exact)) = (&g.color, &t.exact) else {
            return;
        };
        self.tally.add(
            tag,
            &GpuPixels {
                valid: g.valid().unwrap_or_else(|| all.clone()),
                class: None,
                depth: g.depth.as_ref().map(|d| d.data.as_slice()),
                rgb: &gc.data,
            },
            &RefPixels {
                valid: t.valid().unwrap_or(all),
                class: None,
                ties: None,
                depth: exact.depth.as_deref(),
                rgb: &exact.color,
            },
            &TOL,
        );
    }

    fn row(self, capability: &'static str, case: &str) -> StressRow {
        let problems = self.valid_non_finite + self.split + self.accepted_raw;
        let mut row = StressRow::from_tally(capability, case, self.tally, TOL, "");
        row.non_finite += self.valid_non_finite;
        row.pass = row.pass && problems == 0;
        row.note = format!(
            "value sweep, {} runs ({} refused on both sides); 0 NaN/Inf where valid (GPU and twin), \
             same refusals{}",
            self.runs,
            self.refused,
            self.first_bad
                .map_or(String::new(), |b| format!("; first problem: {b}"))
        );
        row
    }
}

/// Valid pixels (mask nonzero) whose depth is not finite.
fn valid_non_finite(v: &ViewOutput) -> usize {
    match (&v.depth, &v.mask) {
        (Some(d), Some(m)) => d
            .data
            .iter()
            .zip(&m.data)
            .filter(|(z, m)| **m != 0 && !z.is_finite())
            .count(),
        (Some(d), None) => d.data.iter().filter(|z| !z.is_finite()).count(),
        _ => 0,
    }
}

/// `v` in every third pixel of `depth` (the rest keeps the scene); `cleared` applies the loaders' rule.
fn planted(depth: &DepthMap, v: f32, cleared: bool) -> DepthMap {
    let mut d = depth.clone();
    d.data.iter_mut().step_by(3).for_each(|z| *z = v);
    if cleared {
        clear_unusable_depth(&mut d.data);
    }
    d
}

fn usable(v: f32) -> bool {
    viewsynth::depth::usable_depth_value(v)
}

/// The values of a sweep (every third one in quick mode, keeping both ends).
fn values<T: Copy>(all: &[T], quick: bool) -> Vec<T> {
    all.iter()
        .enumerate()
        .filter(|(i, _)| !quick || i % 3 == 0 || *i == all.len() - 1)
        .map(|(_, v)| *v)
        .collect()
}

fn refocus_rows(device: &Device, opts: StressOptions) -> Result<Vec<StressRow>> {
    let cam = viewsynth::world::demo_camera(32, 24);
    let (rgb, depth) = viewsynth::world::render(&cam);
    let conv = Conventions::default();
    let mut depth_sweep = Sweep::default();
    let mut focal_sweep = Sweep::default();
    let run = |s: &mut Sweep, tag: &str, src: &RefocusSource, target: &viewsynth::camera::PinholeCamera, raw: bool| {
        for method in [Method::Fullscreen, Method::Mesh] {
            let input = RefocusInput {
                source: src,
                target,
                rule: BreakRule::default(),
                method,
                outputs: OutputSet::default(),
                rgb_everywhere: false,
                conv,
            };
            let tag = format!("{tag} {method:?}");
            let (g, t) = (refocus::pass::gpu(device, &input), refocus::pass::reference(&input));
            if raw {
                s.refuse(&tag, g, t);
            } else {
                s.compare(&tag, g, t);
            }
        }
    };
    for v in values(&DEPTH_VALUES, opts.quick) {
        for cleared in [true, false].into_iter().filter(|c| *c || !usable(v)) {
            // Built field by field: the pass's own check is what is swept.
            let src = RefocusSource {
                rgb: rgb.clone(),
                depth: planted(&depth, v, cleared),
                k: cam.k,
            };
            for scale in [1e-3 / cam.k.fx, 0.5, 2.0, 1e6 / cam.k.fx] {
                let mut target = src.camera();
                target.k.fx *= scale;
                target.k.fy *= scale;
                run(
                    &mut depth_sweep,
                    &format!("depth {v:e} scale {scale:e}"),
                    &src,
                    &target,
                    !cleared,
                );
            }
        }
    }
    for f in values(&FOCAL_VALUES, opts.quick) {
        let mut k = cam.k;
        (k.fx, k.fy) = (f, f);
        let src = RefocusSource {
            rgb: rgb.clone(),
            depth: depth.clone(),
            k,
        };
        // Source and target at f: refused on both sides outside [1e-3, 1e6], run inside.
        let target = src.camera();
        run(&mut focal_sweep, &format!("source fx=fy {f:e}"), &src, &target, false);
        let demo = RefocusSource {
            rgb: rgb.clone(),
            depth: depth.clone(),
            k: cam.k,
        };
        let mut target = demo.camera();
        (target.k.fx, target.k.fy) = (f, f);
        run(&mut focal_sweep, &format!("target fx=fy {f:e}"), &demo, &target, false);
    }
    Ok(vec![
        depth_sweep.row(
            "refocus",
            "value sweep: depth 1e-45 .. f32::MAX, target focal 1e-3 .. 1e6 px",
        ),
        focal_sweep.row("refocus", "value sweep: source/target focal 5e-324 .. 1e300 px"),
    ])
}

/// A cyclopean pass as the table names it.
fn pass_label(pass: &CyclopeanPass) -> &'static str {
    match pass {
        CyclopeanPass::Gather(p) if p.method == viewsynth::stereo::gather::Method::Seed => "seed",
        CyclopeanPass::Gather(_) => "refine",
        CyclopeanPass::Splat(_) => "splat-gather",
    }
}

fn cyclopean_rows(device: &Device, opts: StressOptions) -> Result<Vec<StressRow>> {
    let conv = Conventions::default();
    let mut rows = Vec::new();
    for kind in [FrameDepth::ViewZ, FrameDepth::Device] {
        let (frame0, mid, _) = scene_frame(&StereoRig::demo(32, 24), conv, kind);
        let passes = [
            CyclopeanPass::Gather(CyclopeanParams::seed(3.0)),
            CyclopeanPass::Gather(CyclopeanParams {
                method: viewsynth::stereo::gather::Method::Refine { steps: 4 },
                ..CyclopeanParams::seed(3.0)
            }),
            CyclopeanPass::Splat(SplatParams::default()),
        ];
        let mut s = Sweep::default();
        for v in values(&DEPTH_VALUES, opts.quick) {
            for cleared in [true, false].into_iter().filter(|c| *c || !usable(v)) {
                let mut frame = frame0.clone();
                frame.left.depth = planted(&frame.left.depth, v, cleared);
                frame.right.depth = planted(&frame.right.depth, v, cleared);
                for pass in passes {
                    let input = CyclopeanInput {
                        frame: &frame,
                        mid: &mid,
                        pass,
                        outputs: CyclopeanOutputs::default(),
                    };
                    let tag = format!("{kind:?} depth {v:e} {}", pass_label(&pass));
                    let (g, t) = (cyclopean::pass::gpu(device, &input), cyclopean::pass::reference(&input));
                    if cleared {
                        s.compare(&tag, g, t);
                    } else {
                        s.refuse(&tag, g, t);
                    }
                }
                // The forward warp has no f64 twin: its own output is held to the rule.
                let fwd = ForwardWarp::new(device, &frame, &BreakRule::default())
                    .and_then(|mut f| f.render(&mid))
                    .map(|(o, _)| ViewOutput::from_cyclopean(&o, mid.width, mid.height, None));
                let tag = format!("{kind:?} depth {v:e} forward");
                s.runs += 1;
                match (fwd, cleared) {
                    (Ok(view), true) => {
                        let bad = valid_non_finite(&view);
                        s.valid_non_finite += bad;
                        if bad > 0 {
                            s.bad(format!("{tag}: {bad} valid pixels not finite"));
                        }
                    }
                    (Err(_), false) => s.refused += 1,
                    (Ok(_), false) => {
                        s.accepted_raw += 1;
                        s.bad(format!("{tag}: accepted raw"));
                    }
                    (Err(e), true) => {
                        s.split += 1;
                        s.bad(format!("{tag}: {e}"));
                    }
                }
            }
        }
        rows.push(s.row(
            "cyclopean",
            &format!("value sweep: {kind:?} depth 1e-45 .. f32::MAX (seed, refine, splat-gather, forward)"),
        ));
    }
    Ok(rows)
}

fn reproject_rows(device: &Device, opts: StressOptions) -> Result<Vec<StressRow>> {
    let conv = Conventions::default();
    let mut rows = Vec::new();
    for kind in [FrameDepth::ViewZ, FrameDepth::Device] {
        let cases = crate::eval::reproject::scene_cases(32, 24, 0.2, conv, kind)?;
        let case = &cases[0];
        let mut s = Sweep::default();
        for v in values(&DEPTH_VALUES, opts.quick) {
            for cleared in [true, false].into_iter().filter(|c| *c || !usable(v)) {
                let mut source = case.source.clone();
                source.depth = planted(&source.depth, v, cleared);
                for params in crate::eval::reproject::methods() {
                    let input = ReprojectInput {
                        source: &source,
                        geometry: &case.geometry,
                        params,
                    };
                    let tag = format!("{kind:?} depth {v:e} {}", params.method.label());
                    let (g, t) = (reproject::pass::gpu(device, &input), reproject::pass::reference(&input));
                    if cleared {
                        s.compare(&tag, g, t);
                    } else {
                        s.refuse(&tag, g, t);
                    }
                }
            }
        }
        rows.push(s.row(
            "reproject",
            &format!("value sweep: {kind:?} depth 1e-45 .. f32::MAX (shift, shift-scan, gather3d)"),
        ));
    }
    Ok(rows)
}

fn stitch_rows(device: &Device, opts: StressOptions) -> Result<Vec<StressRow>> {
    let rig = OdsRig::demo();
    let (l0, r0) = (
        scene_faces(&rig, Side::Left, 8, 100.0)?,
        scene_faces(&rig, Side::Right, 8, 100.0)?,
    );
    let mut s = Sweep::default();
    for v in values(&DEPTH_VALUES, opts.quick) {
        for cleared in [true, false].into_iter().filter(|c| *c || !usable(v)) {
            let mut l = l0.clone();
            for face in &mut l.faces {
                face.depth = planted(&face.depth, v, cleared);
            }
            for method in stitch::Method::ALL {
                let input = StitchInput {
                    left: &l,
                    right: &r0,
                    params: StitchParams {
                        method,
                        overlap_deg: 5.0,
                        width: 32,
                        height: 16,
                    },
                    outputs: OutputSet::RGB,
                    conv: Conventions::default(),
                };
                let tag = format!("depth {v:e} {}", method.label());
                let (g, t) = (stitch::pass::gpu(device, &input), stitch::pass::reference(&input));
                if cleared {
                    s.compare(&tag, g, t);
                } else {
                    s.refuse(&tag, g, t);
                }
            }
        }
    }
    Ok(vec![s.row(
        "stitch",
        "value sweep: face depth 1e-45 .. f32::MAX (3 methods)",
    )])
}

/// The value-sweep rows of `capability` (none for `camera`, whose sweeps are its own rows).
pub fn rows(device: &Device, capability: &str, opts: StressOptions) -> Result<Vec<StressRow>> {
    match capability {
        "refocus" => refocus_rows(device, opts),
        "cyclopean" => cyclopean_rows(device, opts),
        "reproject" => reproject_rows(device, opts),
        "stitch" => stitch_rows(device, opts),
        _ => Ok(Vec::new()),
    }
}
