//! Refusals name the option or file and the exact reason, and exit as the rest do: 2 for a
//! command line that contradicts itself, 1 for what is found while running, never a panic.

use crate::cli::{bin, scratch, RUN_ERROR};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use viewsynth::io::{self, RgbImage};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A negative `--min-disparity` widens both images by its size; past the GPU's image limit
/// (16384 px on llvmpipe) the refusal names the left image, the options and the widening (it
/// named an internal image only).
#[test]
fn a_search_widened_past_the_gpus_limit_names_the_image_and_the_options() {
    let d = scratch("messages-widened");
    let (w, h) = (16300u32, 4u32);
    let image = RgbImage::new(w, h, (0..w * h * 3).map(|i| (i * 13 % 251) as u8).collect()).unwrap();
    let (l, r) = (d.join("left.png"), d.join("right.png"));
    io::save_rgb(&l, &image).unwrap();
    io::save_rgb(&r, &image).unwrap();
    let out = d.join("out");
    let o = bin()
        .args([
            "cyclopean",
            "--left-rgb",
            s(&l),
            "--right-rgb",
            s(&r),
            "--out-dir",
            s(&out),
        ])
        .args(["--min-disparity", "-200", "--max-disparity", "8"])
        .output()
        .unwrap();
    let err = text(&o);
    assert_eq!(o.status.code(), Some(RUN_ERROR), "{err}");
    assert!(
        err.contains("left.png")
            && err.contains("--min-disparity/--max-disparity")
            && err.contains("widened by 200 columns")
            && err.contains("16500x4"),
        "{err}"
    );
    assert!(!out.exists());
}

/// `--device surfaceless --backend vulkan` contradicts itself: exit 2 like other
/// contradictions, before any input is read (it exited 1 when the device was opened).
#[cfg(feature = "vulkan")]
#[test]
fn surfaceless_with_vulkan_is_a_usage_error_on_every_command() {
    let d = scratch("messages-surfaceless");
    let out = d.join("out");
    for args in [
        vec!["info"],
        vec!["scene", "--out-dir", s(&out)],
        vec![
            "cyclopean",
            "--left-rgb",
            "l.png",
            "--right-rgb",
            "r.png",
            "--out-dir",
            s(&out),
        ],
        vec!["stitch", "--scene", "demo", "--out-dir", s(&out)],
    ] {
        let o = bin()
            .args(&args)
            .args(["--device", "surfaceless", "--backend", "vulkan"])
            .output()
            .unwrap();
        let err = text(&o);
        assert_eq!(o.status.code(), Some(crate::cli::USAGE), "{args:?}: {err}");
        assert!(
            err.contains("--device") && err.contains("surfaceless is an EGL choice"),
            "{args:?}: {err}"
        );
    }
    assert!(!out.exists());
}

/// A FIFO where a flow-peer image should be is named as a FIFO, not as missing, before any
/// row is measured (and without opening it, which would block).
#[test]
fn a_fifo_as_a_flow_peer_image_is_named_as_such() {
    let d = scratch("messages-peer-fifo");
    let (data, peer) = (d.join("data"), d.join("flow_peer"));
    crate::lab::demo_and_report::fake_flow_peer(&data, &peer);
    let fifo = peer.join("tsukuba_2_4_3.png");
    std::fs::remove_file(&fifo).unwrap();
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let out = d.join("report");
    let o = bin()
        .args([
            "report",
            "--repeats",
            "1",
            "--out-dir",
            s(&out),
            "--data-dir",
            s(&data),
            "--flow-peer",
            s(&peer),
        ])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let err = text(&o);
    assert_eq!(o.status.code(), Some(RUN_ERROR), "{err}");
    assert!(
        err.contains("tsukuba_2_4_3.png") && err.contains("a FIFO") && !err.contains("missing"),
        "{err}"
    );
    assert!(!out.exists());
}

/// A refused write to stderr (`2>/dev/full`) ends the run with exit 1 on every command that
/// writes notes there (`scene` panicked at its software-renderer note: exit 101); one that
/// writes nothing there (scene on a hardware GPU) succeeds.
#[test]
fn a_full_stderr_is_exit_1_without_a_panic() {
    let d = scratch("messages-full-stderr");
    let (scene, again) = (d.join("scene"), d.join("again"));
    let frame = |f: &str| scene.join(f).display().to_string();
    let cyclopean = |out: &Path| {
        let mut args: Vec<String> = vec!["cyclopean".into()];
        for (flag, f) in [
            ("--left-rgb", "left_rgb.png"),
            ("--right-rgb", "right_rgb.png"),
            ("--left-depth", "left_device_depth.exr"),
            ("--right-depth", "right_device_depth.exr"),
            ("--cameras", "cameras.json"),
        ] {
            args.extend([flag.to_string(), frame(f)]);
        }
        args.extend(["--out-dir".to_string(), out.display().to_string()]);
        args
    };
    let scene_args = |out: &Path| -> Vec<String> {
        ["scene", "--width", "16", "--height", "12", "--out-dir", s(out)]
            .map(String::from)
            .to_vec()
    };
    for (first, second) in [
        (scene_args(&scene), scene_args(&again)),
        (cyclopean(&d.join("c1")), cyclopean(&d.join("c2"))),
    ] {
        let o = bin().args(&first).output().unwrap();
        assert!(o.status.success(), "{first:?}: {}", text(&o));
        let writes_notes = !o.stderr.is_empty();
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let o = bin().args(&second).stderr(full).stdin(Stdio::null()).output().unwrap();
        let expected = if writes_notes { RUN_ERROR } else { 0 };
        assert_eq!(o.status.code(), Some(expected), "{second:?}: {:?}", o.status);
    }
}
