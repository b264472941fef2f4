//! Hostile input, round 4 (issue 33), as classes over every command: an output never lands on
//! an input (one table, every command of `viewsynth --help` in it), and after a successful run
//! the folder holds that run's set (the previous run's files it does not write again go at
//! commit; a file the previous run did not write stays; a failed run changes nothing).

use std::path::{Path, PathBuf};
use std::process::Output;

use viewsynth::io::{self, DepthMap, RgbImage};

use crate::cli::{bin, files_in, scratch};

#[cfg(feature = "vulkan")]
const BACKENDS: &[&str] = &["gl", "vulkan"];
#[cfg(not(feature = "vulkan"))]
const BACKENDS: &[&str] = &["gl"];

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn ok(args: &[&str]) {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", text(&o));
}

/// A `w` x `h` colour PNG and NPY depth map named `{stem}_rgb.png`, `{stem}_depth.npy`.
pub(crate) fn frame(dir: &Path, stem: &str, w: u32, h: u32) -> (PathBuf, PathBuf) {
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
    let (r, d) = (
        dir.join(format!("{stem}_rgb.png")),
        dir.join(format!("{stem}_depth.npy")),
    );
    io::save_rgb(&r, &RgbImage::new(w, h, rgb).unwrap()).unwrap();
    let depth = (0..w * h).map(|i| 1.0 + 0.01 * (i % w) as f32).collect();
    io::save_depth_npy(&d, &DepthMap::new(w, h, depth).unwrap()).unwrap();
    (r, d)
}

/// The 16 x 12 rig every frame of these tests is seen with.
pub(crate) const K: [&str; 8] = ["--fx", "16", "--fy", "16", "--cx", "7.5", "--cy", "5.5"];

/// One hostile command line: `args` writes over the input its option `input` names (so the
/// refusal must name `input` and `output`); `keep` must be unchanged after.
struct Case {
    args: Vec<String>,
    input: &'static str,
    output: &'static str,
    keep: Vec<PathBuf>,
}

/// The commands of `viewsynth --help`.
fn commands() -> Vec<String> {
    let o = run(&["--help"]);
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect()
}

/// A face folder as `stitch --faces` reads it, from `scene --cube-faces`.
fn faces(dir: &Path) -> PathBuf {
    let faces = dir.join("faces");
    ok(&[
        "scene",
        "--width",
        "16",
        "--height",
        "12",
        "--cube-faces",
        "8",
        "--out-dir",
        s(&faces),
    ]);
    faces
}

/// The hostile case of `command`, or why it has none: every command that reads a file an
/// output could be has a case.
fn case(command: &str, d: &Path) -> Result<Case, &'static str> {
    let own = |v: &[&str]| v.iter().map(|a| a.to_string()).collect::<Vec<_>>();
    match command {
        "refocus" => {
            // Its inputs under the names it writes, in its out-dir.
            let out = d.join("refocus");
            std::fs::create_dir_all(&out).unwrap();
            let (rgb, depth) = frame(&out, "s2", 16, 12);
            let mut args = own(&["refocus", "--zoom-range", "2", "--depth-format", "npy"]);
            args.extend(own(&K));
            args.extend(own(&["--rgb", s(&rgb), "--depth", s(&depth), "--out-dir", s(&out)]));
            Ok(Case {
                args,
                input: "--rgb",
                output: "--out-dir",
                keep: vec![rgb, depth],
            })
        }
        "cyclopean" => {
            let out = d.join("cyclopean");
            std::fs::create_dir_all(&out).unwrap();
            let (left, _) = frame(&out, "middle", 16, 12);
            let (right, _) = frame(d, "right", 16, 12);
            let args = own(&[
                "cyclopean",
                "--left-rgb",
                s(&left),
                "--right-rgb",
                s(&right),
                "--max-disparity",
                "4",
                "--out-dir",
                s(&out),
            ]);
            Ok(Case {
                args,
                input: "--left-rgb",
                output: "--out-dir",
                keep: vec![left],
            })
        }
        "reproject" => {
            // The right eye's colour, reprojected to the right eye into its own folder, through a
            // hard link under the name the run writes.
            let out = d.join("reproject");
            std::fs::create_dir_all(&out).unwrap();
            let (rgb, depth) = frame(d, "src", 16, 12);
            std::fs::hard_link(&rgb, out.join("right_rgb.png")).unwrap();
            let mut args = own(&["reproject", "--baseline", "0.06"]);
            args.extend(own(&K));
            args.extend(own(&["--color", s(&rgb), "--depth", s(&depth), "--out-dir", s(&out)]));
            Ok(Case {
                args,
                input: "--color",
                output: "--out-dir",
                keep: vec![rgb, depth],
            })
        }
        "stitch" => {
            // A face symlinked under the stitched image's name in the out-dir.
            let faces = faces(d);
            let out = d.join("stitch");
            std::fs::create_dir_all(&out).unwrap();
            let face = faces.join("left_pz.png");
            std::os::unix::fs::symlink(&face, out.join("ods_top_bottom.png")).unwrap();
            let args = own(&[
                "stitch",
                "--faces",
                s(&faces),
                "--width",
                "32",
                "--height",
                "32",
                "--out-dir",
                s(&out),
            ]);
            Ok(Case {
                args,
                input: "--faces",
                output: "--out-dir",
                keep: vec![face],
            })
        }
        "scene" => {
            // A scene file named as the cameras file the run writes beside its images.
            let out = d.join("scene");
            std::fs::create_dir_all(&out).unwrap();
            let file = out.join("cameras.json");
            let scene = viewsynth::world::builtin("boxes").unwrap();
            std::fs::write(&file, serde_json::to_string(&scene).unwrap()).unwrap();
            let args = own(&[
                "scene",
                "--scene",
                s(&file),
                "--width",
                "16",
                "--height",
                "12",
                "--out-dir",
                s(&out),
            ]);
            Ok(Case {
                args,
                input: "--scene",
                output: "--out-dir",
                keep: vec![file],
            })
        }
        "compare" => {
            let (a, _) = frame(d, "a", 16, 12);
            let (b, _) = frame(d, "b", 16, 12);
            Ok(Case {
                args: own(&["compare", "--a-rgb", s(&a), "--b-rgb", s(&b), "--diff", s(&b)]),
                input: "--b-rgb",
                output: "--diff",
                keep: vec![a, b],
            })
        }
        "manifest" => {
            // A TUM-style sequence whose manifest would replace its own colour listing.
            let seq = d.join("sequence");
            std::fs::create_dir_all(&seq).unwrap();
            let (rgb, depth) = frame(&seq, "f", 16, 12);
            let rgb_list = seq.join("rgb.txt");
            std::fs::write(&rgb_list, format!("# colour\n1.000 {}\n", s(&rgb))).unwrap();
            std::fs::write(seq.join("depth.txt"), format!("# depth\n1.001 {}\n", s(&depth))).unwrap();
            let mut args = own(&["manifest", s(&seq)]);
            args.extend(own(&K));
            args.extend(own(&["--out", s(&rgb_list)]));
            Ok(Case {
                args,
                input: "--rgb-list",
                output: "--out",
                keep: vec![rgb_list],
            })
        }
        "info" => Err("writes no file (stdout only)"),
        "bench" => Err("writes only stdout and its own temporary folder, never a name the user gives"),
        "stress" => Err("reads no file: --json is its only output"),
        "demo" => Err("reads no file: renders the built-in scene"),
        "report" => {
            Err("its inputs (--case, --data-dir) are read-only folders of other names; it writes report.{md,csv,svg}")
        }
        "index" => Err("reads only the index parts it joins and writes index.jsonl, a name no part has"),
        _ => Err(""),
    }
}

/// Every command that writes files refuses, by name and with exit 2 before any work, an
/// output that is one of its inputs (by identity: the name itself, a hard link, a symlink). A
/// command added later fails here until it has a case or a reason. On main, reproject, stitch
/// and scene ran (exit 0) over their inputs.
#[test]
fn no_command_writes_an_output_over_an_input() {
    let d = scratch("r4-outputs-table");
    let commands = commands();
    assert!(commands.len() >= 12, "{commands:?}");
    for command in &commands {
        let dir = d.join(command);
        std::fs::create_dir_all(&dir).unwrap();
        let case = match case(command, &dir) {
            Ok(case) => case,
            Err("") => panic!("`viewsynth {command}` is not in this table: give it a case or a reason"),
            Err(_) => continue,
        };
        let before: Vec<Vec<u8>> = case.keep.iter().map(|p| std::fs::read(p).unwrap()).collect();
        let takes_backend = ["reproject", "stitch", "scene", "refocus", "cyclopean"].contains(&command.as_str());
        for &backend in if takes_backend { BACKENDS } else { &["gl"] } {
            let mut args = case.args.clone();
            if takes_backend {
                args.extend(["--backend".to_string(), backend.to_string()]);
            }
            let o = bin().args(&args).output().unwrap();
            let err = text(&o);
            assert_eq!(o.status.code(), Some(2), "{command} {backend}: {err}");
            assert!(
                err.contains(case.input) && err.contains(case.output),
                "{command}: the refusal names neither {} nor {}: {err}",
                case.input,
                case.output
            );
            let after: Vec<Vec<u8>> = case.keep.iter().map(|p| std::fs::read(p).unwrap()).collect();
            assert!(before == after, "{command} {backend}: an input changed");
        }
    }
}

/// The files of `dir` that are not hidden (the set records are).
fn visible(dir: &Path) -> Vec<String> {
    files_in(dir).into_iter().filter(|f| !f.starts_with('.')).collect()
}

/// A rerun with fewer outputs leaves only its own set: the first run's other files go at
/// commit, the user's files (and the inputs) stay, and a failed rerun changes nothing. On
/// main, every first-run file stayed beside the second set.
#[test]
fn reproject_stitch_and_scene_replace_their_previous_set() {
    let d = scratch("r4-sets");
    for &backend in BACKENDS {
        let be = ["--backend", backend];
        // reproject: rgb, depth and mask, then rgb alone; the source in the same folder.
        let out = d.join(format!("reproject-{backend}"));
        std::fs::create_dir_all(&out).unwrap();
        let (rgb, depth) = frame(&out, "left", 16, 12);
        std::fs::write(out.join("right_notes.txt"), "mine").unwrap();
        let base = [
            "reproject",
            "--baseline",
            "0.06",
            "--from",
            "left",
            "--color",
            s(&rgb),
            "--depth",
            s(&depth),
            "--out-dir",
            s(&out),
        ];
        let with = |extra: &[&'static str]| -> Vec<&str> { [&base[..], &K, &be, extra].concat() };
        ok(&with(&[]));
        let first = visible(&out);
        assert!(first.contains(&"right_mask.png".to_string()), "{first:?}");
        // A failed rerun (depth that holds nothing valid) keeps the first set.
        let zero = d.join("zero_depth.npy");
        io::save_depth_npy(&zero, &DepthMap::new(16, 12, vec![0.0; 192]).unwrap()).unwrap();
        let mut failing = with(&["--outputs", "rgb"]);
        failing[8] = s(&zero);
        assert_eq!(run(&failing).status.code(), Some(1));
        assert_eq!(visible(&out), first, "{backend}: a failed run changed the folder");
        ok(&with(&["--outputs", "rgb"]));
        assert_eq!(
            visible(&out),
            ["left_depth.npy", "left_rgb.png", "right_notes.txt", "right_rgb.png"],
            "{backend}"
        );

        // stitch: both eyes too, then the top-bottom image alone.
        let out = d.join(format!("stitch-{backend}"));
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join("ods_notes.txt"), "mine").unwrap();
        let base = [
            "stitch",
            "--scene",
            "demo",
            "--face-size",
            "16",
            "--width",
            "32",
            "--height",
            "32",
            "--out-dir",
            s(&out),
        ];
        ok(&[&base[..], &be, &["--per-eye"]].concat());
        assert_eq!(visible(&out).len(), 4, "{:?}", visible(&out));
        ok(&[&base[..], &be].concat());
        assert_eq!(visible(&out), ["ods_notes.txt", "ods_top_bottom.png"], "{backend}");

        // scene: 3 frames, then 2; a file of the user's named as a frame's stays.
        let out = d.join(format!("scene-{backend}"));
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join("00009_left_rgb.png"), "mine").unwrap();
        let base = ["scene", "--width", "16", "--height", "12", "--out-dir", s(&out)];
        ok(&[&base[..], &be, &["--frames", "3"]].concat());
        ok(&[&base[..], &be, &["--frames", "2"]].concat());
        let third: Vec<String> = visible(&out).into_iter().filter(|f| f.starts_with("00002_")).collect();
        assert!(third.is_empty(), "{backend}: {third:?} of the 3-frame run stayed");
        assert!(out.join("00009_left_rgb.png").exists());
        assert!(out.join("00001_left_rgb.png").exists() && out.join("sequence.json").exists());
        // One frame writes no prefix and no sequence.json.
        ok(&[&base[..], &be].concat());
        let prefixed: Vec<String> = visible(&out)
            .into_iter()
            .filter(|f| f.starts_with("0000") || f == "sequence.json")
            .collect();
        assert_eq!(prefixed, ["00009_left_rgb.png"], "{backend}");
    }
}

/// refocus (one frame): the previous run's set, as its manifest lists it, goes where the new
/// run does not write the same names (fewer scales, no depth); other files stay.
#[test]
fn refocus_replaces_the_set_its_previous_manifest_lists() {
    let d = scratch("r4-refocus-set");
    let (rgb, depth) = frame(&d, "in", 16, 12);
    for &backend in BACKENDS {
        let out = d.join(format!("out-{backend}"));
        std::fs::create_dir_all(&out).unwrap();
        // The user's file, under a name a scale's files could have.
        std::fs::write(out.join("s3_rgb.png"), "mine").unwrap();
        let base = [
            "refocus",
            "--rgb",
            s(&rgb),
            "--depth",
            s(&depth),
            "--backend",
            backend,
            "--out-dir",
            s(&out),
        ];
        ok(&[&base[..], &K, &["--zoom-range", "1,2"]].concat());
        let first = files_in(&out);
        assert!(first.iter().any(|f| f.starts_with("s2_")), "{first:?}");
        ok(&[&base[..], &K, &["--zoom-range", "1", "--outputs", "rgb"]].concat());
        assert_eq!(
            files_in(&out),
            ["manifest.json", "s1_rgb.png", "s3_rgb.png"],
            "{backend}"
        );
        assert_eq!(std::fs::read_to_string(out.join("s3_rgb.png")).unwrap(), "mine");
    }
}

/// `refocus --batch`: a frame whose colour lies in its own output folder under a name the frame
/// writes is refused before any frame is rendered (a run error: the frame list is a file), the
/// manifest under an index name too; and a frame redone with fewer scales (another setting)
/// leaves only its new set in its folder. On main the batch replaced the frame's input and
/// left the old scale's files.
#[test]
fn a_batch_neither_writes_over_a_frames_input_nor_leaves_a_redone_frames_old_set() {
    let d = scratch("r4-batch-set");
    let out = d.join("out");
    let frame_dir = out.join("f1");
    std::fs::create_dir_all(&frame_dir).unwrap();
    let (rgb, depth) = frame(&frame_dir, "s2", 16, 12);
    let csv =
        |rgb: &Path, depth: &Path| format!("rgb,depth,fx,fy,cx,cy,name\n{},{},16,16,7.5,5.5,f1\n", s(rgb), s(depth));
    let manifest = d.join("frames.csv");
    std::fs::write(&manifest, csv(&rgb, &depth)).unwrap();
    let batch = |manifest: &Path, scales: &str, backend: &str| {
        run(&[
            "refocus",
            "--jobs",
            "1",
            "--zoom-range",
            scales,
            "--backend",
            backend,
            "--batch",
            s(manifest),
            "--out-dir",
            s(&out),
        ])
    };
    let before = std::fs::read(&rgb).unwrap();
    let o = batch(&manifest, "1,2", "gl");
    let err = text(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--batch rgb") && err.contains("s2_rgb.png"), "{err}");
    assert_eq!(std::fs::read(&rgb).unwrap(), before);
    assert_eq!(files_in(&frame_dir), ["s2_depth.npy", "s2_rgb.png"]);
    // The frame list itself named as the index a run writes.
    let index = out.join("index.jsonl");
    std::fs::write(&index, csv(&rgb, &depth)).unwrap();
    let o = batch(&index, "1", "gl");
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("--batch"), "{}", text(&o));
    std::fs::remove_file(&index).unwrap();

    // Inputs elsewhere: scales 1 and 2, then 1 alone (a new setting redoes the frame).
    let src = d.join("src");
    std::fs::create_dir_all(&src).unwrap();
    let (rgb, depth) = frame(&src, "in", 16, 12);
    std::fs::write(&manifest, csv(&rgb, &depth)).unwrap();
    std::fs::remove_dir_all(&frame_dir).unwrap();
    for &backend in BACKENDS {
        let o = batch(&manifest, "1,2", backend);
        assert!(o.status.success(), "{}", text(&o));
        std::fs::write(frame_dir.join("s2_notes.txt"), "mine").unwrap();
        assert!(files_in(&frame_dir).contains(&"s2_rgb.png".to_string()));
        let o = batch(&manifest, "1", backend);
        assert!(o.status.success(), "{}", text(&o));
        let left: Vec<String> = files_in(&frame_dir)
            .into_iter()
            .filter(|f| f.starts_with("s2_"))
            .collect();
        assert_eq!(left, ["s2_notes.txt"], "{backend}");
        std::fs::remove_dir_all(&frame_dir).unwrap();
    }
}
