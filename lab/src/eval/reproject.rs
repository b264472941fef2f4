//! Report rows for `viewsynth report` and the data set-ups the tests share: the built-in scene
//! (left eye or ray-traced centre view -> right eye, exact truth) and the Middlebury pairs.

use crate::report::ReportRow;
use std::path::Path;
use viewsynth::camera::stereo::Eye;
use viewsynth::camera::{Intrinsics, PinholeCamera};
use viewsynth::convention::Conventions;
use viewsynth::depth::DepthEncoding;
use viewsynth::error::Result;
use viewsynth::io::{self, DepthDecode, DepthMap, RgbImage};
use viewsynth::metrics;
use viewsynth::pass::{Device, Timing};
use viewsynth::reproject::render::Reprojector;
use viewsynth::reproject::{Geometry, Method, ReprojectOutput, ReprojectParams, ReprojectSource, ShiftModel};
use viewsynth::ssim;
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;

/// The methods compared.
pub fn methods() -> Vec<ReprojectParams> {
    [
        Method::Shift { steps: 3 },
        Method::ShiftScan,
        Method::Gather3d { steps: 3 },
    ]
    .into_iter()
    .map(ReprojectParams::new)
    .collect()
}

/// A reprojection case with its truth (colour, and depth where known: 0 = no surface).
pub struct Case {
    /// Report name of the case, e.g. "left -> right (Device depth)".
    pub name: String,
    /// The source view and its depth.
    pub source: ReprojectSource,
    /// Source and target cameras of the rig.
    pub geometry: Geometry,
    /// True colour of the target view.
    pub truth: RgbImage,
    /// True target depth (0 = no surface); None where unknown (Middlebury).
    pub truth_depth: Option<DepthMap>,
}

/// Built-in scene on a parallel rig (`ipd` apart): left eye -> right eye with the given depth
/// kind, the ray-traced centre view (view Z) -> right eye, and the seed's converged form.
pub fn scene_cases(width: u32, height: u32, ipd: f64, conv: Conventions, kind: FrameDepth) -> Result<Vec<Case>> {
    let mut rig = StereoRig::demo(width, height);
    rig.ipd = ipd;
    let (frame, _, mid_truth) = scene_frame(&rig, conv, kind);
    let right = viewsynth::world::render_posed(&rig.camera, &rig.eye_pose(1.0));
    let depth_kind = DepthEncoding::with_planes(kind.into(), rig.planes)?;
    let fx = rig.camera.k.fx;
    Ok(vec![
        Case {
            name: format!("left -> right ({kind:?} depth)"),
            source: ReprojectSource {
                color: frame.left.color,
                depth: frame.left.depth,
                depth_kind,
                conv,
            },
            geometry: Geometry::Rig {
                camera: rig.camera,
                shift: ShiftModel::rectified(fx, ipd, 0.0, Some(Eye::Left), Some(Eye::Right))?,
            },
            truth: right.0.clone(),
            truth_depth: Some(right.1.clone()),
        },
        Case {
            name: "centre -> right (view Z)".to_string(),
            source: ReprojectSource {
                color: mid_truth.color,
                depth: mid_truth.depth,
                depth_kind: DepthEncoding::ViewZ,
                conv,
            },
            geometry: Geometry::Rig {
                camera: rig.camera,
                shift: ShiftModel::rectified(fx, ipd, 0.0, None, Some(Eye::Right))?,
            },
            truth: right.0,
            truth_depth: Some(right.1),
        },
        seed_case(&rig, conv)?,
    ])
}

/// Seed 004's converged form: the centre view -> right eye with separation S and convergence
/// c = 3 m chosen so the interaxial is the rig's ipd (S = ipd fx / (W c)). The right eye is then
/// the centre camera moved ipd / 2 along x with its image shifted by W S / 2 (cx + a): ray
/// traced as such for the truth.
fn seed_case(rig: &StereoRig, conv: Conventions) -> Result<Case> {
    let cam = rig.camera;
    let convergence = 3.0;
    let separation = rig.ipd * cam.k.fx / (cam.width as f64 * convergence);
    let params = viewsynth::camera::stereo::StereoParams::new(separation, convergence)?;
    let shift = ShiftModel::seed(&params, cam.width, None, Some(Eye::Right));
    let (color, depth) = viewsynth::world::render_posed(&cam, &rig.head);
    let mut target = cam;
    target.k.cx += shift.a_px;
    let right =
        viewsynth::world::render_posed(&target, &viewsynth::camera::Pose::at([shift.b_px / cam.k.fx, 0.0, 0.0]));
    Ok(Case {
        name: format!("centre -> right (seed S = {separation:.4}, c = {convergence} m)"),
        source: ReprojectSource {
            color,
            depth,
            depth_kind: DepthEncoding::ViewZ,
            conv,
        },
        geometry: Geometry::Rig { camera: cam, shift },
        truth: right.0,
        truth_depth: Some(right.1),
    })
}

/// Calibration of the Middlebury 2014 Motorcycle copy (4x down), from the data README:
/// focal length and principal point (px), baseline (m), doffs (px).
pub struct MotorcycleCalibration;

impl MotorcycleCalibration {
    /// Focal length, px.
    pub const FOCAL_PX: f64 = 994.978;
    /// Baseline, m.
    pub const BASELINE_M: f64 = 0.193001;
    /// Right principal point x minus the left one, px.
    pub const DOFFS_PX: f64 = 31.086;
    /// Principal point, px.
    pub const PRINCIPAL_POINT: [f64; 2] = [311.193, 254.877];
}

/// Middlebury 2014 Motorcycle (scikit-image copy, 4x down): left + left disparity -> right,
/// with the calibration of the data README (f, cx, cy, doffs in px; baseline in m).
pub fn motorcycle_case(data_dir: &Path, conv: Conventions) -> Result<Case> {
    let dir = data_dir.join("middlebury2014_motorcycle_skimage");
    let left = io::load_rgb(&dir.join("motorcycle_left.png"))?;
    let truth = io::load_rgb(&dir.join("motorcycle_right.png"))?;
    // +inf (invalid) stays as stored: float depth is not rescaled without a scale.
    let disparity = io::load_depth(&dir.join("motorcycle_disp.npz"), &DepthDecode::default())?;
    type C = MotorcycleCalibration;
    let (f, baseline, doffs) = (C::FOCAL_PX, C::BASELINE_M, C::DOFFS_PX);
    let camera = PinholeCamera {
        k: Intrinsics {
            fx: f,
            fy: f,
            cx: C::PRINCIPAL_POINT[0],
            cy: C::PRINCIPAL_POINT[1],
        },
        width: left.width,
        height: left.height,
    };
    Ok(Case {
        name: "Middlebury 2014 Motorcycle (left + disp -> right)".into(),
        source: ReprojectSource {
            color: left,
            depth: disparity,
            depth_kind: DepthEncoding::Disparity {
                focal_px: f,
                baseline,
                doffs,
            },
            conv,
        },
        geometry: Geometry::Rig {
            camera,
            shift: ShiftModel::rectified(f, baseline, doffs, Some(Eye::Left), Some(Eye::Right))?,
        },
        truth,
        truth_depth: None,
    })
}

/// Middlebury 2003 Teddy: im2 + disp2 (value / 4, 0 unknown) -> im6, with the nominal
/// f = 400 px, B = 0.1 m, doffs 0 of `cyclopean::disparity_frame` (only f B matters).
pub fn teddy_case(data_dir: &Path, conv: Conventions) -> Result<Case> {
    let dir = data_dir.join("middlebury2003_teddy");
    let left = io::load_rgb(&dir.join("im2.png"))?;
    let truth = io::load_rgb(&dir.join("im6.png"))?;
    let disparity = io::load_depth(
        &dir.join("disp2.pgm"),
        &DepthDecode {
            scale: Some(4.0),
            ..Default::default()
        },
    )?;
    let (f, baseline) = (400.0, 0.1);
    let camera = PinholeCamera {
        k: Intrinsics {
            fx: f,
            fy: f,
            cx: (left.width as f64 - 1.0) / 2.0,
            cy: (left.height as f64 - 1.0) / 2.0,
        },
        width: left.width,
        height: left.height,
    };
    Ok(Case {
        name: "Middlebury 2003 Teddy (im2 + disp2 -> im6)".into(),
        source: ReprojectSource {
            color: left,
            depth: disparity,
            depth_kind: DepthEncoding::Disparity {
                focal_px: f,
                baseline,
                doffs: 0.0,
            },
            conv,
        },
        geometry: Geometry::Rig {
            camera,
            shift: ShiftModel::rectified(f, baseline, 0.0, Some(Eye::Left), Some(Eye::Right))?,
        },
        truth,
        truth_depth: None,
    })
}

/// Scores of one output against a case's truth.
#[derive(Debug, Clone, Copy)]
pub struct Score {
    /// PSNR (dB) on pixels valid in the output and (where truth depth is known) in the truth.
    pub psnr_db: f64,
    /// Fraction of all pixels the method marks valid.
    pub coverage: f64,
    /// Fraction of pixels scored.
    pub scored: f64,
    /// Luma SSIM against the truth over the scored pixels; None where no window fits.
    pub ssim: Option<f64>,
    /// Mean relative depth error on scored pixels with truth depth.
    pub depth_rel_mean: Option<f64>,
}

/// Scores of an output against its case's truth; needs the colour (and depth where the case
/// has a true depth).
pub fn score(out: &ReprojectOutput, case: &Case) -> Result<Score> {
    let color = out
        .color
        .as_ref()
        .ok_or_else(|| viewsynth::Error::param("outputs", "scoring needs the colour output"))?;
    let depth = match (&case.truth_depth, &out.depth) {
        (Some(_), None) => return Err(viewsynth::Error::param("outputs", "scoring needs the depth output")),
        (_, d) => d.as_ref(),
    };
    let mask: Vec<bool> = out
        .mask
        .iter()
        .enumerate()
        .map(|(i, m)| *m != 0 && case.truth_depth.as_ref().is_none_or(|t| t.data[i] > 0.0))
        .collect();
    let (mut sq, mut n, mut drel, mut nz) = (0.0, 0usize, 0.0, 0usize);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        n += 1;
        for c in 0..3 {
            let d = color.data[i * 3 + c] as f64 - case.truth.data[i * 3 + c] as f64;
            sq += d * d;
        }
        if let (Some(t), Some(z)) = (&case.truth_depth, depth) {
            let (z, t) = (z.data[i] as f64, t.data[i] as f64);
            drel += (z - t).abs() / t;
            nz += 1;
        }
    }
    let total = mask.len().max(1) as f64;
    Ok(Score {
        psnr_db: metrics::psnr_from_mse(sq / (3 * n.max(1)) as f64),
        coverage: out.coverage(),
        scored: n as f64 / total,
        ssim: ssim::ssim_rgb(&color.data, &case.truth.data, color.width, color.height, Some(&mask)),
        depth_rel_mean: (nz > 0).then(|| drel / nz as f64),
    })
}

/// Median of `repeats` runs after one warm-up (shader JIT, allocations).
pub fn run_timed(
    device: &Device,
    case: &Case,
    params: ReprojectParams,
    repeats: usize,
) -> Result<(ReprojectOutput, Timing)> {
    let mut r = Reprojector::new(device, &case.source, &case.geometry, params)?;
    r.render()?;
    let mut runs = Vec::new();
    for _ in 0..repeats.max(1) {
        runs.push(r.render()?);
    }
    runs.sort_by(|a, b| a.1.wall_ms.total_cmp(&b.1.wall_ms));
    Ok(runs.swap_remove(runs.len() / 2))
}

fn row(
    case: &Case,
    scene: &str,
    params: ReprojectParams,
    out: &ReprojectOutput,
    t: Timing,
) -> Result<(ReportRow, Score)> {
    let s = score(out, case)?;
    let mut r = ReportRow::new("reproject", scene, params.method.label(), case.name.clone(), t.wall_ms);
    r.gpu_ms = t.gpu_ms;
    r.psnr_db = Some(s.psnr_db);
    r.ssim = s.ssim;
    r.coverage = Some(s.coverage);
    r.depth_rel_mean = s.depth_rel_mean;
    Ok((r, s))
}

/// The general mesh warp of the foundation (the cyclopean forward warp with the source as the
/// only eye and the target as the middle camera), for comparison with the shift methods.
pub fn mesh_warp_timed(device: &Device, case: &Case, repeats: usize) -> Result<(ReprojectOutput, Timing)> {
    let (frame, target) = viewsynth::reproject::one_eye_frame(&case.source, &case.geometry)?;
    let mut warp =
        viewsynth::cyclopean::forward::ForwardWarp::new(device, &frame, &viewsynth::refocus::BreakRule::default())?;
    warp.render(&target)?; // warm-up
    let mut runs = Vec::new();
    for _ in 0..repeats.max(1) {
        runs.push(warp.render(&target)?);
    }
    runs.sort_by(|a, b| a.1.wall_ms.total_cmp(&b.1.wall_ms));
    let (out, t) = runs.swap_remove(runs.len() / 2);
    let mask = out.sources.iter().map(|s| if *s != 0 { 255 } else { 0 }).collect();
    Ok((
        ReprojectOutput {
            color: out.color,
            depth: out.depth,
            mask,
        },
        t,
    ))
}

fn mesh_row(case: &Case, scene: &str, out: &ReprojectOutput, t: Timing) -> Result<(ReportRow, Score)> {
    let s = score(out, case)?;
    let mut r = ReportRow::new(
        "reproject",
        scene,
        "mesh warp (source depth mesh rasterised)",
        case.name.clone(),
        t.wall_ms,
    );
    r.gpu_ms = t.gpu_ms;
    r.psnr_db = Some(s.psnr_db);
    r.ssim = s.ssim;
    r.coverage = Some(s.coverage);
    r.depth_rel_mean = s.depth_rel_mean;
    Ok((r, s))
}

/// Rows for `viewsynth report`: the built-in scene at 640x480 (64 mm and 200 mm baselines, left
/// eye with device depth and centre view -> right eye, against the ray-traced right eye), and,
/// with `data_dir`, Middlebury 2014 Motorcycle and 2003 Teddy against their real right views.
pub fn reproject_rows(
    device: &Device,
    data_dir: Option<&Path>,
    repeats: usize,
) -> Result<(Vec<ReportRow>, Vec<String>)> {
    let mut rows = Vec::new();
    let mut notes = vec![
        "reproject: shift walk k = k fixed-point steps along the row from the zero-parallax guess and from the near bound, verified by segment coverage; shift scan = every segment the depth range allows, nearest wins; 3-D gather k = the cyclopean k-step walk with one eye. Disocclusions stay invalid; PSNR on pixels valid in the output (and with a surface in the truth for the built-in scene).".to_string(),
    ];
    let conv = Conventions::default();
    for ipd in [0.064, 0.2] {
        for case in scene_cases(640, 480, ipd, conv, FrameDepth::Device)? {
            for params in methods() {
                let (out, t) = run_timed(device, &case, params, repeats)?;
                let (mut r, _) = row(&case, "builtin:demo 640x480", params, &out, t)?;
                r.setting = format!("{}, ipd {:.0} mm", case.name, ipd * 1e3);
                rows.push(r);
            }
            let (out, t) = mesh_warp_timed(device, &case, repeats)?;
            let (mut r, _) = mesh_row(&case, "builtin:demo 640x480", &out, t)?;
            r.setting = format!("{}, ipd {:.0} mm", case.name, ipd * 1e3);
            rows.push(r);
        }
    }
    if let Some(dir) = data_dir {
        type MakeCase = fn(&Path, Conventions) -> Result<Case>;
        let sets: [(&str, MakeCase); 2] = [
            ("middlebury2014_motorcycle_skimage", motorcycle_case),
            ("middlebury2003_teddy", teddy_case),
        ];
        for (set, make) in sets {
            // Sets absent from the folder are skipped (and said so), not failed on.
            if !dir.join(set).is_dir() {
                notes.push(format!("reproject on {set} skipped: not in {}", dir.display()));
                continue;
            }
            let case = make(dir, conv)?;
            for params in methods() {
                let (out, t) = run_timed(device, &case, params, repeats)?;
                let (mut r, s) = row(&case, &case.name, params, &out, t)?;
                r.setting = "PSNR vs the real right view on pixels marked valid".into();
                notes.push(format!(
                    "{}, {}: PSNR {:.2} dB on the {:.1} % of pixels marked valid, {:.1} ms",
                    case.name,
                    params.method.label(),
                    s.psnr_db,
                    s.coverage * 100.0,
                    t.wall_ms
                ));
                rows.push(r);
            }
            let (out, t) = mesh_warp_timed(device, &case, repeats)?;
            let (mut r, s) = mesh_row(&case, &case.name, &out, t)?;
            r.setting = "PSNR vs the real right view on pixels marked valid".into();
            notes.push(format!(
                "{}, mesh warp: PSNR {:.2} dB on the {:.1} % of pixels marked valid, {:.1} ms",
                case.name,
                s.psnr_db,
                s.coverage * 100.0,
                t.wall_ms
            ));
            rows.push(r);
        }
    }
    Ok((rows, notes))
}
