//! Every option a depth warning suggests (in backticks, as it would be typed) is accepted by the
//! command that prints it: the command run again with the suggestion is no usage error. A
//! warning once told `cyclopean` to use `--ndc vulkan --reversed-z`, options it refuses with
//! `--cameras` (the conventions come from cameras.json).

use crate::cli::{bin, scratch};
use std::path::Path;
use std::process::Output;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The backticked suggestions of the warning lines, placeholders filled (N near, F far, S scale).
fn suggestions(stderr: &str) -> Vec<Vec<String>> {
    stderr
        .lines()
        .filter(|l| l.starts_with("warning"))
        .flat_map(|l| l.split('`').skip(1).step_by(2).map(str::to_owned).collect::<Vec<_>>())
        .filter(|code| code.starts_with("--"))
        .map(|code| {
            code.split_whitespace()
                .map(|t| match t {
                    "N" => "0.05".to_string(),
                    "F" => "100".to_string(),
                    "S" => "1000".to_string(),
                    t => t.to_string(),
                })
                .collect()
        })
        .collect()
}

/// Runs `args`, expects warnings with suggestions, and reruns with each suggestion appended.
fn each_suggestion_is_accepted(args: &[&str]) {
    let o: Output = bin().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    let found = suggestions(&err);
    assert!(!found.is_empty(), "{args:?}: no suggestion in {err}");
    // No option outside backticks: every suggestion is runnable as written.
    for line in err.lines().filter(|l| l.starts_with("warning")) {
        let outside: String = line.split('`').step_by(2).collect();
        assert!(!outside.contains(" --"), "an option outside backticks: {line}");
    }
    for extra in found {
        let o = bin().args(args).args(&extra).output().unwrap();
        assert_ne!(
            o.status.code(),
            Some(2),
            "{extra:?} is a usage error: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn cyclopean_and_compare_warnings_suggest_only_options_they_take() {
    let d = scratch("warning-flags");
    let scene = d.join("scene");
    let o = bin()
        .args(["scene", "--width", "64", "--height", "48", "--out-dir", s(&scene)])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The eyes' projections with planes 5 and 6 m in place of 0.05 and 100: every pixel
    // decodes near the far plane (the case, where the warning suggested --ndc).
    let mut wrong: serde_json::Value =
        serde_json::from_slice(&std::fs::read(scene.join("cameras.json")).unwrap()).unwrap();
    for eye in ["left", "right"] {
        wrong[eye]["proj"][2][2] = (-11.0).into();
        wrong[eye]["proj"][2][3] = (-60.0).into();
    }
    let wrong_path = d.join("planes.json");
    std::fs::write(&wrong_path, serde_json::to_vec(&wrong).unwrap()).unwrap();
    let (l_rgb, l_d, r_rgb, r_d) = (
        scene.join("left_rgb.png"),
        scene.join("left_device_depth.exr"),
        scene.join("right_rgb.png"),
        scene.join("right_device_depth.exr"),
    );
    let out = d.join("middle");
    each_suggestion_is_accepted(&[
        "cyclopean",
        "--left-rgb",
        s(&l_rgb),
        "--left-depth",
        s(&l_d),
        "--right-rgb",
        s(&r_rgb),
        "--right-depth",
        s(&r_d),
        "--cameras",
        s(&wrong_path),
        "--out-dir",
        s(&out),
    ]);
    // compare: B's view Z in millimetres given as metres.
    let z = scene.join("middle_view_z.exr");
    let mm = d.join("mm.exr");
    let metres = viewsynth::io::load_depth(&z, &Default::default()).unwrap();
    let data = metres.data.iter().map(|v| v * 1000.0).collect();
    let b = viewsynth::io::DepthMap::new(metres.width, metres.height, data).unwrap();
    viewsynth::io::save_depth_exr(&mm, &b).unwrap();
    let rgb = scene.join("middle_rgb.png");
    each_suggestion_is_accepted(&[
        "compare",
        "--a-rgb",
        s(&rgb),
        "--a-depth",
        s(&z),
        "--b-rgb",
        s(&rgb),
        "--b-depth",
        s(&mm),
    ]);
}
