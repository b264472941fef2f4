//! The commands on `--backend vulkan`: reproject, stitch, scene, cyclopean and the refocus
//! batch write what their GL runs write, under the agreement rule of `eval::backends` (bounds
//! derived in `viewsynth_tests`' `vulkan::passes`), and every pass runs clean under the Khronos
//! validation layer. A missing Vulkan loader, driver or validation layer fails, never skips.
use crate::cli::{bin, scratch};
use crate::common::run_clean_under_validation_layer;
use crate::common::{cyclopean_cli, data_dir, write_cyclopean_files};
use std::path::Path;
use viewsynth::convention::Conventions;
use viewsynth::stereo::scene_frame::{scene_frame, StereoRig};
use viewsynth::stereo::FrameDepth;
use viewsynth::view::ViewOutput;
use viewsynth_lab::eval::backends::{backend_diff, BackendDiff};

fn assert_agree(tag: &str, d: &BackendDiff) {
    println!("{tag}: {d:?}");
    assert!(d.agrees(), "{tag}: GL and Vulkan differ beyond the bounds: {d:?}");
}

/// Every file `gl` holds is in `vk` with the same shape, within the agreement rule.
fn compare_folders(tag: &str, gl: &Path, vk: &Path) {
    // The outputs (files_in leaves out the hidden record of the set); sorted.
    let names = crate::cli::files_in(gl);
    assert!(!names.is_empty(), "{tag}: the GL run wrote nothing");
    for name in names {
        let (a, b) = (gl.join(&name), vk.join(&name));
        assert!(b.exists(), "{tag}: the Vulkan run did not write {name}");
        let what = format!("{tag} {name}");
        let d = if name.ends_with("_mask.png") {
            let (ma, mb) = (
                viewsynth::io::load_mask_png(&a).unwrap(),
                viewsynth::io::load_mask_png(&b).unwrap(),
            );
            assert_eq!((ma.width, ma.height), (mb.width, mb.height), "{what}: size");
            BackendDiff {
                pixels: ma.data.len(),
                mask_mismatches: ma
                    .data
                    .iter()
                    .zip(&mb.data)
                    .filter(|(x, y)| (**x != 0) != (**y != 0))
                    .count(),
                ..Default::default()
            }
        } else if name.ends_with(".png") {
            let (ca, cb) = (
                viewsynth::io::load_rgb(&a).unwrap(),
                viewsynth::io::load_rgb(&b).unwrap(),
            );
            assert_eq!((ca.width, ca.height), (cb.width, cb.height), "{what}: size");
            backend_diff(&ViewOutput::color_only(ca, None), &ViewOutput::color_only(cb, None))
        } else if name.ends_with(".npy") || name.ends_with(".exr") {
            let load = |p: &Path| viewsynth::io::load_depth(p, &Default::default()).unwrap();
            let (za, zb) = (load(&a), load(&b));
            assert_eq!((za.width, za.height), (zb.width, zb.height), "{what}: size");
            let view = |z: viewsynth::io::DepthMap| ViewOutput {
                width: z.width,
                height: z.height,
                color: None,
                depth: Some(z),
                mask: None,
                timing: None,
                exact: None,
            };
            backend_diff(&view(za), &view(zb))
        } else {
            // JSON (cameras, manifests): same keys at the top level.
            let keys = |p: &Path| {
                let v: serde_json::Value = serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap();
                v.as_object().map(|o| o.keys().cloned().collect::<Vec<_>>())
            };
            assert_eq!(keys(&a), keys(&b), "{what}");
            continue;
        };
        assert_agree(&what, &d);
    }
}

fn run_both(tag: &str, dir: &Path, args: &[&str]) {
    run_on_both(tag, dir, args);
    compare_folders(tag, &dir.join(format!("{tag}-gl")), &dir.join(format!("{tag}-vulkan")));
}

/// The command on each backend, into `<dir>/<tag>-gl` and `<dir>/<tag>-vulkan`.
fn run_on_both(tag: &str, dir: &Path, args: &[&str]) {
    for backend in ["gl", "vulkan"] {
        let out = dir.join(format!("{tag}-{backend}"));
        let o = bin()
            .args(args)
            .args(["--backend", backend, "--out-dir"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{tag} --backend {backend}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn reproject_stitch_scene_and_cyclopean_commands_write_the_same_files_on_vulkan() {
    let dir = scratch("vulkan-passes-cli");
    let tum = data_dir().join("rgbd_open3d_testdata");
    let (rgb, depth) = (tum.join("TUM_color.png"), tum.join("TUM_depth.png"));
    let (rgb, depth) = (rgb.to_str().unwrap(), depth.to_str().unwrap());
    for method in ["shift", "shift-scan", "gather3d"] {
        run_both(
            &format!("reproject-{method}"),
            &dir,
            &[
                "reproject",
                "--rgb",
                rgb,
                "--depth",
                depth,
                "--depth-scale",
                "5000",
                "--fx",
                "525",
                "--fy",
                "525",
                "--cx",
                "319.5",
                "--cy",
                "239.5",
                "--baseline",
                "0.064",
                "--depth-format",
                "npy",
                "--method",
                method,
            ],
        );
    }
    for method in ["blend", "border-weight", "reproject"] {
        run_both(
            &format!("stitch-{method}"),
            &dir,
            &[
                "stitch",
                "--scene",
                "demo",
                "--face-size",
                "64",
                "--width",
                "256",
                "--height",
                "128",
                "--method",
                method,
            ],
        );
    }
    run_both("scene", &dir, &["scene", "--width", "160", "--height", "120"]);
    // The README's Cones example: the default method from Middlebury disparities.
    let cones = data_dir().join("middlebury2003_cones");
    let file = |f: &str| cones.join(f).to_str().unwrap().to_string();
    let (l, r, dl, dr) = (file("im2.png"), file("im6.png"), file("disp2.pgm"), file("disp6.pgm"));
    run_both(
        "cones",
        &dir,
        &[
            "cyclopean",
            "--left-rgb",
            &l,
            "--right-rgb",
            &r,
            "--left-disparity",
            &dl,
            "--right-disparity",
            &dr,
            "--disparity-scale",
            "4",
        ],
    );
    // The cyclopean gather from the scene's own files (seed and refine run on Vulkan).
    let (frame, mid, _) = scene_frame(&StereoRig::demo(96, 72), Conventions::all()[6], FrameDepth::Device);
    write_cyclopean_files(&dir, &frame, &mid);
    for method in ["splat-gather", "seed", "refine", "forward"] {
        let (gl, vk) = (
            dir.join(format!("cyc-{method}-gl")),
            dir.join(format!("cyc-{method}-vulkan")),
        );
        for (backend, out) in [("gl", &gl), ("vulkan", &vk)] {
            let o = cyclopean_cli(&dir, "cams.json", &["--method", method, "--backend", backend], out);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
        compare_folders(&format!("cyclopean {method}"), &gl, &vk);
    }
}

/// A refocus manifest of the TUM and SUN frames in `dir`.
fn refocus_manifest(dir: &Path) -> std::path::PathBuf {
    let d = data_dir().join("rgbd_open3d_testdata");
    let p = |f: &str| d.join(f).to_str().unwrap().to_string();
    let csv = format!(
        "rgb,depth,fx,fy,cx,cy,depth_scale,sun_bit_rotate,name\n\
         {},{},525,525,319.5,239.5,5000,,tum\n\
         {},{},525,525,319.5,239.5,1000,true,sun\n",
        p("TUM_color.png"),
        p("TUM_depth.png"),
        p("SUN_color.jpg"),
        p("SUN_depth.png")
    );
    let path = dir.join("frames.csv");
    std::fs::write(&path, csv).unwrap();
    path
}

/// `refocus --batch MANIFEST` with 3 scales on 2 threads per pool, `--method METHOD`.
fn batch_args(manifest: &Path, method: &str) -> Vec<String> {
    let m = manifest.to_str().unwrap();
    [
        "refocus",
        "--batch",
        m,
        "--zoom-range",
        "0.5,1,2",
        "--jobs",
        "2",
        "--method",
        method,
    ]
    .map(String::from)
    .to_vec()
}

/// `refocus --batch --backend vulkan`: the pipelined batch (decoder and writer threads, targets
/// and frames in flight) writes, frame by frame, what the GL batch writes, for both methods.
#[test]
fn refocus_batch_writes_the_same_files_on_vulkan() {
    let dir = scratch("vulkan-batch");
    let manifest = refocus_manifest(&dir);
    for method in ["fullscreen", "mesh"] {
        let tag = format!("batch-{method}");
        let args = batch_args(&manifest, method);
        run_on_both(&tag, &dir, &args.iter().map(String::as_str).collect::<Vec<_>>());
        for frame in ["tum", "sun"] {
            let (gl, vk) = (
                dir.join(format!("{tag}-gl")).join(frame),
                dir.join(format!("{tag}-vulkan")).join(frame),
            );
            compare_folders(&format!("{tag} {frame}"), &gl, &vk);
            let m: serde_json::Value =
                serde_json::from_slice(&std::fs::read(vk.join("manifest.json")).unwrap()).unwrap();
            assert!(
                m["renderer"].as_str().unwrap().starts_with("Vulkan: "),
                "{tag} {frame}: the manifest names {}",
                m["renderer"]
            );
        }
    }
}

/// One run of each Vulkan pass under VK_LAYER_KHRONOS_validation (Debian package
/// `vulkan-validationlayers`): any validation message fails. The loader's own log proves the
/// layer was inserted, so a missing layer cannot pass silently.
#[test]
fn every_vulkan_pass_runs_clean_under_the_validation_layer() {
    let dir = scratch("vulkan-validation");
    let tum = data_dir().join("rgbd_open3d_testdata");
    let (rgb, depth) = (tum.join("TUM_color.png"), tum.join("TUM_depth.png"));
    let (rgb, depth) = (rgb.to_str().unwrap(), depth.to_str().unwrap());
    let intrinsics = ["--fx", "525", "--fy", "525", "--cx", "319.5", "--cy", "239.5"];
    let (frame, mid, _) = scene_frame(&StereoRig::demo(64, 48), Conventions::default(), FrameDepth::Device);
    write_cyclopean_files(&dir, &frame, &mid);
    let mut runs: Vec<Vec<String>> = Vec::new();
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    for method in ["shift", "shift-scan", "gather3d"] {
        let mut a = s(&["reproject", "--rgb", rgb, "--depth", depth, "--depth-scale", "5000"]);
        a.extend(s(&intrinsics));
        a.extend(s(&["--baseline", "0.064", "--method", method]));
        runs.push(a);
    }
    for method in ["blend", "border-weight", "reproject"] {
        runs.push(s(&[
            "stitch",
            "--scene",
            "demo",
            "--face-size",
            "32",
            "--width",
            "128",
            "--height",
            "64",
            "--method",
            method,
        ]));
    }
    runs.push(s(&["scene", "--width", "64", "--height", "48"]));
    let manifest = refocus_manifest(&dir);
    for method in ["fullscreen", "mesh"] {
        let mut a = s(&["refocus", "--rgb", rgb, "--depth", depth, "--depth-scale", "5000"]);
        a.extend(s(&intrinsics));
        a.extend(s(&["--zoom-range", "0.5,2", "--method", method]));
        runs.push(a);
        // The batch: several runs in flight, image writes staged per flight.
        runs.push(batch_args(&manifest, method));
    }
    let file = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let (lr, ld, rr, rd, cams) = (
        file("left.png"),
        file("left.exr"),
        file("right.png"),
        file("right.exr"),
        file("cams.json"),
    );
    for method in ["splat-gather", "seed", "refine", "forward"] {
        runs.push(s(&[
            "cyclopean",
            "--method",
            method,
            "--left-rgb",
            &lr,
            "--left-depth",
            &ld,
            "--right-rgb",
            &rr,
            "--right-depth",
            &rd,
            "--cameras",
            &cams,
        ]));
    }
    // The fill pass after the default method.
    let mut filled = runs.last().unwrap().clone();
    filled[2] = "splat-gather".into();
    filled.push("--fill".into());
    runs.push(filled);
    // Two images alone with the fill: the semi-global matcher checked by the census one's stages
    // and the trust stage (one run) over the estimated range, the densify pass on both eyes, the
    // two renders and the fill.
    runs.push(s(&["cyclopean", "--left-rgb", &lr, "--right-rgb", &rr, "--fill"]));
    // The semi-global matcher's stages.
    runs.push(s(&[
        "cyclopean",
        "--left-rgb",
        &lr,
        "--right-rgb",
        &rr,
        "--matcher",
        "sgm",
    ]));
    // The temporal accumulation: a two-frame sequence with --fill (frame 1 takes the history).
    let seq = dir.join("seq");
    let made = bin()
        .args([
            "scene",
            "--width",
            "64",
            "--height",
            "48",
            "--frames",
            "2",
            "--spectator-offset",
            "0.1",
            "--out-dir",
        ])
        .arg(&seq)
        .output()
        .unwrap();
    assert!(made.status.success(), "{}", String::from_utf8_lossy(&made.stderr));
    runs.push(s(&["cyclopean", "--sequence", &file("seq/sequence.json"), "--fill"]));
    for (k, args) in runs.iter().enumerate() {
        let out = dir.join(format!("run{k}"));
        run_clean_under_validation_layer(
            &format!("{args:?}"),
            bin().args(args).args(["--backend", "vulkan", "--out-dir"]).arg(&out),
        );
    }
    // The stereo matcher has no command of its own: `viewsynth_tests`'
    // `vulkan::passes::the_matcher_runs_clean_under_the_validation_layer` runs its Vulkan test
    // under the layer.
}
