//! `--backend vulkan` from the command line: `info` lists the Vulkan devices, `--require-gpu`
//! refuses a CPU (software) device, and `compare` on a Vulkan refocus and a GL refocus of the
//! same frame reports the match within the bounds derived in vulkan_refocus.rs.

use crate::cli::{bin, scratch};
use crate::common::data_dir;
use std::path::Path;
use std::process::Output;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(o: &Output) -> String {
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(o.status.code(), Some(0), "{text}");
    text
}

fn devices_json() -> serde_json::Value {
    let o = bin().args(["info", "--backend", "vulkan", "--json"]).output().unwrap();
    serde_json::from_str(&ok(&o)).expect("info --json prints one JSON object")
}

#[test]
fn info_lists_the_vulkan_devices_with_their_type_and_the_auto_pick() {
    let j = devices_json();
    let devices = j["devices"].as_array().unwrap();
    assert!(
        !devices.is_empty(),
        "no Vulkan device (ci/install-deps.sh installs lavapipe): {j}"
    );
    for d in devices {
        assert!(d["name"].as_str().is_some_and(|n| !n.is_empty()), "{d}");
        let t = d["device_type"].as_str().unwrap();
        assert_eq!(d["software"].as_bool().unwrap(), t == "cpu", "{d}");
    }
    let auto = j["auto_device"].as_u64().expect("a usable device") as usize;
    assert!(devices[auto]["usable"].as_bool().unwrap());
    let text = ok(&bin().args(["info", "--backend", "vulkan"]).output().unwrap());
    assert!(text.contains(&format!("auto picks: device {auto}")), "{text}");
}

#[test]
fn require_gpu_refuses_a_cpu_vulkan_device() {
    let j = devices_json();
    let cpu = j["devices"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["software"].as_bool() == Some(true))
        .expect("lavapipe (a CPU-type Vulkan device) is installed by ci/install-deps.sh");
    let index = cpu["index"].as_u64().unwrap().to_string();
    let o = bin()
        .args(["info", "--backend", "vulkan", "--device", &index, "--require-gpu"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("a hardware GPU is required") && err.contains(cpu["name"].as_str().unwrap()),
        "{err}"
    );
    // The same rule on a rendering command, before any output is written.
    let d = scratch("vk-require");
    let o = tum_refocus()
        .args(["--backend", "vulkan", "--device", &index, "--require-gpu"])
        .args(["--zoom-range", "1", "--out-dir", s(&d.join("out"))])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!d.join("out").join("manifest.json").exists());
}

/// `viewsynth refocus` on the TUM frame with its calibration; options and outputs to add.
fn tum_refocus() -> std::process::Command {
    let frame = data_dir().join("rgbd_open3d_testdata");
    let mut c = bin();
    c.arg("refocus")
        .args([
            "--rgb",
            s(&frame.join("TUM_color.png")),
            "--depth",
            s(&frame.join("TUM_depth.png")),
        ])
        .args([
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
        ]);
    c
}

/// Refocus TUM at scale 1.5 under `backend` and the Vulkan conventions into `out`.
fn refocus(backend: &str, method: &str, out: &Path) {
    let o = tum_refocus()
        .args(["--backend", backend, "--method", method])
        .args([
            "--zoom-range",
            "1.5",
            "--ndc",
            "vulkan",
            "--reversed-z",
            "--rows",
            "top-down",
        ])
        .args(["--out-dir", s(out)])
        .output()
        .unwrap();
    ok(&o);
}

#[test]
fn compare_reports_that_a_vulkan_refocus_matches_the_gl_one() {
    let d = scratch("vk-compare");
    for method in ["fullscreen", "mesh"] {
        let (gl, vk) = (d.join(format!("gl-{method}")), d.join(format!("vk-{method}")));
        refocus("gl", method, &gl);
        refocus("vulkan", method, &vk);
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(vk.join("manifest.json")).unwrap()).unwrap();
        assert!(
            manifest["renderer"].as_str().unwrap().starts_with("Vulkan: "),
            "{manifest}"
        );
        let summary = d.join(format!("summary-{method}.json"));
        // Every colour value within one level gives RMSE <= 1 and PSNR >= 48.1 dB; depth within
        // the 32-ulp bound of vulkan_refocus.rs.
        let o = bin()
            .args([
                "compare",
                "--a-rgb",
                s(&gl.join("s1.5_rgb.png")),
                "--b-rgb",
                s(&vk.join("s1.5_rgb.png")),
            ])
            .args([
                "--a-depth",
                s(&gl.join("s1.5_depth.exr")),
                "--b-depth",
                s(&vk.join("s1.5_depth.exr")),
            ])
            .args([
                "--max-colour-rmse",
                "1",
                "--min-psnr",
                "48",
                "--max-depth-rel",
                "1.9e-6",
            ])
            .args(["--json", s(&summary)])
            .output()
            .unwrap();
        let text = ok(&o);
        let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&summary).unwrap()).unwrap();
        assert_eq!(j["passed"], true, "{text}\n{j}");
        assert_eq!(j["mask_disagreement"], 0, "{j}");
        assert!(j["max_color_diff"].as_f64().unwrap() <= 1.0, "{j}");
        let (mg, mv) = (
            viewsynth::io::load_mask_png(&gl.join("s1.5_mask.png")).unwrap(),
            viewsynth::io::load_mask_png(&vk.join("s1.5_mask.png")).unwrap(),
        );
        assert_eq!(mg.data, mv.data, "{method}: mask files differ");
        assert!(mg.data.iter().any(|&m| m != 0));
    }
}
