//! `viewsynth compare` for CI: thresholds with exit 1, a mask, the JSON summary ("inf" PSNR), a
//! diff image that does not saturate, and row orders named as the CLI spells them.

use crate::cli::{bin, scratch};
use std::path::{Path, PathBuf};
use std::process::Output;
use viewsynth::io::{self, DepthMap, Mask, RgbImage};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// 8x2 colour, grey 100 with the last column at `last`; view Z 2 m with (0, 0) at `z0`.
fn side(dir: &Path, name: &str, last: u8, z0: f32) -> (PathBuf, PathBuf) {
    let mut color = vec![100u8; 8 * 2 * 3];
    for y in 0..2 {
        color[(y * 8 + 7) * 3..(y * 8 + 8) * 3].fill(last);
    }
    let mut z = vec![2.0f32; 16];
    z[0] = z0;
    let (c, d) = (dir.join(format!("{name}.png")), dir.join(format!("{name}_z.exr")));
    io::save_rgb(&c, &RgbImage::new(8, 2, color).unwrap()).unwrap();
    io::save_depth_exr(&d, &DepthMap::new(8, 2, z).unwrap()).unwrap();
    (c, d)
}

fn compare(a: &(PathBuf, PathBuf), b: &(PathBuf, PathBuf), extra: &[&str]) -> Output {
    bin()
        .args(["compare", "--a-rgb", s(&a.0), "--b-rgb", s(&b.0)])
        .args(["--a-depth", s(&a.1), "--b-depth", s(&b.1)])
        .args(extra)
        .output()
        .unwrap()
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap()
}

#[test]
fn identical_inputs_pass_and_write_inf_psnr() {
    let d = scratch("cmp-same");
    let a = side(&d, "a", 100, 2.0);
    let summary = d.join("summary.json");
    let o = compare(
        &a,
        &a,
        &[
            "--min-psnr",
            "60",
            "--max-colour-rmse",
            "0",
            "--max-depth-rel",
            "0",
            "--json",
            s(&summary),
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let j = json(&summary);
    assert_eq!(
        (j["psnr_db"].as_str(), j["passed"].as_bool()),
        (Some("inf"), Some(true)),
        "{j}"
    );
    assert_eq!(j["thresholds"]["min_psnr_db"], 60.0);
    // Without FILE, the JSON goes to stdout.
    let o = compare(&a, &a, &["--json"]);
    let printed: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(printed["psnr_db"], "inf");
}

#[test]
fn each_broken_threshold_exits_1_and_a_mask_can_exclude_the_difference() {
    let d = scratch("cmp-diff");
    // The last column differs by 40 levels: MSE 40^2 / 8 = 200, RMSE 14.14, PSNR
    // 10 log10(255^2 / 200) = 25.12 dB; depth by 5 % at (0, 0).
    let (a, b) = (side(&d, "a", 100, 2.0), side(&d, "b", 140, 2.1));
    let summary = d.join("summary.json");
    for (flags, needle) in [
        (["--max-colour-rmse", "14"], "colour RMSE 14.1421 > 14"),
        (["--max-color-rmse", "10"], "colour RMSE"),
        (["--min-psnr", "30"], "PSNR 25.12 dB < 30 dB"),
        (["--max-depth-rel", "0.04"], "max relative depth error 5.000e-2 > 4e-2"),
    ] {
        let _ = std::fs::remove_file(&summary);
        let o = compare(&a, &b, &[&flags[..], &["--json", s(&summary)]].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{flags:?}: {err}");
        assert!(
            err.contains("threshold broken") && err.contains(needle),
            "{flags:?}: {err}"
        );
        // The summary is still written, for the CI log.
        let j = json(&summary);
        assert_eq!(
            (j["passed"].as_bool(), j["broken"].as_array().map(Vec::len)),
            (Some(false), Some(1))
        );
    }
    let loose = [
        "--max-colour-rmse",
        "14.2",
        "--min-psnr",
        "25",
        "--max-depth-rel",
        "0.05",
    ];
    assert_eq!(compare(&a, &b, &loose).status.code(), Some(0));
    // Masking out the last column and (0, 0) leaves identical pixels.
    let mask = d.join("mask.png");
    let mut bits = vec![1u8; 16];
    for i in [0, 7, 15] {
        bits[i] = 0;
    }
    io::save_mask_png(&mask, &Mask::new(8, 2, bits).unwrap()).unwrap();
    let o = compare(
        &a,
        &b,
        &[
            "--mask",
            s(&mask),
            "--min-psnr",
            "100",
            "--max-depth-rel",
            "0",
            "--json",
            s(&summary),
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        (json(&summary)["pixels"].as_u64(), json(&summary)["psnr_db"].as_str()),
        (Some(13), Some("inf"))
    );
}

#[test]
fn the_diff_image_is_scaled_to_its_largest_difference() {
    let d = scratch("cmp-image");
    // Differences of 40 and 20 levels: x 255/40 gives 255 and 128, where x 8 would give 255
    // (saturated: 320) and 160.
    let a = side(&d, "a", 100, 2.0);
    let b = side(&d, "b", 140, 2.0);
    let mut c = io::load_rgb(&b.0).unwrap();
    c.data[6 * 3] = 120;
    io::save_rgb(&b.0, &c).unwrap();
    let diff = d.join("diff.png");
    let o = compare(&a, &b, &["--diff", s(&diff)]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && out.contains("x 6.375"), "{out}");
    let img = io::load_rgb(&diff).unwrap();
    assert_eq!(&img.data[6 * 3..8 * 3], [128, 0, 0, 255, 255, 255]);
    assert!(img.data[..6 * 3].iter().all(|v| *v == 0));
}

/// Each depth input is summarised in metres on stderr (device depth converted with the
/// planes), and a depth in millimetres given as view Z warns, naming the side's option.
#[test]
fn depth_inputs_are_summarised_and_an_implausible_range_warns() {
    use viewsynth::convention::{Conventions, DepthPlanes};
    let d = scratch("cmp-summary");
    let a = side(&d, "a", 100, 2.0);
    // B: the same 2 m as GL window depth written with the default planes (0.1, 1000).
    let (conv, planes) = (Conventions::default(), DepthPlanes { near: 0.1, far: 1000.0 });
    let window = DepthPlanes::window_depth_of_ndc_z(&conv, planes.ndc_z_of_view_z(&conv, 2.0)) as f32;
    let b_device = d.join("b_device.exr");
    io::save_depth_exr(&b_device, &DepthMap::new(8, 2, vec![window; 16]).unwrap()).unwrap();
    let device = ["--b-depth-kind", "device", "--b-near", "0.1", "--b-far", "1000"];
    let o = compare(&a, &(a.0.clone(), b_device), &device);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let log = String::from_utf8_lossy(&o.stderr);
    for file in ["a_z.exr", "b_device.exr"] {
        // f32 window depth holds 2 m to ~1e-4 m at these planes: 3 decimals agree.
        let line = format!("{file}: 8x2, 100.0 % valid depth, min 2.000 / median 2.000 / max 2.000 m");
        assert!(log.contains(&line), "{line} not in {log}");
    }
    assert!(!log.contains("warning"), "{log}");
    // Millimetres read as metres: median 2000 m.
    let b_mm = d.join("b_mm.exr");
    io::save_depth_exr(&b_mm, &DepthMap::new(8, 2, vec![2000.0; 16]).unwrap()).unwrap();
    let o = compare(&a, &(a.0.clone(), b_mm), &[]);
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(
        log.contains("b_mm.exr: 8x2, 100.0 % valid depth, min 2000.000")
            && log.contains("warning")
            && log.contains("implausibly far")
            && log.contains("--b-depth-kind"),
        "{log}"
    );
    // Only B's file is wrong.
    let warnings: Vec<&str> = log.lines().filter(|l| l.starts_with("warning")).collect();
    assert!(
        !warnings.is_empty() && warnings.iter().all(|l| l.contains("b_mm.exr")),
        "{log}"
    );
}

#[test]
fn bad_thresholds_and_masks_fail_cleanly() {
    let d = scratch("cmp-bad");
    let a = side(&d, "a", 100, 2.0);
    let o = compare(&a, &a, &["--max-colour-rmse=-1"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("max-colour-rmse"));
    assert_ne!(o.status.code(), Some(0));
    let small = d.join("small.png");
    io::save_mask_png(&small, &Mask::new(2, 2, vec![1; 4]).unwrap()).unwrap();
    let o = compare(&a, &a, &["--mask", s(&small)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.code() == Some(1) && err.contains("small.png") && err.contains("2x2"),
        "{err}"
    );
}

/// The case: the built-in scene written by `viewsynth scene` under GL conventions and
/// as Vulkan reversed-Z at 640x480, where one pixel of 307,200 is off by 140 % in depth.
#[test]
fn gl_against_vulkan_at_640x480_agree_on_every_pixel_and_the_missing_conventions_are_named() {
    let d = scratch("cmp-scene");
    for (dir, extra) in [("gl", &[][..]), ("vk", &["--ndc", "vulkan", "--reversed-z"][..])] {
        let o = bin()
            .args([
                "scene",
                "--width",
                "640",
                "--height",
                "480",
                "--out-dir",
                s(&d.join(dir)),
            ])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let run = |extra: &[&str]| {
        bin()
            .args(["compare", "--near", "0.05", "--far", "100"])
            .args(["--a-rgb", s(&d.join("gl/middle_rgb.png")), "--a-depth-kind", "device"])
            .args(["--a-depth", s(&d.join("gl/middle_device_depth.exr"))])
            .args(["--b-rgb", s(&d.join("vk/middle_rgb.png")), "--b-depth-kind", "device"])
            .args(["--b-depth", s(&d.join("vk/middle_device_depth.exr"))])
            .args(extra)
            .output()
            .unwrap()
    };
    let vk = ["--b-reversed-z"];
    // The ray tracer builds the same rays under every convention (issue 47): no pixel changes
    // surface (once one silhouette pixel did, 1.4 relative), and depth differs only by the f32
    // rounding of each convention's window depth, under 2e-5 (docs/compare.md).
    let o = run(&[&vk[..], &["--max-bad-share", "0.0001", "--max-depth-rel", "2e-5"]].concat());
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        out.contains("max difference 0 levels") && out.contains("over 1.00e-3: 0.00 %"),
        "{out}"
    );
    let o = run(&[&vk[..], &["--max-depth-rel", "1e-7"]].concat());
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("max relative depth error") && err.contains("> 1e-7"),
        "{err}"
    );
    // Without B's conventions the check names reversed-Z (it said nothing at this size).
    let o = run(&["--json"]);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        j["suspicions"][0]
            .as_str()
            .unwrap_or_default()
            .contains("reversed-Z true (declared false"),
        "{j}"
    );
    // The JSON holds both distributions, and the FLIP map is written.
    let flip = d.join("flip.png");
    let o = run(&[&vk[..], &["--json", "--flip-map", s(&flip)]].concat());
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for key in ["median", "p99", "p99_9", "max", "share_over"] {
        assert!(
            !j["color_error"][key].is_null() && !j["depth_rel_error"][key].is_null(),
            "{key}: {j}"
        );
    }
    assert!(j["flip_mean"].as_f64().is_some_and(|m| (0.0..0.01).contains(&m)), "{j}");
    assert_eq!(viewsynth::io::load_rgb(&flip).unwrap().width, 640);
}

/// Gates never pass on nothing: B's depth all NaN leaves no pixel valid in both. Each of A's
/// valid pixels is then a disagreement (a surface against none), so the share gate fails on
/// all of them (it once passed, gating colour alone); both sides without any valid depth
/// compared nothing, and the gate fails saying so.
#[test]
fn the_share_gate_fails_when_no_depth_was_compared() {
    let d = scratch("cmp-nan");
    let a = side(&d, "a", 100, 2.0);
    let b_nan = d.join("b_nan.exr");
    io::save_depth_exr(&b_nan, &DepthMap::new(8, 2, vec![f32::NAN; 16]).unwrap()).unwrap();
    let o = compare(&a, &(a.0.clone(), b_nan.clone()), &["--max-bad-share", "0.01"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("threshold broken")
            && err.contains("100.00 % of the pixels with depth are bad (0 over relative depth error 1e-3 + 16 valid on one side only, of 16)"),
        "{err}"
    );
    let o = compare(
        &(a.0.clone(), b_nan.clone()),
        &(a.0.clone(), b_nan),
        &["--max-bad-share", "0.01"],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("no pixel holds valid depth on either side"), "{err}");
}

/// A pixel with depth on one side only is a disagreement: it counts as bad in the depth share,
/// whose denominator is every pixel with depth on either side, and both counts are in the text
/// and the JSON, beside how each side was read (colour reading, depth kind, planes).
#[test]
fn depth_valid_on_one_side_only_is_bad_and_reported_with_each_sides_reading() {
    let d = scratch("cmp-one-side");
    // A has no depth at pixel 0, B none at pixel 1: one pixel each, 14 valid in both.
    let a = side(&d, "a", 100, f32::NAN);
    let mut z = vec![2.0f32; 16];
    z[1] = f32::NAN;
    let b = (a.0.clone(), d.join("b_z.exr"));
    io::save_depth_exr(&b.1, &DepthMap::new(8, 2, z).unwrap()).unwrap();
    let summary = d.join("s.json");
    let o = compare(&a, &b, &["--max-bad-share", "0.1", "--json", s(&summary)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "2 of 16 is over 10 %: {err}");
    assert!(
        err.contains("12.50 % of the pixels with depth are bad (0 over relative depth error 1e-3 + 2 valid on one side only, of 16)"),
        "{err}"
    );
    let j = json(&summary);
    assert_eq!(
        j["depth_valid"],
        serde_json::json!({"both": 14, "a_only": 1, "b_only": 1}),
        "{j}"
    );
    assert_eq!(j["depth_bad"]["denominator"], 16, "{j}");
    assert_eq!(j["depth_bad"]["share"], 0.125, "{j}");
    assert_eq!(j["a"]["colour"]["channels"], "rgb", "{j}");
    assert_eq!(j["b"]["depth_kind"], "view-z", "{j}");
    assert!(j["b"]["near"].is_null(), "{j}");
    // The text says the same.
    let o = compare(&a, &b, &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("valid in only one: 2 pixels (A only 1, B only 1; valid in both 14)")
            && out.contains("depth bad share: 12.50 % (0 over 1.00e-3 + 2 valid in only one, of 16 pixels with depth)"),
        "{out}"
    );
    // Per-side planes as read, an infinite far plane included.
    let dev = d.join("b_dev.exr");
    io::save_depth_exr(&dev, &DepthMap::new(8, 2, vec![0.5f32; 16]).unwrap()).unwrap();
    let o = compare(
        &a,
        &(a.0.clone(), dev),
        &[
            "--b-depth-kind",
            "device",
            "--b-near",
            "0.1",
            "--b-far",
            "inf",
            "--b-channels",
            "bgr",
            "--json",
        ],
    );
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (
            &j["b"]["depth_kind"],
            &j["b"]["near"],
            &j["b"]["far"],
            &j["b"]["colour"]["channels"]
        ),
        (
            &serde_json::json!("device"),
            &serde_json::json!(0.1),
            &serde_json::json!("inf"),
            &serde_json::json!("bgr")
        ),
        "{j}"
    );
}

/// 32x24 colour with red along x, blue along y and green at `g` (no pixel grey: red and blue
/// differ almost everywhere), top-down; B takes it through `b`.
fn colourful(dir: &Path, b: impl Fn(f64) -> f64, swap: bool) -> (PathBuf, PathBuf) {
    let (w, h) = (32u32, 24u32);
    let (mut ca, mut cb) = (Vec::new(), Vec::new());
    for y in 0..h {
        for x in 0..w {
            let px = [40 + x * 6, 150, 30 + y * 8].map(|v| v as u8);
            ca.extend(px);
            let q = px.map(|v| (b(f64::from(v) / 255.0) * 255.0).round() as u8);
            cb.extend(if swap { [q[2], q[1], q[0]] } else { q });
        }
    }
    let (pa, pb) = (dir.join("a.png"), dir.join("b.png"));
    io::save_rgb(&pa, &RgbImage::new(w, h, ca).unwrap()).unwrap();
    io::save_rgb(&pb, &RgbImage::new(w, h, cb).unwrap()).unwrap();
    (pa, pb)
}

fn colour_only(a: &Path, b: &Path, extra: &[&str]) -> Output {
    bin()
        .args(["compare", "--a-rgb", s(a), "--b-rgb", s(b)])
        .args(extra)
        .output()
        .unwrap()
}

/// The two commonest Vulkan readback mistakes are named, one line each, with the option that
/// reads them; given that option, B matches. (Both scored 11-13 dB with no suspicion before.)
#[test]
fn compare_names_bgr_and_linear_for_srgb_and_ssim_is_reported() {
    use viewsynth::compare::srgb_decode;
    let d = scratch("cmp-colour");
    for (name, b, swap, fix) in [
        ("bgr", (|v| v) as fn(f64) -> f64, true, ["--b-channels", "bgr"]),
        (
            "linear",
            srgb_decode as fn(f64) -> f64,
            false,
            ["--b-transfer", "linear"],
        ),
    ] {
        let dir = d.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = colourful(&dir, b, swap);
        let o = colour_only(&a, &b, &[]);
        let out = String::from_utf8_lossy(&o.stdout);
        let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("suspicion")).collect();
        let named = format!("({})", fix.join(" "));
        assert!(
            matches!(&lines[..], [l] if l.contains("B's colour fits") && l.contains(&named)),
            "{name}: {out}"
        );
        assert!(out.contains("SSIM: 0."), "{name}: {out}");
        // Read as the suspicion says: within a level or two (8-bit linear is coarse in the
        // darks), no suspicion.
        let o = colour_only(&a, &b, &[&fix[..], &["--json"]].concat());
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert!(j["suspicions"].as_array().is_some_and(Vec::is_empty), "{name}: {j}");
        assert!(
            j["color_error"]["p99"].as_f64().is_some_and(|p| p <= 2.0),
            "{name}: {j}"
        );
        assert!(j["ssim"].as_f64().is_some_and(|s| s > 0.99), "{name}: {j}");
    }
}

/// 16-bit colour is compared at 16 bits: one 16-bit level is not 0 error (8-bit loading kept the
/// high byte: both 117, PSNR inf).
#[test]
fn sixteen_bit_colour_is_compared_at_sixteen_bits() {
    let d = scratch("cmp-16");
    let save = |name: &str, last: u16| {
        let p = d.join(name);
        let mut px = vec![30000u16; 16 * 16 * 3];
        px[0] = last;
        image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(16, 16, px)
            .unwrap()
            .save(&p)
            .unwrap();
        p
    };
    let (a, b) = (save("a.png", 30000), save("b.png", 30001));
    let summary = d.join("s.json");
    let o = colour_only(&a, &b, &["--max-colour-rmse", "0", "--json", s(&summary)]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let j = json(&summary);
    // One level of 65535 is 255 / 65535 = 0.0039 8-bit levels.
    assert_eq!(j["max_color_diff"].as_f64(), Some(0.0039), "{j}");
    assert!(j["psnr_db"].as_f64().is_some_and(|p| p > 100.0), "{j}");
    assert_eq!(j["color_bits"], serde_json::json!([16, 16]));
    let o = colour_only(&a, &a, &["--max-colour-rmse", "0"]);
    assert_eq!(o.status.code(), Some(0));
}

/// Window depth of view Z `z` under reversed-Z with an infinite far plane: near / Z.
fn reversed_infinite(z: f32, near: f32) -> f32 {
    near / z
}

/// Each side's planes, an infinite far plane, and no silent default: the case (an
/// infinite-far reversed-Z buffer read with a finite far failed on every pixel, silently).
#[test]
fn per_side_and_infinite_planes_and_no_default_planes() {
    use viewsynth::convention::{Conventions, DepthPlanes};
    let d = scratch("cmp-planes");
    // A: GL standard-Z window depth with (0.1, 100); B: reversed-Z, infinite far, near 0.05.
    let z: Vec<f32> = (0..16 * 12)
        .map(|i| 2.0 + (i % 16) as f32 * 0.25 + (i / 16) as f32 * 0.1)
        .collect();
    let (conv, pa) = (Conventions::default(), DepthPlanes { near: 0.1, far: 100.0 });
    let wa: Vec<f32> = z
        .iter()
        .map(|z| DepthPlanes::window_depth_of_ndc_z(&conv, pa.ndc_z_of_view_z(&conv, f64::from(*z))) as f32)
        .collect();
    let wb: Vec<f32> = z.iter().map(|z| reversed_infinite(*z, 0.05)).collect();
    let rgb = d.join("c.png");
    io::save_rgb(&rgb, &RgbImage::new(16, 12, vec![90; 16 * 12 * 3]).unwrap()).unwrap();
    let (da, db) = (d.join("a.exr"), d.join("b.exr"));
    io::save_depth_exr(&da, &DepthMap::new(16, 12, wa).unwrap()).unwrap();
    io::save_depth_exr(&db, &DepthMap::new(16, 12, wb).unwrap()).unwrap();
    let run = |extra: &[&str]| {
        compare(
            &(rgb.clone(), da.clone()),
            &(rgb.clone(), db.clone()),
            &[
                &[
                    "--a-depth-kind",
                    "device",
                    "--b-depth-kind",
                    "device",
                    "--a-near",
                    "0.1",
                    "--a-far",
                    "100",
                    "--max-bad-share",
                    "0.001",
                ][..],
                extra,
            ]
            .concat(),
        )
    };
    let o = run(&["--b-near", "0.05", "--b-far", "inf", "--b-reversed-z"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.contains("suspicion"), "{out}");
    // Read with far 1000 (the old silent default): every pixel bad, and the reading named.
    let o = run(&["--b-near", "0.05", "--b-far", "1000", "--b-reversed-z"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(
        out.contains("suspicion: B's depth fits an infinite far plane (--b-far inf; declared 1000)"),
        "{out}"
    );
    // No planes for B's device depth: a usage error naming the options, no silent default.
    let o = run(&["--b-reversed-z"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.code() == Some(2) && err.contains("--b-near N --b-far F"),
        "{err}"
    );
}

/// Every convention option changes the reading or is refused (exit 2, saying why): --b-ndc on
/// window depth changed nothing (the same function of Z under either range); it now reads
/// stored NDC z, where the range matters.
#[test]
fn convention_options_change_the_reading_or_are_refused() {
    use viewsynth::convention::{Conventions, DepthPlanes};
    let d = scratch("cmp-ndc");
    let a = side(&d, "a", 100, 2.0);
    // B: GL NDC z of the same 2 m, near 0.1, far 10.
    let (conv, planes) = (Conventions::default(), DepthPlanes { near: 0.1, far: 10.0 });
    let ndc = d.join("b_ndc.exr");
    let v = planes.ndc_z_of_view_z(&conv, 2.0) as f32;
    io::save_depth_exr(&ndc, &DepthMap::new(8, 2, vec![v; 16]).unwrap()).unwrap();
    let b = (a.0.clone(), ndc);
    let as_ndc = |range: &str| {
        compare(
            &a,
            &b,
            &[
                "--b-depth-kind",
                "ndc",
                "--b-ndc",
                range,
                "--b-near",
                "0.1",
                "--b-far",
                "10",
                "--max-depth-rel",
                "1e-4",
            ],
        )
    };
    assert_eq!(as_ndc("gl").status.code(), Some(0));
    assert_eq!(as_ndc("vulkan").status.code(), Some(1), "the range changes the reading");
    for (flags, why) in [
        (
            &[
                "--b-depth-kind",
                "device",
                "--b-near",
                "0.1",
                "--b-far",
                "10",
                "--b-ndc",
                "vulkan",
            ][..],
            "same function of Z",
        ),
        (&["--b-reversed-z"][..], "view-z"),
        (&["--near", "0.1", "--far", "10"][..], "neither side"),
        (
            &["--b-depth-kind", "ndc", "--b-near", "0.1", "--b-far", "10"][..],
            "--b-ndc gl",
        ),
    ] {
        let o = compare(&a, &b, flags);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.code() == Some(2) && err.contains(why), "{flags:?}: {err}");
    }
    // Premultiplied alpha where the file has none: refused, naming the side.
    let o = compare(&a, &a, &["--b-alpha", "premultiplied"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() != Some(0) && err.contains("B alpha"), "{err}");
}
