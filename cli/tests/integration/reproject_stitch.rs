//! `viewsynth reproject` and `viewsynth stitch` end to end: the files asked for, with the sizes
//! and the pixels the library gives for the same inputs; bad input exits 1 naming the file or
//! parameter, without a panic and without output files.

use crate::cli::{assert_clean_failure, bin, files_in, scratch, RUN_ERROR, USAGE};
use crate::common::gpu;
use std::path::{Path, PathBuf};
use std::process::Output;
use viewsynth::camera::stereo::{Eye, StereoParams};
use viewsynth::convention::Conventions;
use viewsynth::io::{self, DepthMap};
use viewsynth::reproject::render::Reprojector;
use viewsynth::reproject::{Geometry, Method, ReprojectOutput, ReprojectParams};
use viewsynth::stereo::FrameDepth;
use viewsynth::stitch::faces::scene_faces;
use viewsynth::stitch::render::StitchRenderer;
use viewsynth::stitch::{Method as StitchMethod, OdsRig, Side, StitchParams};
use viewsynth_lab::eval::reproject::{scene_cases, Case};

const W: u32 = 64;
const H: u32 = 48;
const IPD: f64 = 0.2;

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run viewsynth")
}

fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "stdout: {}\nstderr: {}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 scratch path")
}

/// The built-in scene's case `index` of [`scene_cases`] at W x H, its source written as PNG +
/// EXR in `dir`.
fn case_files(dir: &Path, kind: FrameDepth, index: usize) -> (Case, PathBuf, PathBuf) {
    let case = scene_cases(W, H, IPD, Conventions::default(), kind)
        .unwrap()
        .swap_remove(index);
    let (c, d) = (dir.join("src_rgb.png"), dir.join("src_depth.exr"));
    io::save_rgb(&c, &case.source.color).unwrap();
    io::save_depth_exr(&d, &case.source.depth).unwrap();
    (case, c, d)
}

fn intrinsics(case: &Case) -> Vec<String> {
    let Geometry::Rig { camera, .. } = case.geometry else {
        panic!("scene cases are rigs")
    };
    let k = camera.k;
    // `{}` prints the shortest text that parses back to the same f64.
    [("--fx", k.fx), ("--fy", k.fy), ("--cx", k.cx), ("--cy", k.cy)]
        .iter()
        .flat_map(|(f, v)| [f.to_string(), format!("{v}")])
        .collect()
}

fn library(case: &Case, method: Method) -> ReprojectOutput {
    Reprojector::new(&gpu(), &case.source, &case.geometry, ReprojectParams::new(method))
        .unwrap()
        .render()
        .unwrap()
        .0
}

/// The CLI's files for `eye` equal the library's output pixel for pixel (same GPU, same inputs:
/// PNG and EXR are lossless).
fn assert_files_match(out: &Path, eye: &str, lib: &ReprojectOutput, with_depth: bool) {
    let rgb = io::load_rgb(&out.join(format!("{eye}_rgb.png"))).unwrap();
    assert_eq!((rgb.width, rgb.height), (W, H));
    assert!(
        rgb.data == lib.color.as_ref().unwrap().data,
        "{eye}: colour differs from the library"
    );
    let mask = io::load_mask_png(&out.join(format!("{eye}_mask.png"))).unwrap();
    assert_eq!((mask.width, mask.height), (W, H));
    let want: Vec<u8> = lib.mask.iter().map(|m| (*m != 0) as u8).collect();
    assert!(mask.data == want, "{eye}: mask differs from the library");
    if with_depth {
        let z = io::load_depth(&out.join(format!("{eye}_depth.exr")), &Default::default()).unwrap();
        assert_eq!((z.width, z.height), (W, H));
        assert!(
            z.data == lib.depth.as_ref().unwrap().data,
            "{eye}: depth differs from the library"
        );
    }
}

fn coverage_in(text: &str) -> f64 {
    let at = text.find("coverage ").expect("coverage printed") + "coverage ".len();
    text[at..].split_whitespace().next().unwrap().parse().unwrap()
}

#[test]
fn reproject_left_to_right_from_device_depth_matches_the_library() {
    let d = scratch("rp-device");
    let (case, c, z) = case_files(&d, FrameDepth::Device, 0);
    let out = d.join("out");
    let mut args = vec![
        "reproject".to_string(),
        "--color".into(),
        s(&c).into(),
        "--depth".into(),
        s(&z).into(),
        "--depth-kind".into(),
        "device".into(),
        "--near".into(),
        "0.05".into(),
        "--far".into(),
        "100".into(),
        "--baseline".into(),
        format!("{IPD}"),
        "--out-dir".into(),
        s(&out).into(),
    ];
    args.extend(intrinsics(&case));
    let text = ok(&bin().args(&args).output().unwrap());
    assert_eq!(files_in(&out), ["right_depth.exr", "right_mask.png", "right_rgb.png"]);
    let lib = library(&case, Method::ShiftScan);
    assert_files_match(&out, "right", &lib, true);
    // Measured 89.1 % at 64x48 with a 0.2 m baseline (disocclusions and the left border).
    assert!(lib.coverage() > 0.87, "coverage {}", lib.coverage());
    assert!((coverage_in(&text) - lib.coverage() * 100.0).abs() < 0.01, "{text}");
    assert!(
        text.contains("left -> right (shift scan)") && text.contains("ms wall"),
        "{text}"
    );
}

#[test]
fn reproject_centre_to_both_eyes_on_the_seed_rig() {
    let d = scratch("rp-seed");
    // Case 2: the centre view (view Z) -> right eye with seed 004's S and c = 3 m.
    let (case, c, z) = case_files(&d, FrameDepth::ViewZ, 2);
    let Geometry::Rig { camera, shift } = case.geometry else {
        panic!("rig")
    };
    let separation = IPD * camera.k.fx / (W as f64 * 3.0);
    let p = StereoParams::new(separation, 3.0).unwrap();
    assert_eq!(
        shift,
        viewsynth::reproject::ShiftModel::seed(&p, W, None, Some(Eye::Right))
    );
    let out = d.join("out");
    let mut args: Vec<String> = [
        "reproject",
        "--color",
        s(&c),
        "--depth",
        s(&z),
        "--depth-kind",
        "metric",
        "--from",
        "centre",
        "--to",
        "both",
        "--separation",
        &format!("{separation}"),
        "--convergence",
        "3",
        "--method",
        "shift",
        "--outputs",
        "color,mask",
        "--out-dir",
        s(&out),
    ]
    .iter()
    .map(|a| a.to_string())
    .collect();
    args.extend(intrinsics(&case));
    let text = ok(&bin().args(&args).output().unwrap());
    assert_eq!(
        files_in(&out),
        ["left_mask.png", "left_rgb.png", "right_mask.png", "right_rgb.png"]
    );
    let lib = library(&case, Method::Shift { steps: 3 });
    assert_files_match(&out, "right", &lib, false);
    println!("seed rig, shift walk: coverage {:.4}", lib.coverage());
    assert!(lib.coverage() > 0.95, "coverage {}", lib.coverage());
    let left = Case {
        geometry: Geometry::Rig {
            camera,
            shift: viewsynth::reproject::ShiftModel::seed(&p, W, None, Some(Eye::Left)),
        },
        ..case
    };
    assert_files_match(&out, "left", &library(&left, Method::Shift { steps: 3 }), false);
    assert!(
        text.contains("centre -> left") && text.contains("centre -> right"),
        "{text}"
    );
}

#[test]
fn reproject_from_disparity_agrees_with_view_z() {
    let d = scratch("rp-disp");
    let (case, c, _) = case_files(&d, FrameDepth::ViewZ, 0);
    let Geometry::Rig { camera, .. } = case.geometry else {
        panic!("rig")
    };
    let f = camera.k.fx;
    // Disparity d = f B / Z (doffs 0), 0 = unknown where the scene has no surface.
    let disp: Vec<f32> = case
        .source
        .depth
        .data
        .iter()
        .map(|&z| if z > 0.0 { (f * IPD / z as f64) as f32 } else { 0.0 })
        .collect();
    let dp = d.join("disp.npy");
    io::save_depth_npy(&dp, &DepthMap::new(W, H, disp).unwrap()).unwrap();
    let out = d.join("out");
    let mut args: Vec<String> = [
        "reproject",
        "--rgb",
        s(&c),
        "--depth",
        s(&dp),
        "--depth-kind",
        "disparity",
        "--baseline",
        &format!("{IPD}"),
        "--focal",
        &format!("{f}"),
        "--method",
        "gather3d",
        "--outputs",
        "mask,depth",
        "--depth-format",
        "exr,npy",
        "--out-dir",
        s(&out),
    ]
    .iter()
    .map(|a| a.to_string())
    .collect();
    args.extend(intrinsics(&case));
    ok(&bin().args(&args).output().unwrap());
    assert_eq!(files_in(&out), ["right_depth.exr", "right_depth.npy", "right_mask.png"]);
    let lib = library(&case, Method::Gather3d { steps: 3 });
    let mask = io::load_mask_png(&out.join("right_mask.png")).unwrap();
    let zc = io::load_depth(&out.join("right_depth.npy"), &Default::default()).unwrap();
    let (mut differ, mut worst) = (0, 0f64);
    for i in 0..mask.data.len() {
        if (mask.data[i] != 0) != (lib.mask[i] != 0) {
            differ += 1;
        } else if mask.data[i] != 0 {
            worst = worst.max(
                ((zc.data[i] - lib.depth.as_ref().unwrap().data[i]) / lib.depth.as_ref().unwrap().data[i]).abs() as f64,
            );
        }
    }
    // Disparity -> Z in f32 differs from the stored Z by a few ulp: a rare decision may flip.
    assert!(differ * 200 <= mask.data.len(), "{differ} mask pixels differ");
    assert!(worst < 1e-4, "depth rel {worst}");
    println!("disparity, 3-D gather: coverage {:.4}", lib.coverage());
    assert!(lib.coverage() > 0.87, "coverage {}", lib.coverage());
}

#[test]
fn reproject_bad_input_fails_cleanly() {
    let d = scratch("rp-bad");
    let (case, c, z) = case_files(&d, FrameDepth::ViewZ, 0);
    let k = intrinsics(&case);
    let out = d.join("out");
    let rp = |color: &Path, depth: &Path, extra: &[&str]| -> Output {
        bin()
            .args([
                "reproject",
                "--color",
                s(color),
                "--depth",
                s(depth),
                "--out-dir",
                s(&out),
            ])
            .args(&k)
            .args(extra)
            .output()
            .unwrap()
    };
    let base = ["--baseline", "0.064"];
    let with = |extra: &[&str]| -> Vec<String> { base.iter().chain(extra).map(|a| a.to_string()).collect() };
    let rpx = |extra: &[&str]| {
        let a = with(extra);
        rp(&c, &z, &a.iter().map(String::as_str).collect::<Vec<_>>())
    };

    assert_clean_failure(RUN_ERROR, &rp(&d.join("nope.png"), &z, &base), "nope.png", &out);
    assert_clean_failure(RUN_ERROR, &rp(&c, &d.join("nope.exr"), &base), "nope.exr", &out);
    let small = d.join("small.exr");
    io::save_depth_exr(
        &small,
        &DepthMap::new(W / 2, H / 2, vec![1.0; (W * H / 4) as usize]).unwrap(),
    )
    .unwrap();
    assert_clean_failure(RUN_ERROR, &rp(&c, &small, &base), "size mismatch", &out);
    let corrupt = d.join("corrupt.exr");
    std::fs::write(&corrupt, b"not an exr").unwrap();
    assert_clean_failure(RUN_ERROR, &rp(&c, &corrupt, &base), "corrupt.exr", &out);

    // Bad intrinsics.
    for (flag, value) in [("--fx", "0"), ("--cy", "nan"), ("--fy", "-2"), ("--cx", "inf")] {
        let mut bad = k.clone();
        let at = bad.iter().position(|a| a == flag).unwrap();
        bad[at + 1] = value.to_string();
        let o = bin()
            .args(["reproject", "--color", s(&c), "--depth", s(&z), "--out-dir", s(&out)])
            .args(&bad)
            .args(base)
            .output()
            .unwrap();
        assert_clean_failure(USAGE, &o, &flag[2..], &out);
    }

    // Rig and depth kind.
    assert_clean_failure(USAGE, &rp(&c, &z, &[]), "--baseline", &out);
    assert_clean_failure(
        USAGE,
        &rp(&c, &z, &["--depth-kind", "disparity", "--baseline", "0"]),
        "baseline",
        &out,
    );
    assert_clean_failure(
        USAGE,
        &rp(&c, &z, &["--depth-kind", "disparity"]),
        "--depth-kind disparity needs --baseline",
        &out,
    );
    assert_clean_failure(USAGE, &rpx(&["--depth-kind", "device"]), "--near and --far", &out);
    assert_clean_failure(
        USAGE,
        &rpx(&["--depth-kind", "device", "--near", "1", "--far", "0.5"]),
        "--near/--far",
        &out,
    );
    // View Z stored as if it were device depth: all "background".
    assert_clean_failure(
        RUN_ERROR,
        &rpx(&["--depth-kind", "device", "--near", "0.05", "--far", "100"]),
        "no pixel holds valid depth",
        &out,
    );
    assert_clean_failure(
        USAGE,
        &rp(&c, &z, &["--separation=-0.1", "--convergence", "3"]),
        "separation",
        &out,
    );
    assert_clean_failure(USAGE, &rpx(&["--to", "both"]), "--to both needs --from centre", &out);
    assert_clean_failure(USAGE, &rpx(&["--to", "left"]), "source view itself", &out);

    // Method parameters and outputs.
    assert_clean_failure(USAGE, &rpx(&["--method", "shift", "--steps", "0"]), "steps", &out);
    assert_clean_failure(USAGE, &rpx(&["--tau-rel=-1"]), "tau_rel", &out);
    assert_clean_failure(USAGE, &rpx(&["--outputs", "rgb,normals"]), "outputs", &out);
    assert_clean_failure(USAGE, &rpx(&["--depth-format", "tiff"]), "depth-format", &out);

    // The last file cannot be written (a directory holds its name): the files written before
    // it are removed again.
    let blocked = d.join("blocked");
    std::fs::create_dir_all(blocked.join("right_mask.png")).unwrap();
    let o = bin()
        .args([
            "reproject",
            "--color",
            s(&c),
            "--depth",
            s(&z),
            "--out-dir",
            s(&blocked),
        ])
        .args(&k)
        .args(base)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("right_mask.png") && !err.contains("panicked"), "{err}");
    let left: Vec<String> = files_in(&blocked)
        .into_iter()
        .filter(|f| !f.starts_with(".viewsynth-write-test"))
        .collect();
    assert_eq!(left, ["right_mask.png"], "written outputs were not removed");
}

/// Faces and equirect small enough for llvmpipe and the CPU ray tracer in a test.
const N: u32 = 32;
const EW: u32 = 128;
const EH: u32 = 64;

#[test]
fn stitch_scene_demo_writes_the_stereo_equirect_the_library_renders() {
    let d = scratch("st-demo");
    let out = d.join("out");
    let text = ok(&run(&[
        "stitch",
        "--scene",
        "demo",
        "--face-size",
        &N.to_string(),
        "--width",
        &EW.to_string(),
        "--height",
        &EH.to_string(),
        "--overlap",
        "10",
        "--method",
        "blend",
        "--per-eye",
        "--truth",
        "--out-dir",
        s(&out),
    ]));
    assert_eq!(files_in(&out), ["ods_left.png", "ods_right.png", "ods_top_bottom.png"]);
    let tb = io::load_rgb(&out.join("ods_top_bottom.png")).unwrap();
    assert_eq!((tb.width, tb.height), (EW, 2 * EH));
    let rig = OdsRig::demo();
    let left = scene_faces(&rig, Side::Left, N, 110.0).unwrap();
    let right = scene_faces(&rig, Side::Right, N, 110.0).unwrap();
    let params = StitchParams {
        method: StitchMethod::Blend,
        overlap_deg: 10.0,
        width: EW,
        height: EH,
    };
    let (lib, _) = StitchRenderer::new(&gpu(), &left, &right)
        .unwrap()
        .render(&params)
        .unwrap();
    assert!(tb.data == lib.data, "top-bottom differs from the library");
    let half = tb.data.len() / 2;
    for (name, part) in [("ods_left.png", &tb.data[..half]), ("ods_right.png", &tb.data[half..])] {
        let eye = io::load_rgb(&out.join(name)).unwrap();
        assert_eq!((eye.width, eye.height), (EW, EH));
        assert!(eye.data == part, "{name} is not its half of the top-bottom image");
    }
    assert!(
        text.contains("seam band PSNR") && text.contains("whole image PSNR") && text.contains("ms wall"),
        "{text}"
    );
}

/// Writes the demo rig's faces with the documented names: {eye}_{pz,nz,up,down,px,nx}.png and
/// {eye}_{..}_depth.exr.
fn write_faces(dir: &Path, fov: f64) {
    write_faces_as(dir, fov, None);
}

/// As [`write_faces`], depth stored as f32 window depth under `device` (planes, conventions)
/// when given.
fn write_faces_as(dir: &Path, fov: f64, device: Option<(viewsynth::convention::DepthPlanes, Conventions)>) {
    let rig = OdsRig::demo();
    for (side, eye) in [(Side::Left, "left"), (Side::Right, "right")] {
        let set = scene_faces(&rig, side, N, fov).unwrap();
        for (face, tag) in set.faces.iter().zip(["pz", "nz", "up", "down", "px", "nx"]) {
            io::save_rgb(&dir.join(format!("{eye}_{tag}.png")), &face.color).unwrap();
            let mut depth = face.depth.clone();
            if let Some((planes, conv)) = device {
                for z in depth.data.iter_mut() {
                    *z = if *z > 0.0 {
                        let ndc = planes.ndc_z_of_view_z(&conv, *z as f64);
                        viewsynth::convention::DepthPlanes::window_depth_of_ndc_z(&conv, ndc) as f32
                    } else {
                        conv.clear_depth() as f32
                    };
                }
            }
            io::save_depth_exr(&dir.join(format!("{eye}_{tag}_depth.exr")), &depth).unwrap();
        }
    }
}

#[test]
fn stitch_faces_with_device_depth_under_vulkan_reversed_z() {
    use viewsynth::convention::DepthPlanes;
    let d = scratch("st-device");
    let (zf, df) = (d.join("z-faces"), d.join("device-faces"));
    std::fs::create_dir_all(&zf).unwrap();
    std::fs::create_dir_all(&df).unwrap();
    write_faces(&zf, 110.0);
    let conv = Conventions::all()[7];
    write_faces_as(&df, 110.0, Some((DepthPlanes { near: 0.05, far: 100.0 }, conv)));
    let size = ["--width", &EW.to_string(), "--height", &EH.to_string(), "--fov", "110"].map(String::from);
    let (a, b) = (d.join("out-z"), d.join("out-device"));
    ok(&bin()
        .args(["stitch", "--faces", s(&zf), "--out-dir", s(&a)])
        .args(&size)
        .output()
        .unwrap());
    let device = [
        "--depth-kind",
        "device",
        "--near",
        "0.05",
        "--far",
        "100",
        "--ndc",
        "vulkan",
        "--reversed-z",
        "--rows",
        "top-down",
    ];
    ok(&bin()
        .args(["stitch", "--faces", s(&df), "--out-dir", s(&b)])
        .args(device)
        .args(&size)
        .output()
        .unwrap());
    let (x, y) = (
        io::load_rgb(&a.join("ods_top_bottom.png")).unwrap(),
        io::load_rgb(&b.join("ods_top_bottom.png")).unwrap(),
    );
    // Reversed-Z [0,1] float depth holds view Z to ~1e-7: only a discrete choice on a tie may
    // flip (the 0.5 % allowed GPU vs f64).
    let off = x
        .data
        .chunks_exact(3)
        .zip(y.data.chunks_exact(3))
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(u, v)| u.abs_diff(*v) > 1))
        .count();
    assert!(off * 200 <= (EW * EH * 2) as usize, "{off} pixels differ");
    // Device depth needs its planes; view Z takes none.
    let bad = d.join("bad");
    let o = bin()
        .args([
            "stitch",
            "--faces",
            s(&df),
            "--depth-kind",
            "device",
            "--out-dir",
            s(&bad),
        ])
        .output()
        .unwrap();
    assert_clean_failure(USAGE, &o, "--near and --far", &bad);
    let o = bin()
        .args(["stitch", "--faces", s(&zf), "--near", "0.1", "--out-dir", s(&bad)])
        .output()
        .unwrap();
    assert_clean_failure(USAGE, &o, "--depth-kind device only", &bad);
}

#[test]
fn stitch_faces_from_a_folder_match_the_built_in_faces() {
    let d = scratch("st-faces");
    let faces = d.join("faces");
    std::fs::create_dir_all(&faces).unwrap();
    write_faces(&faces, 110.0);
    let common = [
        "--width",
        &EW.to_string(),
        "--height",
        &EH.to_string(),
        "--method",
        "reproject",
    ]
    .map(String::from);
    let (a, b) = (d.join("from-faces"), d.join("from-scene"));
    let text = ok(&bin()
        .args(["stitch", "--faces", s(&faces), "--fov", "110", "--out-dir", s(&a)])
        .args(&common)
        .output()
        .unwrap());
    assert!(text.contains("loaded 12 faces of 32x32"), "{text}");
    ok(&bin()
        .args([
            "stitch",
            "--scene",
            "demo",
            "--face-size",
            "32",
            "--overlap",
            "10",
            "--out-dir",
            s(&b),
        ])
        .args(&common)
        .output()
        .unwrap());
    assert_eq!(files_in(&a), ["ods_top_bottom.png"]);
    let (x, y) = (
        io::load_rgb(&a.join("ods_top_bottom.png")).unwrap(),
        io::load_rgb(&b.join("ods_top_bottom.png")).unwrap(),
    );
    assert_eq!((x.width, x.height), (EW, 2 * EH));
    // Same faces; only the rig centre differs (0 for --faces, the demo's 1.6 m for --scene),
    // which moves f32 rounding: a swapped or mis-oriented face would change most pixels.
    let off = x
        .data
        .chunks_exact(3)
        .zip(y.data.chunks_exact(3))
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(u, v)| u.abs_diff(*v) > 1))
        .count();
    assert!(off * 200 <= (EW * EH * 2) as usize, "{off} pixels differ");
}

/// One summary line per eye (the six faces pooled), in metres; a face folder whose depth was
/// written in millimetres as float (x 1000) warns, naming the options to check.
#[test]
fn stitch_faces_print_the_input_depth_summary_and_warn_on_a_wrong_scale() {
    let d = scratch("st-summary");
    let (metres, millimetres) = (d.join("m"), d.join("mm"));
    std::fs::create_dir_all(&metres).unwrap();
    std::fs::create_dir_all(&millimetres).unwrap();
    write_faces(&metres, 110.0);
    for entry in std::fs::read_dir(&metres).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap();
        if path.extension().is_some_and(|e| e == "exr") {
            let mut z = io::load_depth(&path, &Default::default()).unwrap();
            z.data.iter_mut().for_each(|v| *v *= 1000.0);
            io::save_depth_exr(&millimetres.join(name), &z).unwrap();
        } else {
            std::fs::copy(&path, millimetres.join(name)).unwrap();
        }
    }
    let stitch = |faces: &Path, out: &Path| {
        bin()
            .args(["stitch", "--faces", s(faces), "--fov", "110", "--out-dir", s(out)])
            .args(["--width", &EW.to_string(), "--height", &EH.to_string()])
            .output()
            .unwrap()
    };
    let o = stitch(&metres, &d.join("out-m"));
    ok(&o);
    let log = String::from_utf8_lossy(&o.stderr);
    assert_eq!(log.matches("input depth").count(), 2, "{log}");
    for eye in ["left", "right"] {
        // Six 32x32 faces stacked.
        let line = format!("{eye}_{{pz,nz,up,down,px,nx}}_depth: 32x192, ");
        assert!(log.contains(&line), "{line} not in {log}");
    }
    assert!(!log.contains("warning"), "{log}");
    let o = stitch(&millimetres, &d.join("out-mm"));
    ok(&o);
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(
        log.contains("warning") && log.contains("implausibly far") && log.contains("--depth-scale"),
        "{log}"
    );
}

#[test]
fn stitch_bad_input_fails_cleanly() {
    let d = scratch("st-bad");
    let faces = d.join("faces");
    std::fs::create_dir_all(&faces).unwrap();
    write_faces(&faces, 110.0);
    let out = d.join("out");
    let st = |extra: &[&str]| -> Output {
        bin()
            .args(["stitch", "--width", "64", "--height", "32", "--out-dir", s(&out)])
            .args(extra)
            .output()
            .unwrap()
    };
    let f = s(&faces);
    let demo = ["--scene", "demo", "--face-size", "16"];
    let demo_with = |extra: &[&str]| st(&demo.iter().chain(extra).copied().collect::<Vec<_>>());

    assert_clean_failure(USAGE, &demo_with(&["--overlap", "0"]), "overlap", &out);
    assert_clean_failure(USAGE, &demo_with(&["--fov", "110", "--overlap", "30"]), "overlap", &out);
    assert_clean_failure(USAGE, &demo_with(&["--fov", "80"]), "--fov", &out);
    assert_clean_failure(USAGE, &demo_with(&["--ipd=-1"]), "ipd", &out);
    assert_clean_failure(
        RUN_ERROR,
        &st(&["--scene", "demo", "--face-size", "1"]),
        "face size",
        &out,
    );
    assert_clean_failure(USAGE, &st(&["--scene", "boxes"]), "--scene 'boxes'", &out);
    assert_clean_failure(
        USAGE,
        &st(&["--faces", f, "--fov", "110", "--truth"]),
        "--truth needs --scene",
        &out,
    );
    assert_clean_failure(
        RUN_ERROR,
        &st(&["--faces", s(&d.join("none")), "--fov", "110"]),
        "not a directory",
        &out,
    );
    // The overlap must fit the declared face FOV.
    assert_clean_failure(
        USAGE,
        &st(&["--faces", f, "--fov", "100", "--overlap", "10"]),
        "overlap",
        &out,
    );
    // --npz-key reaches the face loader: it names an array of .npz files, refused for EXR faces.
    assert_clean_failure(
        RUN_ERROR,
        &st(&["--faces", f, "--fov", "110", "--npz-key", "z"]),
        "applies to .npz files only",
        &out,
    );

    // A face file missing: the error names the path expected.
    std::fs::remove_file(faces.join("right_px_depth.exr")).unwrap();
    assert_clean_failure(RUN_ERROR, &st(&["--faces", f]), "right_px_depth.exr", &out);
    // A face of another size.
    io::save_depth_exr(
        &faces.join("right_px_depth.exr"),
        &DepthMap::new(N / 2, N / 2, vec![1.0; (N * N / 4) as usize]).unwrap(),
    )
    .unwrap();
    assert_clean_failure(RUN_ERROR, &st(&["--faces", f]), "size mismatch", &out);
    // A corrupt colour face.
    write_faces(&faces, 110.0);
    std::fs::write(faces.join("left_up.png"), b"\x89PNG\r\n\x1a\nbroken").unwrap();
    assert_clean_failure(RUN_ERROR, &st(&["--faces", f]), "left_up.png", &out);
}

#[test]
fn reproject_with_full_eye_matrices_from_a_cameras_file() {
    // `viewsynth scene` writes both eyes, their device depth and cameras.json; reprojecting the
    // left eye through the file's matrices must give the library's 3-D gather exactly, and the
    // ray-traced right eye where it is valid.
    use viewsynth::convention::DepthPlanes;
    use viewsynth::depth::DepthEncoding;
    use viewsynth::reproject::ReprojectSource;
    use viewsynth::stereo::camera_file::CameraFile;
    use viewsynth::stereo::MiddleCamera;
    let dir = scratch("reproject_cameras");
    let scene = dir.join("scene");
    ok(&run(&[
        "scene",
        "--width",
        "96",
        "--height",
        "72",
        "--reversed-z",
        "--ndc",
        "vulkan",
        "--out-dir",
        s(&scene),
    ]));
    let (cams, color, depth) = (
        scene.join("cameras.json"),
        scene.join("left_rgb.png"),
        scene.join("left_device_depth.exr"),
    );
    let out = dir.join("out");
    let common = [
        "reproject",
        "--cameras",
        s(&cams),
        "--color",
        s(&color),
        "--depth",
        s(&depth),
    ];
    let stdout = ok(&run(
        &[&common[..], &["--method", "gather3d", "--out-dir", s(&out)]].concat()
    ));
    assert!(stdout.contains("left -> right (3-D gather 3)"), "{stdout}");
    assert_eq!(files_in(&out), ["right_depth.exr", "right_mask.png", "right_rgb.png"]);

    let file = CameraFile::load(&cams).unwrap();
    let conv = file.conventions;
    let src = ReprojectSource {
        color: io::load_rgb(&color).unwrap(),
        depth: io::load_depth(&depth, &Default::default()).unwrap(),
        depth_kind: DepthEncoding::Device {
            planes: DepthPlanes::from_gl_projection(&file.left.proj, &conv).unwrap(),
        },
        conv,
    };
    let geometry = Geometry::Matrices {
        source_view: file.left.view,
        source_proj: file.left.proj,
        target: MiddleCamera {
            view: file.right.view,
            proj: file.right.proj,
            width: 96,
            height: 72,
        },
    };
    let (lib, _) = Reprojector::new(
        &gpu(),
        &src,
        &geometry,
        ReprojectParams::new(Method::Gather3d { steps: 3 }),
    )
    .unwrap()
    .render()
    .unwrap();
    let rgb = io::load_rgb(&out.join("right_rgb.png")).unwrap();
    assert_eq!(rgb.data, lib.color.as_ref().unwrap().data);
    // Against the ray-traced right eye on the valid pixels: measured 96.8 % coverage and
    // 33.8 dB at 96x72, where the unmoved left image scores 19.7 dB; 30 dB separates them.
    let truth = io::load_rgb(&scene.join("right_rgb.png")).unwrap();
    let (mut sq, mut n) = (0.0, 0usize);
    for (i, _) in lib.mask.iter().enumerate().filter(|(_, m)| **m != 0) {
        n += 1;
        for c in 0..3 {
            let d = rgb.data[i * 3 + c] as f64 - truth.data[i * 3 + c] as f64;
            sq += d * d;
        }
    }
    let psnr = viewsynth::metrics::psnr_from_mse(sq / (3 * n) as f64);
    // Baseline: the unmoved left image scored the same way.
    let sq0: f64 = lib
        .mask
        .iter()
        .enumerate()
        .filter(|(_, m)| **m != 0)
        .flat_map(|(i, _)| (0..3).map(move |c| i * 3 + c))
        .map(|j| (src.color.data[j] as f64 - truth.data[j] as f64).powi(2))
        .sum();
    let unmoved = viewsynth::metrics::psnr_from_mse(sq0 / (3 * n) as f64);
    println!(
        "cameras.json left -> right: coverage {:.4}, {psnr:.2} dB (unmoved left: {unmoved:.2} dB)",
        lib.coverage()
    );
    assert!(
        lib.coverage() > 0.9 && psnr > 30.0,
        "coverage {} psnr {psnr}",
        lib.coverage()
    );

    // The shift methods need a rig; the centre is not in the file.
    let bad = dir.join("bad");
    let o = run(&[&common[..], &["--method", "shift-scan", "--out-dir", s(&bad)]].concat());
    assert_clean_failure(USAGE, &o, "--method gather3d", &bad);
    let o = run(&[
        &common[..],
        &["--method", "gather3d", "--from", "centre", "--out-dir", s(&bad)],
    ]
    .concat());
    assert_clean_failure(USAGE, &o, "--from left or right", &bad);
    let o = run(&[
        &common[..],
        &["--method", "gather3d", "--reversed-z", "--out-dir", s(&bad)],
    ]
    .concat());
    assert_clean_failure(USAGE, &o, "come from the file", &bad);
}

/// `scene --cube-faces` writes a face folder `stitch --faces` reads as is: stitched, it gives
/// the image `stitch --scene demo` gives from the same faces ray-traced in memory (up to the
/// last f32 rounding of the rig's centre, which the face folder does not carry).
#[test]
fn scene_cube_faces_feed_stitch_faces() {
    let d = scratch("scene-cube-faces");
    let faces = d.join("faces");
    let f = faces.display().to_string();
    let o = ok(&run(&[
        "scene",
        "--width",
        "32",
        "--height",
        "24",
        "--cube-faces",
        "32",
        "--out-dir",
        &f,
    ]));
    assert!(o.contains("cube faces: 12 of 32x32, fov 110 deg"), "{o}");
    let names = files_in(&faces);
    for eye in ["left", "right"] {
        for tag in viewsynth::stitch::faces::FACE_TAGS {
            for file in [format!("{eye}_{tag}.png"), format!("{eye}_{tag}_depth.exr")] {
                assert!(names.contains(&file), "{file} missing: {names:?}");
            }
        }
    }
    let size = ["--width", "128", "--height", "64"];
    let from_faces = d.join("from_faces").display().to_string();
    ok(&run(&[
        &["stitch", "--faces", &f, "--fov", "110"],
        &size[..],
        &["--out-dir", &from_faces],
    ]
    .concat()));
    let from_scene = d.join("from_scene").display().to_string();
    ok(&run(&[
        &["stitch", "--scene", "demo", "--face-size", "32"],
        &size[..],
        &["--out-dir", &from_scene],
    ]
    .concat()));
    let a = io::load_rgb(&Path::new(&from_faces).join("ods_top_bottom.png")).unwrap();
    let b = io::load_rgb(&Path::new(&from_scene).join("ods_top_bottom.png")).unwrap();
    assert_eq!((a.width, a.height), (128, 128));
    let diff: Vec<i32> = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(x, y)| (*x as i32 - *y as i32).abs())
        .collect();
    let off = diff.iter().filter(|v| **v > 0).count();
    assert!(diff.iter().all(|v| *v <= 1), "max difference {:?}", diff.iter().max());
    assert!(off * 1000 < diff.len(), "{off} of {} values differ", diff.len());
    // A face FOV stitch cannot use is refused before anything is written.
    let bad = d.join("bad");
    let o = run(&[
        "scene",
        "--cube-faces",
        "16",
        "--face-fov",
        "90",
        "--out-dir",
        &bad.display().to_string(),
    ]);
    assert_clean_failure(USAGE, &o, "--face-fov 90", &bad);
}

/// `reproject --cameras` renders by the 3-D gather without being told, to any camera of the
/// file (`--to centre`, alias middle: the file's middle camera); a contradictory method or
/// target is a usage error that writes nothing.
#[test]
fn reproject_cameras_default_to_gather3d_and_reach_the_middle_camera() {
    let dir = scratch("reproject_cameras_targets");
    let scene = dir.join("scene");
    ok(&run(&[
        "scene",
        "--width",
        "96",
        "--height",
        "72",
        "--out-dir",
        s(&scene),
    ]));
    let cams = scene.join("cameras.json");
    let (color, depth) = (scene.join("left_rgb.png"), scene.join("left_device_depth.exr"));
    let common = [
        "reproject",
        "--cameras",
        s(&cams),
        "--color",
        s(&color),
        "--depth",
        s(&depth),
    ];
    // No --method: gather3d (before, exit 2 "needs --method gather3d").
    let right = dir.join("right");
    let stdout = ok(&run(&[&common[..], &["--out-dir", s(&right)]].concat()));
    assert!(stdout.contains("left -> right (3-D gather 3)"), "{stdout}");
    // The middle camera, against the scene's ray-traced middle view on the valid pixels.
    let middle = dir.join("middle");
    let stdout = ok(&run(
        &[&common[..], &["--to", "middle", "--out-dir", s(&middle)]].concat()
    ));
    assert!(stdout.contains("left -> centre (3-D gather 3)"), "{stdout}");
    assert_eq!(
        files_in(&middle),
        ["centre_depth.exr", "centre_mask.png", "centre_rgb.png"]
    );
    let (rgb, truth) = (
        io::load_rgb(&middle.join("centre_rgb.png")).unwrap(),
        io::load_rgb(&scene.join("middle_rgb.png")).unwrap(),
    );
    let mask = io::load_rgb(&middle.join("centre_mask.png")).unwrap();
    let valid: Vec<usize> = (0..mask.data.len() / 3).filter(|&i| mask.data[3 * i] > 0).collect();
    let sq: f64 = valid
        .iter()
        .flat_map(|&i| (0..3).map(move |c| 3 * i + c))
        .map(|j| (rgb.data[j] as f64 - truth.data[j] as f64).powi(2))
        .sum();
    let psnr = viewsynth::metrics::psnr_from_mse(sq / (3 * valid.len()) as f64);
    let coverage = valid.len() as f64 / (96.0 * 72.0);
    println!("cameras.json left -> middle: coverage {coverage:.4}, {psnr:.2} dB");
    assert!(coverage > 0.9 && psnr > 30.0, "coverage {coverage} psnr {psnr}");

    let bad = dir.join("bad");
    let o = run(&[&common[..], &["--method", "shift", "--out-dir", s(&bad)]].concat());
    assert_clean_failure(USAGE, &o, "--method gather3d", &bad);
    let o = run(&[&common[..], &["--to", "left", "--out-dir", s(&bad)]].concat());
    assert_clean_failure(USAGE, &o, "the source view itself", &bad);
    let o = run(&[&common[..], &["--to", "both", "--out-dir", s(&bad)]].concat());
    assert_clean_failure(USAGE, &o, "--to both", &bad);
    let rig = [
        "reproject",
        "--color",
        s(&color),
        "--depth",
        s(&color),
        "--fx",
        "80",
        "--fy",
        "80",
        "--cx",
        "48",
        "--cy",
        "36",
        "--baseline",
        "0.1",
        "--to",
        "centre",
        "--out-dir",
        s(&bad),
    ];
    assert_clean_failure(USAGE, &run(&rig), "--to centre (middle) needs --cameras", &bad);
}
