//! Wrong conventions named wherever depth comes in: device depth decoded under the wrong
//! --ndc/--reversed-z/--near/--far warns (reproject on Vulkan reversed-Z depth), and a batch
//! gives every frame the single-frame input checks, applies --depth-scale or refuses flags it
//! cannot apply.

use crate::cli::{bin, scratch};
use std::path::Path;
use viewsynth::io::{self, DepthMap, RgbImage};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn reproject_of_vulkan_reversed_z_depth_without_its_conventions_warns_naming_the_options() {
    let d = scratch("plaus-reproject");
    let scene = d.join("scene_vk");
    let o = bin()
        .args([
            "scene",
            "--width",
            "160",
            "--height",
            "120",
            "--ndc",
            "vulkan",
            "--reversed-z",
        ])
        .args(["--out-dir", s(&scene)])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let run = |extra: &[&str], out: &str| {
        bin()
            .args(["reproject", "--color", s(&scene.join("middle_rgb.png"))])
            .args(["--depth", s(&scene.join("middle_device_depth.exr"))])
            .args(["--depth-kind", "device", "--near", "0.05", "--far", "100"])
            .args(["--fx", "131.25", "--fy", "131.25", "--cx", "79.5", "--cy", "59.5"])
            .args([
                "--from",
                "centre",
                "--to",
                "both",
                "--separation",
                "0.02",
                "--convergence",
                "3",
            ])
            .args(["--out-dir", s(&d.join(out))])
            .args(extra)
            .output()
            .unwrap()
    };
    // The case: min 0.050 / median 0.051 m, exit 0 and no word of it before.
    let o = run(&[], "wrong");
    let t = text(&o);
    let warning = t
        .lines()
        .find(|l| l.starts_with("warning:"))
        .unwrap_or_else(|| panic!("no warning: {t}"));
    for needle in ["within 10 % of the near plane", "--ndc", "--reversed-z", "--near/--far"] {
        assert!(warning.contains(needle), "{needle}: {warning}");
    }
    // With the renderer's conventions: no warning.
    let o = run(&["--ndc", "vulkan", "--reversed-z"], "right");
    assert!(o.status.success() && !text(&o).contains("warning"), "{}", text(&o));
}

/// A 32x24 frame whose depth is a 16-bit PNG of `raw` units (a TUM-style millimetre * 5 map).
fn frame(dir: &Path) {
    let (w, h) = (32u32, 24u32);
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
    io::save_rgb(&dir.join("rgb.png"), &RgbImage::new(w, h, rgb).unwrap()).unwrap();
    // 1.2 m to 1.5 m at 5000 units per metre.
    let raw: Vec<u16> = (0..w * h).map(|i| 6000 + (i % w) as u16 * 50).collect();
    let bytes: Vec<u8> = raw.iter().flat_map(|v| v.to_be_bytes()).collect();
    image::save_buffer(dir.join("depth.png"), &bytes, w, h, image::ExtendedColorType::L16).unwrap();
    let _ = DepthMap::new(1, 1, vec![1.0]);
}

#[test]
fn a_batch_applies_depth_scale_warns_per_frame_and_refuses_what_it_cannot_apply() {
    let d = scratch("plaus-batch");
    frame(&d);
    let manifest = d.join("m.csv");
    std::fs::write(
        &manifest,
        "rgb,depth,fx,fy,cx,cy,name\nrgb.png,depth.png,40,40,15.5,11.5,a\nrgb.png,depth.png,40,40,15.5,11.5,b\n",
    )
    .unwrap();
    let batch = |manifest: &Path, out: &str, extra: &[&str]| {
        bin()
            .args([
                "refocus",
                "--zoom-range",
                "0.5,1.5",
                "--jobs",
                "1",
                "--batch",
                s(manifest),
            ])
            .args(["--out-dir", s(&d.join(out))])
            .args(extra)
            .output()
            .unwrap()
    };
    // Without a depth_scale column, --depth-scale is every frame's scale (it was ignored and
    // every frame failed with "16-bit depth needs --depth-scale").
    let o = batch(&manifest, "scaled", &["--depth-scale", "5000"]);
    assert!(o.status.success() && text(&o).contains("2 rendered"), "{}", text(&o));
    assert!(!text(&o).contains("warning"), "{}", text(&o));
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("scaled/a/manifest.json")).unwrap()).unwrap();
    assert!(m.to_string().contains("5000"), "the scale is recorded: {m}");
    // Without either, each frame fails naming the option.
    let o = batch(&manifest, "unscaled", &[]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("--depth-scale"), "{}", text(&o));
    // A row's own scale wins; a wrong one (median ~270 m) warns once per frame, summarised.
    let wrong = d.join("wrong.csv");
    std::fs::write(&wrong, "rgb,depth,fx,fy,cx,cy,depth_scale,name\nrgb.png,depth.png,40,40,15.5,11.5,25,a\nrgb.png,depth.png,40,40,15.5,11.5,5000,b\nrgb.png,depth.png,40,40,15.5,11.5,25,c\n").unwrap();
    let o = batch(&wrong, "wrong", &["--depth-scale", "5000"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let warned: Vec<&str> = t.lines().filter(|l| l.starts_with("warning: frame ")).collect();
    assert_eq!(warned.len(), 2, "{t}");
    assert!(
        warned[0].starts_with("warning: frame a: depth median depth") && warned[0].contains("implausibly far"),
        "{t}"
    );
    assert!(warned[1].starts_with("warning: frame c:"), "{t}");
    assert!(t.contains("warning: 2 of 3 frames"), "{t}");
    // Flags a batch cannot apply are refused (exit 2), never ignored.
    for flag in [&["--sun-bit-rotate"][..], &["--npz-key", "depth"][..]] {
        let o = batch(&manifest, "refused", flag);
        assert_eq!(o.status.code(), Some(2), "{flag:?}: {}", text(&o));
        assert!(
            text(&o).contains(flag[0]) && text(&o).contains("per frame"),
            "{}",
            text(&o)
        );
        assert!(!d.join("refused").exists());
    }
}
