//! cameras.json with cameras in the computer-vision form (K + [R|t], OpenCV axes): the same
//! frame as `viewsynth scene` writes it in GL matrices must give byte-identical outputs through
//! `reproject --cameras` and `cyclopean --cameras`, and malformed matrices fail cleanly.

use crate::cli::{assert_clean_failure, bin, files_in, scratch, RUN_ERROR};
use serde_json::{json, Value};
use std::path::Path;
use std::process::Output;
use viewsynth::stereo::camera_file::CameraFile;
use viewsynth::stereo::scene_frame::StereoRig;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The scene's cameras.json with every camera rewritten as K, R, t, size and planes, from the
/// rig `viewsynth scene` uses (64 mm IPD, the demo camera at the origin).
fn cv_form(gl_file: &Value, width: u32, height: u32) -> Value {
    let rig = StereoRig::demo(width, height);
    let k = &rig.camera.k;
    let cam = |side: f64| {
        let m = rig.eye_pose(side).camera_from_world();
        let r = [0, 1, 2].map(|i| [m[i][0], m[i][1], m[i][2]]);
        json!({
            "K": [[k.fx, 0.0, k.cx], [0.0, k.fy, k.cy], [0.0, 0.0, 1.0]],
            "R": r,
            "t": [m[0][3], m[1][3], m[2][3]],
            "width": width, "height": height,
            "near": rig.planes.near, "far": rig.planes.far,
        })
    };
    let mut f = gl_file.clone();
    f["left"] = cam(-1.0);
    f["right"] = cam(1.0);
    f["middle"] = cam(0.0);
    f
}

#[test]
fn cameras_in_k_r_t_form_give_the_outputs_of_the_gl_matrices() {
    let dir = scratch("cameras-cv");
    let scene = dir.join("scene");
    let (w, h) = (96, 72);
    ok(&bin()
        .args([
            "scene",
            "--width",
            "96",
            "--height",
            "72",
            "--reversed-z",
            "--ndc",
            "vulkan",
        ])
        .args(["--rows", "top-down", "--out-dir", s(&scene)])
        .output()
        .unwrap());
    let gl_path = scene.join("cameras.json");
    let gl: Value = serde_json::from_slice(&std::fs::read(&gl_path).unwrap()).unwrap();
    let cv_path = dir.join("cameras_cv.json");
    std::fs::write(&cv_path, serde_json::to_string_pretty(&cv_form(&gl, w, h)).unwrap()).unwrap();

    // The matrices agree exactly (the row sign flip and the scene's projection are both exact).
    let (a, b) = (CameraFile::load(&gl_path).unwrap(), CameraFile::load(&cv_path).unwrap());
    for (x, y) in [(&a.left, &b.left), (&a.right, &b.right)] {
        assert_eq!((x.view, x.proj), (y.view, y.proj));
    }
    assert_eq!(a.middle.proj, b.middle.proj);
    assert_eq!(Some(a.middle.view.unwrap()), b.middle.view);

    let run = |cmd: &[&str], cams: &Path, out: &Path| {
        ok(&bin()
            .args(cmd)
            .args(["--cameras", s(cams), "--out-dir", s(out)])
            .output()
            .unwrap())
    };
    let eye: Vec<String> = [
        "left_rgb.png",
        "left_device_depth.exr",
        "right_rgb.png",
        "right_device_depth.exr",
    ]
    .map(|n| s(&scene.join(n)).to_string())
    .to_vec();
    let reproject = [
        "reproject",
        "--method",
        "gather3d",
        "--color",
        &eye[0],
        "--depth",
        &eye[1],
    ];
    let cyclopean = [
        "cyclopean",
        "--left-rgb",
        &eye[0],
        "--left-depth",
        &eye[1],
        "--right-rgb",
        &eye[2],
        "--right-depth",
        &eye[3],
    ];
    for (tag, cmd) in [("reproject", &reproject[..]), ("cyclopean", &cyclopean[..])] {
        let (out_gl, out_cv) = (dir.join(format!("{tag}-gl")), dir.join(format!("{tag}-cv")));
        run(cmd, &gl_path, &out_gl);
        run(cmd, &cv_path, &out_cv);
        let names = files_in(&out_gl);
        assert!(names.iter().any(|n| n.ends_with("_rgb.png")), "{tag}: {names:?}");
        assert_eq!(names, files_in(&out_cv), "{tag}");
        for n in &names {
            let same = std::fs::read(out_gl.join(n)).unwrap() == std::fs::read(out_cv.join(n)).unwrap();
            assert!(same, "{tag}: {n} differs between the GL and the K/R/t camera files");
        }
    }

    // A mirrored R and an image of another size than the camera's: clean failures, no output.
    let mut bad = cv_form(&gl, w, h);
    bad["left"]["R"] = json!([[1, 0, 0], [0, 1, 0], [0, 0, -1]]);
    let bad_path = dir.join("mirrored.json");
    std::fs::write(&bad_path, bad.to_string()).unwrap();
    let out = dir.join("bad-out");
    let o = bin()
        .args(reproject)
        .args(["--cameras", s(&bad_path), "--out-dir", s(&out)])
        .output()
        .unwrap();
    assert_clean_failure(RUN_ERROR, &o, "mirrored.json: invalid left.R: determinant", &out);
    let wrong_size = cv_form(&gl, 128, 96);
    let size_path = dir.join("other_size.json");
    std::fs::write(&size_path, wrong_size.to_string()).unwrap();
    let o = bin()
        .args(cyclopean)
        .args(["--cameras", s(&size_path), "--out-dir", s(&out)])
        .output()
        .unwrap();
    assert_clean_failure(RUN_ERROR, &o, "is 96x72, its camera in the camera file 128x96", &out);
}

/// docs/formats.md's cameras.json example, as a Vulkan renderer would write it, parses under the
/// conventions it states (the schema there is the file's, key by key).
#[test]
fn the_documented_vulkan_cameras_json_parses() {
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/formats.md")).unwrap();
    let section = &doc[doc.find("## cameras.json").unwrap()..];
    let start = section.find("```json").unwrap() + "```json".len();
    let block = &section[start..start + section[start..].find("```").unwrap()];
    let d = scratch("cameras-doc");
    let path = d.join("cameras.json");
    std::fs::write(&path, block).unwrap();
    let f = CameraFile::load(&path).unwrap();
    assert!(f.conventions.reversed_z, "{:?}", f.conventions);
    assert_eq!((f.middle.width, f.middle.height), (640, 480));
    assert_eq!(f.left.size, Some([640, 480]));
    let (_, fixation) = f.middle_and_fixation().unwrap();
    assert_eq!(fixation, 3.0);
}
