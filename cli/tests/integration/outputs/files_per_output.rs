//! The output layer end to end, table-driven: every file-writing command (refocus single frame
//! and batch, reproject, cyclopean, stitch, scene) with every
//! `--outputs` subset and every `--depth-format` combination it accepts writes exactly the
//! files its `--help` names for them (each expected name, with the command's placeholder for
//! the view, must appear in the help), and an option a command cannot honour is refused by
//! name with exit 2.

use crate::cli::{bin, files_in, scratch};
use std::path::Path;
use std::process::Output;
use viewsynth::io;

const W: u32 = 32;
const H: u32 = 24;
const OUTPUTS: [&str; 3] = ["rgb", "depth", "mask"];
const DEPTH_FORMATS: [&str; 3] = ["exr", "npy", "png16"];

/// Every non-empty subset of `items`, in order.
fn subsets<'a>(items: &[&'a str]) -> Vec<Vec<&'a str>> {
    (1..1u32 << items.len())
        .map(|bits| {
            items
                .iter()
                .enumerate()
                .filter(|(i, _)| bits & (1 << i) != 0)
                .map(|(_, s)| *s)
                .collect()
        })
        .collect()
}

fn run(args: &[String]) -> Output {
    bin().args(args).output().expect("run viewsynth")
}

fn text(o: &Output) -> String {
    format!(
        "status {:?}\nstdout: {}\nstderr: {}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn help(cmd: &str) -> String {
    let o = run(&[cmd.to_string(), "--help".to_string()]);
    assert!(o.status.success(), "{}", text(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn strs(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// The files of one view named `tag` for these outputs and formats (`rgb_ext`: png, jpg, exr).
fn view_files(tag: &str, outputs: &[&str], depth: &[&str], rgb_ext: &str, preview: bool) -> Vec<String> {
    let mut v = Vec::new();
    if outputs.contains(&"rgb") {
        v.push(format!("{tag}_rgb.{rgb_ext}"));
    }
    if outputs.contains(&"depth") {
        for (format, suffix) in [("exr", "depth.exr"), ("npy", "depth.npy"), ("png16", "depth.png")] {
            if depth.contains(&format) {
                v.push(format!("{tag}_{suffix}"));
            }
        }
        if preview {
            v.push(format!("{tag}_depth_preview.png"));
        }
    }
    if outputs.contains(&"mask") {
        v.push(format!("{tag}_mask.png"));
    }
    v
}

/// One row: a command line (without --out-dir) and the files it must write.
struct Row {
    args: Vec<String>,
    files: Vec<String>,
}

/// Runs every row of `cmd` into a fresh folder and checks the files written against the row and
/// each name, as `named` writes it with the help's placeholder, against the command's help.
fn check(cmd: &str, named: impl Fn(&str) -> String, rows: Vec<Row>, dir: &Path) {
    let help = help(cmd).split_whitespace().collect::<Vec<_>>().join(" ");
    for (i, row) in rows.into_iter().enumerate() {
        let out = dir.join(format!("{cmd}-{i}"));
        let mut args = vec![cmd.to_string()];
        args.extend(row.args.iter().cloned());
        args.extend(["--out-dir".to_string(), out.display().to_string()]);
        let o = run(&args);
        assert!(o.status.success(), "{}: {}", args.join(" "), text(&o));
        let mut want = row.files.clone();
        want.sort();
        assert_eq!(files_in(&out), want, "{}", args.join(" "));
        for f in &row.files {
            let named = named(f);
            assert!(help.contains(&named), "`{cmd} --help` does not name {named} ({f})");
        }
    }
}

/// The rows of a command with --outputs, --depth-format, --rgb-format and --depth-preview.
fn format_rows(base: &[String], tag: &str, extra: &[&str]) -> Vec<Row> {
    let with = |mut files: Vec<String>| {
        files.extend(strs(extra));
        files
    };
    let mut rows = Vec::new();
    for outputs in subsets(&OUTPUTS) {
        let formats = if outputs.contains(&"depth") {
            subsets(&DEPTH_FORMATS)
        } else {
            vec![vec!["exr"]]
        };
        for depth in formats {
            let mut args = base.to_vec();
            args.extend(strs(&[
                "--outputs",
                &outputs.join(","),
                "--depth-format",
                &depth.join(","),
            ]));
            rows.push(Row {
                args,
                files: with(view_files(tag, &outputs, &depth, "png", false)),
            });
        }
    }
    for (format, ext) in [("jpeg", "jpg"), ("exr", "exr")] {
        let mut args = base.to_vec();
        args.extend(strs(&["--rgb-format", format]));
        rows.push(Row {
            args,
            files: with(view_files(tag, &OUTPUTS, &["exr"], ext, false)),
        });
    }
    let mut args = base.to_vec();
    args.push("--depth-preview".into());
    rows.push(Row {
        args,
        files: with(view_files(tag, &OUTPUTS, &["exr"], "png", true)),
    });
    rows
}

/// A W x H frame of the built-in scene (PNG colour, EXR view Z) and its intrinsics options;
/// the colour file follows `colour_flag`.
fn scene_frame(dir: &Path, colour_flag: &str) -> Vec<String> {
    let cam = viewsynth::world::demo_camera(W, H);
    let (rgb, depth) = viewsynth::world::render(&cam);
    let (c, d) = (dir.join("src_rgb.png"), dir.join("src_depth.exr"));
    io::save_rgb(&c, &rgb).unwrap();
    io::save_depth_exr(&d, &depth).unwrap();
    let k = cam.k;
    let mut args = strs(&[
        colour_flag,
        &c.display().to_string(),
        "--depth",
        &d.display().to_string(),
    ]);
    for (flag, v) in [("--fx", k.fx), ("--fy", k.fy), ("--cx", k.cx), ("--cy", k.cy)] {
        // `{}` prints the shortest text that parses back to the same f64.
        args.extend([flag.to_string(), format!("{v}")]);
    }
    args
}

fn refused(args: &[&str], name: &str) {
    let o = run(&strs(args));
    assert_eq!(o.status.code(), Some(2), "{}: {}", args.join(" "), text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(name), "{}: {err}", args.join(" "));
}

#[test]
fn refocus_writes_exactly_the_files_its_help_names_for_every_output_and_format() {
    let d = scratch("table-refocus");
    let mut base = scene_frame(&d, "--rgb");
    base.extend(strs(&["--zoom-range", "1"]));
    let named = |f: &str| f.replacen("s1_", "s{s}_", 1);
    check("refocus", named, format_rows(&base, "s1", &["manifest.json"]), &d);
    // The batch: the same files for every frame, in <out-dir>/<name>/.
    let manifest = d.join("frames.csv");
    let k = viewsynth::world::demo_camera(W, H).k;
    std::fs::write(
        &manifest,
        format!(
            "rgb,depth,fx,fy,cx,cy,name\nsrc_rgb.png,src_depth.exr,{},{},{},{},f0\n",
            k.fx, k.fy, k.cx, k.cy
        ),
    )
    .unwrap();
    for (i, row) in format_rows(&strs(&["--zoom-range", "1"]), "s1", &["manifest.json"])
        .into_iter()
        .enumerate()
    {
        let out = d.join(format!("batch-{i}"));
        let mut args = strs(&["refocus", "--batch", &manifest.display().to_string()]);
        args.extend(row.args);
        args.extend(["--out-dir".to_string(), out.display().to_string()]);
        let o = run(&args);
        assert!(o.status.success(), "{}: {}", args.join(" "), text(&o));
        let mut want = row.files;
        want.sort();
        assert_eq!(files_in(&out.join("f0")), want, "{}", args.join(" "));
    }
    let out = d.join("refused").display().to_string();
    let mut args: Vec<&str> = vec!["refocus"];
    args.extend(base.iter().map(String::as_str));
    args.extend(["--outputs", "rgb,mask", "--depth-preview", "--out-dir", &out]);
    refused(&args, "--depth-preview");
    assert!(!Path::new(&out).exists() || files_in(Path::new(&out)).is_empty());
}

#[test]
fn reproject_writes_exactly_the_files_its_help_names_for_every_output_and_format() {
    let d = scratch("table-reproject");
    let mut base = scene_frame(&d, "--color");
    base.extend(strs(&["--baseline", "0.064"]));
    check(
        "reproject",
        |f| f.replacen("right_", "<target>_", 1),
        format_rows(&base, "right", &[]),
        &d,
    );
    // The 16-bit PNG holds millimetres (0 = invalid) and agrees with the EXR written beside it.
    let out = d.join("png16");
    let mut args = vec!["reproject".to_string()];
    args.extend(base.iter().cloned());
    args.extend(strs(&[
        "--depth-format",
        "exr,png16",
        "--out-dir",
        &out.display().to_string(),
    ]));
    let o = run(&args);
    assert!(o.status.success(), "{}", text(&o));
    let exr = io::load_depth(&out.join("right_depth.exr"), &Default::default()).unwrap();
    let mm = io::load_depth(
        &out.join("right_depth.png"),
        &io::DepthDecode {
            scale: Some(1000.0),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(exr.data.iter().any(|z| *z > 0.0));
    for (z, m) in exr.data.iter().zip(&mm.data) {
        assert!((z - m).abs() <= 0.0005 + 1e-6, "{z} m written as {m} m");
    }
    let out = d.join("refused").display().to_string();
    let mut args: Vec<&str> = vec!["reproject"];
    args.extend(base.iter().map(String::as_str));
    args.extend(["--outputs", "rgb", "--depth-preview", "--out-dir", &out]);
    refused(&args, "--depth-preview");
    let mut args: Vec<&str> = vec!["reproject"];
    args.extend(base.iter().map(String::as_str));
    args.extend(["--depth-format", "exr,tiff", "--out-dir", &out]);
    refused(&args, "tiff");
}

#[test]
fn cyclopean_stitch_and_scene_write_exactly_the_files_their_help_names() {
    let d = scratch("table-views");
    let scene = d.join("scene");
    let files = [
        "cameras.json",
        "left_device_depth.exr",
        "left_rgb.png",
        "left_view_z.exr",
        "middle_device_depth.exr",
        "middle_rgb.png",
        "middle_view_z.exr",
        "right_device_depth.exr",
        "right_rgb.png",
        "right_view_z.exr",
    ];
    let eyes = |f: &str| match f.split_once('_') {
        Some((eye, rest)) if ["left", "right", "middle"].contains(&eye) => format!("{{left,right,middle}}_{rest}"),
        _ => f.to_string(),
    };
    check(
        "scene",
        eyes,
        vec![Row {
            args: strs(&["--width", &W.to_string(), "--height", &H.to_string()]),
            files: strs(&files),
        }],
        &d,
    );
    let _ = std::fs::rename(d.join("scene-0"), &scene);
    let s = |n: &str| scene.join(n).display().to_string();
    let base = strs(&[
        "--left-rgb",
        &s("left_rgb.png"),
        "--left-depth",
        &s("left_device_depth.exr"),
        "--right-rgb",
        &s("right_rgb.png"),
        "--right-depth",
        &s("right_device_depth.exr"),
        "--cameras",
        &s("cameras.json"),
    ]);
    let mut rows: Vec<Row> = subsets(&OUTPUTS)
        .into_iter()
        .map(|outputs| {
            let mut args = base.clone();
            args.extend(strs(&["--outputs", &outputs.join(",")]));
            Row {
                args,
                files: view_files("middle", &outputs, &["exr"], "png", false),
            }
        })
        .collect();
    // Two images alone (the matcher's disparities: no metric depth) with each eye's confidence.
    for outputs in [vec!["rgb"], vec!["mask"], vec!["rgb", "mask"]] {
        let mut files = view_files("middle", &outputs, &["exr"], "png", false);
        files.extend(strs(&viewsynth::job::cyclopean::CONFIDENCE_FILES));
        rows.push(Row {
            args: strs(&[
                "--left-rgb",
                &s("left_rgb.png"),
                "--right-rgb",
                &s("right_rgb.png"),
                "--outputs",
                &outputs.join(","),
                "--confidence",
            ]),
            files,
        });
    }
    check("cyclopean", str::to_string, rows, &d);
    // Depth input has no matcher, so no confidence to write.
    let out = d.join("refused").display().to_string();
    let mut args: Vec<&str> = base.iter().map(String::as_str).collect();
    args.extend(["--confidence", "--out-dir", &out]);
    args.insert(0, "cyclopean");
    refused(&args, "--confidence");
    let base = strs(&[
        "--scene",
        "demo",
        "--face-size",
        "16",
        "--width",
        "64",
        "--height",
        "32",
    ]);
    let mut per_eye = base.clone();
    per_eye.push("--per-eye".into());
    let with = |args: &[String], extra: &[&str]| args.iter().cloned().chain(strs(extra)).collect::<Vec<_>>();
    let rows = vec![
        Row {
            args: base.clone(),
            files: strs(&["ods_top_bottom.png"]),
        },
        Row {
            args: per_eye.clone(),
            files: strs(&["ods_left.png", "ods_right.png", "ods_top_bottom.png"]),
        },
        Row {
            args: with(&base, &["--outputs", "depth"]),
            files: strs(&["ods_top_bottom_depth.exr"]),
        },
        Row {
            args: with(&per_eye, &["--outputs", "rgb,depth"]),
            files: strs(&[
                "ods_left.png",
                "ods_left_depth.exr",
                "ods_right.png",
                "ods_right_depth.exr",
                "ods_top_bottom.png",
                "ods_top_bottom_depth.exr",
            ]),
        },
    ];
    check("stitch", str::to_string, rows, &d);
    // A mask is not a stitch output (distance 0 marks the sky).
    let out = d.join("stitch-refused").display().to_string();
    let mut args: Vec<&str> = base.iter().map(String::as_str).collect();
    args.extend(["--outputs", "rgb,mask", "--out-dir", &out]);
    args.insert(0, "stitch");
    refused(&args, "--outputs");
}

#[test]
fn the_subsets_are_all_of_them() {
    let s = subsets(&OUTPUTS);
    assert_eq!(s.len(), 7);
    assert!(s.contains(&vec!["rgb", "depth", "mask"]) && s.contains(&vec!["mask"]));
}
