//! The input formats users already have, through the binary: `--intrinsics FILE` (each format,
//! flags overriding), `.npz` depth (`--npz-key`), and the printed input summary.

use crate::cli::{assert_clean_failure, bin, files_in, scratch, RUN_ERROR, USAGE};
use std::path::{Path, PathBuf};
use std::process::Output;
use viewsynth::io::{self, DepthMap, RgbImage};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A 32x24 colour + view-Z pair (1 to 1.31 m across).
fn inputs(dir: &Path) -> (PathBuf, PathBuf) {
    let (w, h) = (32u32, 24u32);
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i * 7 % 251) as u8).collect();
    let depth: Vec<f32> = (0..w * h).map(|i| 1.0 + 0.01 * (i % w) as f32).collect();
    let (rp, dp) = (dir.join("rgb.png"), dir.join("depth.npy"));
    io::save_rgb(&rp, &RgbImage::new(w, h, rgb).unwrap()).unwrap();
    io::save_depth_npy(&dp, &DepthMap::new(w, h, depth).unwrap()).unwrap();
    (rp, dp)
}

fn refocus(rgb: &Path, depth: &Path, out: &Path, camera: &[&str]) -> Output {
    bin()
        .args([
            "refocus",
            "--zoom-range",
            "1.5",
            "--rgb",
            s(rgb),
            "--depth",
            s(depth),
            "--out-dir",
            s(out),
        ])
        .args(camera)
        .output()
        .unwrap()
}

fn source_of(out: &Path) -> serde_json::Value {
    let m: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    m["source"].clone()
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn refocus_intrinsics_file_in_every_format_matches_the_flags() {
    let d = scratch("k-formats");
    let (rgb, depth) = inputs(&d);
    let flags = d.join("flags");
    ok(&refocus(
        &rgb,
        &depth,
        &flags,
        &["--fx", "40", "--fy", "41", "--cx", "15.5", "--cy", "11.5"],
    ));
    let want_rgb = std::fs::read(flags.join("s1.5_rgb.png")).unwrap();
    let files = [
        ("K.json", "[[40, 0, 15.5], [0, 41, 11.5], [0, 0, 1]]".to_string()),
        ("K.txt", "40 0 15.5\n0 41 11.5\n0 0 1\n".to_string()),
        (
            "open3d.json",
            r#"{"width": 32, "height": 24, "intrinsic_matrix": [40, 0, 0, 0, 41, 0, 15.5, 11.5, 1]}"#.to_string(),
        ),
        // Middlebury cam0 has one f: fy comes from the flag below.
        (
            "calib.txt",
            "cam0=[40 0 15.5; 0 40 11.5; 0 0 1]\nwidth=32\nheight=24\n".to_string(),
        ),
        ("cameras.txt", "# COLMAP\n1 PINHOLE 32 24 40 41 16 12\n".to_string()),
    ];
    for (name, text) in files {
        let path = d.join(name);
        std::fs::write(&path, text).unwrap();
        let out = d.join(format!("out-{name}"));
        let extra: &[&str] = if name == "calib.txt" { &["--fy", "41"] } else { &[] };
        let mut args = vec!["--intrinsics", s(&path)];
        args.extend_from_slice(extra);
        ok(&refocus(&rgb, &depth, &out, &args));
        assert_eq!(source_of(&out), source_of(&flags), "{name}");
        assert_eq!(std::fs::read(out.join("s1.5_rgb.png")).unwrap(), want_rgb, "{name}");
    }
}

#[test]
fn refocus_flags_override_single_values_of_the_file() {
    let d = scratch("k-override");
    let (rgb, depth) = inputs(&d);
    let k = d.join("K.txt");
    std::fs::write(&k, "40 0 15.5\n0 40 11.5\n0 0 1\n").unwrap();
    let out = d.join("out");
    ok(&refocus(
        &rgb,
        &depth,
        &out,
        &["--intrinsics", s(&k), "--cx", "14", "--fx", "38"],
    ));
    let src = source_of(&out);
    assert_eq!((src["fx"].as_f64(), src["fy"].as_f64()), (Some(38.0), Some(40.0)));
    assert_eq!((src["cx"].as_f64(), src["cy"].as_f64()), (Some(14.0), Some(11.5)));
}

#[test]
fn bad_intrinsics_files_fail_cleanly() {
    let d = scratch("k-bad");
    let (rgb, depth) = inputs(&d);
    let out = d.join("out");
    let cases = [
        ("cameras.txt", "1 OPENCV 32 24 40 40 16 12 0.1 0 0 0", "OPENCV"),
        (
            "open3d.json",
            r#"{"width": 64, "height": 48, "intrinsic_matrix": [40,0,0,0,40,0,15.5,11.5,1]}"#,
            "64x48",
        ),
        ("K.json", "[[40, 0, 15.5], [0, 40, 11.5]]", "3x3"),
    ];
    for (name, text, needle) in cases {
        let path = d.join(name);
        std::fs::write(&path, text).unwrap();
        let o = refocus(&rgb, &depth, &out, &["--intrinsics", s(&path)]);
        assert_clean_failure(RUN_ERROR, &o, needle, &out);
        assert_clean_failure(RUN_ERROR, &o, name, &out);
    }
    let o = refocus(&rgb, &depth, &out, &["--fx", "40", "--fy", "40", "--cx", "15.5"]);
    assert_clean_failure(USAGE, &o, "--cy is missing", &out);
    assert!(files_in(&out).iter().all(|f| f.starts_with(".viewsynth-write-test")));
}

#[test]
fn reproject_takes_an_intrinsics_file() {
    let d = scratch("k-reproject");
    let (rgb, depth) = inputs(&d);
    let k = d.join("K.json");
    std::fs::write(
        &k,
        r#"{"K": [40, 0, 15.5, 0, 40, 11.5, 0, 0, 1], "width": 32, "height": 24}"#,
    )
    .unwrap();
    let run = |out: &Path, camera: &[&str]| {
        bin()
            .args([
                "reproject",
                "--color",
                s(&rgb),
                "--depth",
                s(&depth),
                "--baseline",
                "0.05",
                "--out-dir",
                s(out),
            ])
            .args(camera)
            .output()
            .unwrap()
    };
    let (a, b) = (d.join("a"), d.join("b"));
    ok(&run(&a, &["--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"]));
    ok(&run(&b, &["--intrinsics", s(&k)]));
    for f in ["right_rgb.png", "right_depth.exr", "right_mask.png"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    let none = d.join("none");
    assert_clean_failure(USAGE, &run(&none, &[]), "--intrinsics FILE", &none);
}

#[test]
fn reproject_motorcycle_from_npz_disparity_with_a_calib_txt() {
    let d = scratch("npz-motorcycle");
    let data = crate::common::data_dir().join("middlebury2014_motorcycle_skimage");
    let (left, npz) = (data.join("motorcycle_left.png"), data.join("motorcycle_disp.npz"));
    // The published calib.txt scaled to the 4x downsampled pair (the data README's values).
    let calib = d.join("calib.txt");
    std::fs::write(
        &calib,
        "cam0=[994.978 0 311.193; 0 994.978 254.877; 0 0 1]\n\
         cam1=[994.978 0 342.279; 0 994.978 254.877; 0 0 1]\n\
         doffs=31.086\nbaseline=193.001\nwidth=741\nheight=500\n",
    )
    .unwrap();
    // The same disparity as .npy, to check the .npz path reads it identically.
    let npy = d.join("disp.npy");
    io::save_depth_npy(&npy, &io::load_depth(&npz, &io::DepthDecode::default()).unwrap()).unwrap();
    let run = |depth: &Path, out: &Path, extra: &[&str]| {
        bin()
            .args([
                "reproject",
                "--color",
                s(&left),
                "--depth",
                s(depth),
                "--depth-kind",
                "disparity",
            ])
            .args([
                "--baseline",
                "0.193001",
                "--doffs",
                "31.086",
                "--outputs",
                "rgb,mask",
                "--out-dir",
                s(out),
            ])
            .args(extra)
            .output()
            .unwrap()
    };
    let (a, b) = (d.join("npz"), d.join("npy"));
    let log = ok(&run(&npz, &a, &["--intrinsics", s(&calib), "--npz-key", "arr_0"]));
    // 27,226 of 741 x 500 pixels are +inf and d runs 7.19..59.91 px (the data README), so
    // Z = B f / (d + doffs) runs 2.110..5.017 m.
    assert!(
        log.contains("motorcycle_disp.npz: 741x500, 92.7 % valid depth, min 2.110 / median 2.750 / max 5.017 m"),
        "{log}"
    );
    assert!(!log.contains("warning"), "{log}");
    ok(&run(
        &npy,
        &b,
        &[
            "--fx", "994.978", "--fy", "994.978", "--cx", "311.193", "--cy", "254.877",
        ],
    ));
    for f in ["right_rgb.png", "right_mask.png"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    let bad = d.join("bad");
    assert_clean_failure(
        RUN_ERROR,
        &run(&npz, &bad, &["--intrinsics", s(&calib), "--npz-key", "disp"]),
        "no array 'disp' (arrays: arr_0)",
        &bad,
    );
    assert_clean_failure(
        USAGE,
        &run(&npy, &bad, &["--intrinsics", s(&calib), "--npz-key", "arr_0"]),
        "applies to .npz files only",
        &bad,
    );
}

/// stderr of a refocus run on a real RGB-D frame of ../shared/data.
fn refocus_log(color: &str, depth: &str, extra: &[&str]) -> String {
    let d = crate::common::data_dir().join("rgbd_open3d_testdata");
    let out = scratch(&format!("summary-{depth}-{}", extra.join("")));
    let (color, depth) = (d.join(color), d.join(depth));
    let o = refocus(
        &color,
        &depth,
        &out,
        &[
            &[
                "--fx",
                "525",
                "--fy",
                "525",
                "--cx",
                "319.5",
                "--cy",
                "239.5",
                "--outputs",
                "mask",
            ][..],
            extra,
        ]
        .concat(),
    );
    ok(&o)
}

#[test]
fn refocus_prints_the_input_range_and_warns_on_implausible_scales() {
    let tum = refocus_log("TUM_color.png", "TUM_depth.png", &["--depth-scale", "5000"]);
    // The data README: 19 % holes, 1.46 to 9.33 m.
    assert!(
        tum.contains("TUM_depth.png: 640x480, 80.8 % valid depth, min 1.464 / median 2.415 / max 9.331 m"),
        "{tum}"
    );
    assert!(!tum.contains("warning"), "{tum}");
    let sun = refocus_log("SUN_color.jpg", "SUN_depth.png", &["--depth-scale", "1000"]);
    assert!(
        sun.contains("warning") && sun.contains("implausibly far") && sun.contains("--sun-bit-rotate"),
        "{sun}"
    );
    let sun_ok = refocus_log(
        "SUN_color.jpg",
        "SUN_depth.png",
        &["--depth-scale", "1000", "--sun-bit-rotate"],
    );
    assert!(
        sun_ok.contains("max 9.870 m") && !sun_ok.contains("warning"),
        "{sun_ok}"
    );
    // NYU's raw PGM holds Kinect disparity counts, little-endian: no scale makes it metres.
    let nyu = refocus_log("NYU_color.ppm", "NYU_depth.pgm", &["--depth-scale", "1000"]);
    assert!(
        nyu.contains("median 54.275") && nyu.contains("implausibly far"),
        "{nyu}"
    );
}

#[test]
fn cyclopean_warns_when_the_depth_kind_is_wrong() {
    let d = scratch("summary-cyclopean");
    let scene = d.join("scene");
    ok(&bin()
        .args(["scene", "--width", "64", "--height", "48", "--out-dir", s(&scene)])
        .output()
        .unwrap());
    let run = |suffix: &str, out: &Path| {
        let mut c = bin();
        c.args([
            "cyclopean",
            "--cameras",
            s(&scene.join("cameras.json")),
            "--out-dir",
            s(out),
        ]);
        for eye in ["left", "right"] {
            c.arg(format!("--{eye}-rgb")).arg(scene.join(format!("{eye}_rgb.png")));
            c.arg(format!("--{eye}-depth"))
                .arg(scene.join(format!("{eye}_{suffix}.exr")));
        }
        c.output().unwrap()
    };
    let right = ok(&run("device_depth", &d.join("a")));
    assert_eq!(right.matches("input depth").count(), 2, "{right}");
    assert!(!right.contains("warning"), "{right}");
    // View distance where the camera file says device depth: values > 1 are no window depth.
    let wrong = run("view_z", &d.join("b"));
    let log = String::from_utf8_lossy(&wrong.stderr);
    assert!(log.contains("left_view_z.exr: 64x48, 0.0 % valid depth"), "{log}");
    assert!(
        log.contains("warning") && log.contains("no pixel holds valid depth") && log.contains("depth_kind"),
        "{log}"
    );
}
