//! Device choice end to end: `info` lists the EGL devices and the `auto` pick; a software
//! renderer is never silent: refused with exit 1 under `--require-gpu` / VIEWSYNTH_REQUIRE_GPU=1,
//! warned about when an NVIDIA driver is visible. CI renders on llvmpipe; on a hardware
//! renderer the same tests check that nothing is refused.

use crate::cli::{bin, files_in, scratch};
use std::process::Output;

/// `info --json` of this machine, with `env` set (what the other tests compare against).
fn info_json_with(env: &[(&str, &std::path::Path)]) -> serde_json::Value {
    let mut c = bin();
    c.args(["info", "--json"]).env_remove("VIEWSYNTH_REQUIRE_GPU");
    for (k, v) in env {
        c.env(k, v);
    }
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("info --json prints one JSON object")
}

fn info_json() -> serde_json::Value {
    info_json_with(&[])
}

/// CPU rasterisers by the names their drivers give GL_RENDERER (Mesa's llvmpipe, softpipe and
/// swrast, Google's SwiftShader, the Windows "GDI Generic" is not reachable through EGL).
const SOFTWARE_RENDERER_NAMES: [&str; 4] = ["llvmpipe", "softpipe", "swrast", "swiftshader"];

/// Whether `info` renders in software, derived here from the raw GL_RENDERER string, not from
/// the binary's own `software` flag (whose detection is what these tests check).
fn software_by_name(info: &serde_json::Value) -> bool {
    let r = info["renderer"].as_str().expect("renderer").to_ascii_lowercase();
    assert!(!r.is_empty(), "an empty GL_RENDERER: {info}");
    SOFTWARE_RENDERER_NAMES.iter().any(|n| r.contains(n))
}

/// The renderer's name when it is a software one (derived as [`software_by_name`]).
fn software_renderer() -> Option<String> {
    let i = info_json();
    software_by_name(&i).then(|| i["renderer"].as_str().unwrap().to_string())
}

#[test]
fn the_software_flag_agrees_with_the_renderer_name_and_the_egl_device() {
    let i = info_json();
    let by_name = software_by_name(&i);
    assert_eq!(i["software"].as_bool(), Some(by_name), "{i}");
    // On an enumerated EGL device, Mesa marks a CPU device with EGL_MESA_device_software: the
    // raw extension string must tell the same.
    if i["platform"] == "device" {
        let ext = i["device_extensions"].as_str().expect("device_extensions");
        let marked = ext.split_whitespace().any(|e| e == "EGL_MESA_device_software");
        assert_eq!(marked, by_name, "{i}");
    } else {
        assert_eq!(i["platform"], "surfaceless", "{i}");
    }
}

fn assert_refused_naming(o: &Output, renderer: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains(renderer) && err.contains("software"), "{err}");
    assert!(err.contains("--require-gpu") && !err.contains("panicked"), "{err}");
}

#[test]
fn require_gpu_flag_refuses_a_software_renderer() {
    let o = bin()
        .args(["info", "--require-gpu"])
        .env_remove("VIEWSYNTH_REQUIRE_GPU")
        .output()
        .unwrap();
    match software_renderer() {
        Some(r) => {
            assert_refused_naming(&o, &r);
            assert!(o.stdout.is_empty(), "nothing printed on stdout before the refusal");
        }
        None => assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr)),
    }
}

#[test]
fn require_gpu_env_refuses_every_command_before_any_output() {
    let d = scratch("require-gpu-env");
    let out = d.join("scene");
    let o = bin()
        .args(["scene", "--width", "16", "--height", "12", "--out-dir"])
        .arg(&out)
        .env("VIEWSYNTH_REQUIRE_GPU", "1")
        .output()
        .unwrap();
    match software_renderer() {
        Some(r) => {
            assert_refused_naming(&o, &r);
            assert!(files_in(&out).is_empty(), "{:?}", files_in(&out));
        }
        None => assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr)),
    }
    // Switched off explicitly, the same command renders.
    let o = bin()
        .args(["scene", "--width", "16", "--height", "12", "--out-dir"])
        .arg(&out)
        .env("VIEWSYNTH_REQUIRE_GPU", "0")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        files_in(&out).iter().any(|f| f == "cameras.json"),
        "{:?}",
        files_in(&out)
    );
}

#[test]
fn a_mistyped_require_gpu_env_is_an_error_naming_it() {
    let o = bin()
        .arg("info")
        .env("VIEWSYNTH_REQUIRE_GPU", "maybe")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("VIEWSYNTH_REQUIRE_GPU") && err.contains("maybe"), "{err}");
}

#[test]
fn info_lists_every_device_and_the_auto_pick() {
    let i = info_json();
    let devices = i["devices"].as_array().expect("devices array");
    assert_eq!(devices.len() as u64, i["device_count"].as_u64().unwrap());
    for (n, d) in devices.iter().enumerate() {
        assert_eq!(d["index"].as_u64(), Some(n as u64));
        let ext = d["extensions"].as_str().unwrap();
        assert_eq!(
            d["software"].as_bool(),
            Some(ext.split_whitespace().any(|e| e == "EGL_MESA_device_software")),
            "{d}"
        );
    }
    // Auto picks a hardware device whenever there is one.
    let auto = i["auto_device"].as_u64().map(|a| &devices[a as usize]);
    if devices.iter().any(|d| d["software"] == false) {
        assert_eq!(auto.expect("auto pick")["software"], false, "{i}");
    }

    let o = bin().arg("info").env_remove("VIEWSYNTH_REQUIRE_GPU").output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    let expected_pick = match i["auto_device"].as_u64() {
        Some(a) => format!(
            "auto picks device {a} ({})",
            if devices[a as usize]["software"] == true {
                "software"
            } else {
                "hardware"
            }
        ),
        None => "auto picks Mesa surfaceless".into(),
    };
    assert!(text.contains(&format!("EGL devices: {}", devices.len())), "{text}");
    assert!(text.contains(&expected_pick), "{text}");
    for (n, d) in devices.iter().enumerate() {
        let kind = if d["software"] == true { "software" } else { "hardware" };
        assert!(text.contains(&format!("  [{n}] {kind}")), "{text}");
    }
    // The fields info printed before the device list are kept.
    for field in [
        "vendor:",
        "renderer:",
        "GL version:",
        "EGL:",
        "device:",
        "device ext:",
        "limits:",
    ] {
        assert!(text.contains(field), "{field} missing: {text}");
    }
}

#[test]
fn the_device_in_use_is_listed_with_the_renderers_kind() {
    let i = info_json();
    match i["platform"].as_str() {
        Some("device") => {
            let used = i["device_index"].as_u64().expect("device_index on an EGL device") as usize;
            assert_eq!(
                i["devices"][used]["software"].as_bool(),
                Some(software_by_name(&i)),
                "{i}"
            );
        }
        // Mesa without device enumeration: no device is in use.
        Some("surfaceless") => assert!(i["device_index"].is_null(), "{i}"),
        other => panic!("unknown EGL platform {other:?}: {i}"),
    }
}

#[test]
fn software_rendering_with_an_nvidia_vendor_file_visible_warns_loudly() {
    // glvnd reads vendor files from __EGL_VENDOR_LIBRARY_DIRS instead of the system folders:
    // Mesa's plus an NVIDIA one whose library exists but does not load (as when the toolkit
    // mounts the driver without the graphics capability), so glvnd falls back to Mesa.
    let d = scratch("nvidia-vendor");
    let mesa = ["/usr/share/glvnd/egl_vendor.d", "/etc/glvnd/egl_vendor.d"]
        .iter()
        .flat_map(|dir| std::fs::read_dir(dir).into_iter().flatten())
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| std::fs::read_to_string(p).is_ok_and(|t| t.contains("libEGL_mesa")));
    // The GPU tests need EGL through glvnd (ci/install-deps.sh installs libegl1): missing, fail.
    let mesa = mesa.expect("no glvnd vendor file for Mesa (libEGL_mesa) in /usr/share or /etc/glvnd/egl_vendor.d");
    std::fs::copy(&mesa, d.join("50_mesa.json")).unwrap();
    let lib = d.join("libEGL_nvidia.so.0");
    std::fs::write(&lib, b"not an ELF file").unwrap();
    std::fs::write(
        d.join("10_nvidia.json"),
        format!(
            r#"{{"file_format_version":"1.0.0","ICD":{{"library_path":"{}"}}}}"#,
            lib.display()
        ),
    )
    .unwrap();
    let o = bin()
        .arg("info")
        .env("__EGL_VENDOR_LIBRARY_DIRS", &d)
        .env_remove("VIEWSYNTH_REQUIRE_GPU")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    // What Mesa renders on here, named by its own GL_RENDERER: a CPU rasteriser must be warned
    // about (naming it and the NVIDIA file), a Mesa hardware driver must not.
    let info = info_json_with(&[("__EGL_VENDOR_LIBRARY_DIRS", &d)]);
    if software_by_name(&info) {
        let renderer = info["renderer"].as_str().unwrap();
        assert!(err.contains("WARNING") && err.contains("software renderer"), "{err}");
        assert!(err.contains(renderer), "{renderer} not named: {err}");
        assert!(err.contains("10_nvidia.json"), "{err}");
    } else {
        assert!(!err.contains("WARNING"), "a hardware renderer warned about: {err}");
    }
    // Without the NVIDIA file nothing suggests a GPU: no warning.
    std::fs::remove_file(d.join("10_nvidia.json")).unwrap();
    let o = bin()
        .arg("info")
        .env("__EGL_VENDOR_LIBRARY_DIRS", &d)
        .env_remove("VIEWSYNTH_REQUIRE_GPU")
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(!String::from_utf8_lossy(&o.stderr).contains("WARNING"));
}
