//! Hostile input, round 4 (issue 33), one test per class: an empty mesh on Vulkan, stdout that
//! refuses its text, resource limits (`ulimit -f`, `-n`, `-v`), a benchmark whose frames are
//! missing, outputs over inputs or over each other, the previous set's leftovers, streams as
//! `--json` targets, broken out-dir links and FIFOs among cube faces. Each runs the binary; a
//! command with both backends runs on both.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use viewsynth::io::{self, DepthMap, RgbImage};

use crate::cli::{bin, files_in, scratch, temporaries};

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

/// `viewsynth args` under the shell's `ulimit` line `limit` (stdout to `stdout`, a shell path).
fn limited(limit: &str, args: &[&str], stdout: &str) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("{limit}; exec \"$0\" \"$@\" >{stdout}"))
        .arg(env!("CARGO_BIN_EXE_viewsynth"))
        .args(args)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

/// A `w` x `h` colour image and an NPY depth map holding `depth(i)` at pixel i.
fn frame(dir: &Path, tag: &str, w: u32, h: u32, depth: impl Fn(u32) -> f32) -> (PathBuf, PathBuf) {
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
    let (r, d) = (dir.join(format!("{tag}_rgb.png")), dir.join(format!("{tag}_depth.npy")));
    io::save_rgb(&r, &RgbImage::new(w, h, rgb).unwrap()).unwrap();
    io::save_depth_npy(&d, &DepthMap::new(w, h, (0..w * h).map(depth).collect()).unwrap()).unwrap();
    (r, d)
}

fn refocus_args<'a>(rgb: &'a Path, depth: &'a Path, out: &'a Path) -> Vec<&'a str> {
    vec![
        "refocus",
        "--fx",
        "16",
        "--fy",
        "16",
        "--cx",
        "7.5",
        "--cy",
        "5.5",
        "--rgb",
        s(rgb),
        "--depth",
        s(depth),
        "--out-dir",
        s(out),
    ]
}

/// A mesh that keeps no triangle (all-zero depth, or one valid pixel) renders an all-zero mask
/// on both APIs; on Vulkan this crashed in vkResetDescriptorPool (exit 139). In a batch such
/// a frame is a frame like any other, and the good frames beside it are written.
#[test]
fn a_mesh_that_keeps_no_triangle_renders_an_empty_view_on_both_apis() {
    let d = scratch("r4-empty-mesh");
    let (rgb, zero) = frame(&d, "zero", 16, 12, |_| 0.0);
    let (_, one) = frame(&d, "one", 16, 12, |i| if i == 77 { 2.0 } else { 0.0 });
    let (_, good) = frame(&d, "good", 16, 12, |i| 1.0 + 0.01 * (i % 16) as f32);
    for &backend in BACKENDS {
        for depth in [&zero, &one] {
            let out = d.join(format!("out-{backend}"));
            let mut args = refocus_args(&rgb, depth, &out);
            args.extend(["--zoom-range", "1,2", "--method", "mesh", "--backend", backend]);
            let o = bin().args(&args).output().unwrap();
            assert!(
                o.status.success(),
                "{backend} {}: {:?} {}",
                depth.display(),
                o.status,
                text(&o)
            );
            for tag in ["s1", "s2"] {
                let mask = io::load_mask_png(&out.join(format!("{tag}_mask.png"))).unwrap();
                assert!(mask.data.iter().all(|&m| m == 0), "{backend} {tag}: a pixel is valid");
            }
        }
        let manifest = d.join("frames.csv");
        let rows: String = [("a", &good), ("b", &zero), ("c", &one), ("d", &good)]
            .iter()
            .map(|(name, depth)| format!("{},{},16,16,7.5,5.5,{name}\n", s(&rgb), s(depth)))
            .collect();
        std::fs::write(&manifest, format!("rgb,depth,fx,fy,cx,cy,name\n{rows}")).unwrap();
        let out = d.join(format!("batch-{backend}"));
        let o = bin()
            .args([
                "refocus",
                "--batch",
                s(&manifest),
                "--zoom-range",
                "1,2",
                "--method",
                "mesh",
            ])
            .args(["--backend", backend, "--out-dir", s(&out)])
            .output()
            .unwrap();
        assert!(o.status.success(), "batch on {backend}: {:?} {}", o.status, text(&o));
        for name in ["a", "b", "c", "d"] {
            assert!(
                out.join(name).join("manifest.json").is_file(),
                "{backend}: frame {name} missing"
            );
        }
    }
}

/// Every print path turns a refused write to stdout into exit 1 with a message (it panicked
/// with exit 101); refocus prints after its commit, so its files are there.
#[test]
fn a_full_stdout_is_exit_1_with_a_message() {
    let d = scratch("r4-full-stdout");
    let (rgb, depth) = frame(&d, "in", 16, 12, |i| 1.0 + 0.01 * (i % 16) as f32);
    let (a, b) = (s(&rgb).to_string(), d.join("b.png"));
    std::fs::copy(&rgb, &b).unwrap();
    let out = d.join("out");
    let mut refocus = refocus_args(&rgb, &depth, &out);
    refocus.extend(["--zoom-range", "2"]);
    // `viewsynth index` over a batch folder holding one (empty) part: it joins, then prints.
    let batch = d.join("batch");
    std::fs::create_dir_all(&batch).unwrap();
    std::fs::write(batch.join("index.part-0-of-1.jsonl"), "").unwrap();
    let mut cases: Vec<Vec<&str>> = vec![
        vec!["info"],
        vec!["index", s(&batch)],
        vec!["compare", "--a-rgb", &a, "--b-rgb", s(&b), "--json", "-"],
        vec!["compare", "--a-rgb", &a, "--b-rgb", s(&b)],
        refocus,
    ];
    if BACKENDS.contains(&"vulkan") {
        cases.push(vec!["info", "--backend", "vulkan"]);
    }
    for args in cases {
        let o = limited("true", &args, "/dev/full");
        let err = text(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {:?} {err}", o.status);
        assert!(
            err.contains("writing to stdout") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
    assert!(
        out.join("manifest.json").is_file(),
        "refocus had committed before printing"
    );
}

/// `ulimit -f`: the file that grows past it fails with EFBIG, named ("File too large"), exit 1;
/// the folder keeps its previous files and no temporary (SIGXFSZ killed the run, exit 153).
#[test]
fn a_file_size_limit_is_an_error_naming_the_file() {
    let d = scratch("r4-fsize");
    let (rgb, depth) = frame(&d, "in", 64, 48, |i| 1.0 + 0.01 * (i % 64) as f32);
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("s4_rgb.png"), "previous").unwrap();
    let mut args = refocus_args(&rgb, &depth, &out);
    args.extend(["--zoom-range", "4"]);
    for &backend in BACKENDS {
        let mut args = args.clone();
        args.extend(["--backend", backend]);
        let o = limited("ulimit -f 2", &args, "/dev/null");
        let err = text(&o);
        assert_eq!(o.status.code(), Some(1), "{backend}: {:?} {err}", o.status);
        assert!(err.contains("File too large"), "{backend}: {err}");
        assert_eq!(files_in(&out), ["s4_rgb.png"], "{backend}");
        assert_eq!(std::fs::read(out.join("s4_rgb.png")).unwrap(), b"previous");
    }
}

/// Out of descriptors (`ulimit -n 32`, 8 decoders and 8 encoders): the failed frames leave no
/// staging folder (8 to 34 were left, some with partial files).
#[test]
fn running_out_of_descriptors_leaves_no_staging_folder() {
    let d = scratch("r4-nofile");
    let (rgb, depth) = frame(&d, "in", 16, 12, |i| 1.0 + 0.01 * (i % 16) as f32);
    let manifest = d.join("frames.csv");
    let rows: String = (0..16)
        .map(|k| format!("{},{},16,16,7.5,5.5,f{k:02}\n", s(&rgb), s(&depth)))
        .collect();
    std::fs::write(&manifest, format!("rgb,depth,fx,fy,cx,cy,name\n{rows}")).unwrap();
    for limit in [32, 24, 16] {
        let out = d.join(format!("out-{limit}"));
        let args = [
            "refocus",
            "--batch",
            s(&manifest),
            "--jobs",
            "8",
            "--zoom-range",
            "1,2",
            "--out-dir",
            s(&out),
        ];
        let o = limited(&format!("ulimit -n {limit}"), &args, "/dev/null");
        assert!(o.status.code().is_some(), "ulimit -n {limit}: killed: {:?}", o.status);
        let mut left = temporaries(&out);
        for frame in files_in(&out) {
            left.extend(
                temporaries(&out.join(&frame))
                    .into_iter()
                    .map(|t| format!("{frame}/{t}")),
            );
        }
        assert!(left.is_empty(), "ulimit -n {limit} left {left:?}; {}", text(&o));
    }
}

/// Out of address space (`ulimit -v`): where the allocator refuses an image-sized buffer the
/// run ends with exit 1 and an error naming its size (it aborted, exit 134, at the depth
/// readback). The address space a run needs differs between builds (with and without Vulkan,
/// by a few hundred MB) and machines, so the limit where the run starts to succeed is found by
/// bisection first; the 220 MB below it hold the refusal at the readback of the 2560x2560 view
/// (a refusal of some smaller allocation elsewhere still aborts, and is not counted).
#[test]
fn running_out_of_memory_at_a_readback_is_an_error_naming_the_size() {
    let d = scratch("r4-nomem");
    let (rgb, depth) = frame(&d, "in", 1024, 1024, |_| 2.0);
    let run = |mb: u32| {
        let out = d.join(format!("out-{mb}"));
        let mut args = vec![
            "refocus",
            "--fx",
            "1000",
            "--fy",
            "1000",
            "--cx",
            "512",
            "--cy",
            "512",
            "--rgb",
            s(&rgb),
            "--depth",
            s(&depth),
            "--out-dir",
            s(&out),
        ];
        args.extend(["--zoom-range", "2.5"]);
        let o = limited(&format!("ulimit -v {}", mb * 1000), &args, "/dev/null");
        (o, out)
    };
    // Bisection: `low` fails, `high` succeeds.
    let (mut low, mut high) = (100u32, 8000u32);
    assert!(
        run(high).0.status.success(),
        "the run needs more than {high} MB of address space"
    );
    while high - low > 8 {
        let mid = (low + high) / 2;
        match run(mid).0.status.success() {
            true => high = mid,
            false => low = mid,
        }
    }
    let mut named = Vec::new();
    for mb in (high.saturating_sub(220)..high).step_by(10) {
        let (o, out) = run(mb);
        let err = text(&o);
        assert!(!err.contains("src/pass/mod.rs"), "ulimit -v {mb} MB: {err}");
        if err.contains("out of memory:") {
            assert_eq!(o.status.code(), Some(1), "{err}");
            assert!(err.contains("bytes") && err.contains("readback"), "{err}");
            assert!(temporaries(&out).is_empty() && !out.join("manifest.json").exists());
            named.push(mb);
        }
    }
    assert!(
        !named.is_empty(),
        "no limit in the {} MB below the run's {high} MB met the readback",
        220
    );
}

/// `bench --batch MANIFEST` with frames that cannot be read measures nothing: exit 1 naming
/// the frame (it reported the frames that loaded, or 0 frames/s, and exit 0).
#[test]
fn a_benchmark_with_missing_frames_is_refused() {
    let d = scratch("r4-bench-missing");
    let (rgb, depth) = frame(&d, "in", 16, 12, |i| 1.0 + 0.01 * (i % 16) as f32);
    let missing = d.join("missing.npy");
    for rows in [vec![&depth, &missing], vec![&missing, &missing]] {
        let manifest = d.join("frames.csv");
        let body: String = rows
            .iter()
            .enumerate()
            .map(|(k, depth)| format!("{},{},16,16,7.5,5.5,f{k}\n", s(&rgb), s(depth)))
            .collect();
        std::fs::write(&manifest, format!("rgb,depth,fx,fy,cx,cy,name\n{body}")).unwrap();
        let o = bin().args(["bench", "--batch", s(&manifest)]).output().unwrap();
        let err = text(&o);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(err.contains("missing.npy") && err.contains("failed"), "{err}");
    }
}

/// An output that is an input, or another output, is refused by name before any work, by
/// file identity (a hard link is the same file), whatever the spelling; nothing changes.
#[test]
fn outputs_never_land_on_inputs_or_on_each_other() {
    let d = scratch("r4-same-file");
    let (a, depth) = frame(&d, "a", 16, 12, |i| 1.0 + 0.01 * (i % 16) as f32);
    let b = d.join("b.png");
    std::fs::copy(&a, &b).unwrap();
    let mask = d.join("m.png");
    io::save_mask_png(&mask, &io::Mask::new(16, 12, vec![1; 16 * 12]).unwrap()).unwrap();
    let alias = d.join("a-link.png");
    std::fs::hard_link(&a, &alias).unwrap();
    let x = d.join("x.png");
    let dotted = format!("{}/./x.png", s(&d));
    let base = ["compare", "--a-rgb", s(&a), "--b-rgb", s(&b)];
    let cases: Vec<(Vec<&str>, [&str; 2])> = vec![
        (vec!["--diff", s(&x), "--json", &dotted], ["--diff", "--json"]),
        (vec!["--json", s(&a)], ["--a-rgb", "--json"]),
        (vec!["--json", s(&alias)], ["--a-rgb", "--json"]),
        (vec!["--mask", s(&mask), "--diff", s(&mask)], ["--mask", "--diff"]),
        (vec!["--flip-map", s(&b)], ["--b-rgb", "--flip-map"]),
        (vec!["--diff", s(&x), "--flip-map", &dotted], ["--diff", "--flip-map"]),
    ];
    let before: Vec<Vec<u8>> = [&a, &b, &mask].iter().map(|p| std::fs::read(p).unwrap()).collect();
    for (extra, names) in cases {
        let o = bin().args(base).args(&extra).output().unwrap();
        let err = text(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(names.iter().all(|n| err.contains(n)), "{extra:?}: {err}");
        assert!(!x.exists(), "{extra:?} wrote x.png");
    }
    let after: Vec<Vec<u8>> = [&a, &b, &mask].iter().map(|p| std::fs::read(p).unwrap()).collect();
    assert!(before == after, "an input changed");
    // refocus into the folder holding its inputs under the names it writes.
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let (rgb_in, depth_in) = (out.join("s2_rgb.png"), out.join("s2_depth.npy"));
    std::fs::copy(&a, &rgb_in).unwrap();
    std::fs::copy(&depth, &depth_in).unwrap();
    for &backend in BACKENDS {
        let mut args = refocus_args(&rgb_in, &depth_in, &out);
        args.extend(["--zoom-range", "2", "--depth-format", "npy", "--backend", backend]);
        let o = bin().args(&args).output().unwrap();
        let err = text(&o);
        assert_eq!(o.status.code(), Some(2), "{backend}: {err}");
        assert!(err.contains("--out-dir") && err.contains("--rgb"), "{err}");
        assert_eq!(files_in(&out), ["s2_depth.npy", "s2_rgb.png"]);
        assert_eq!(std::fs::read(&rgb_in).unwrap(), before[0]);
    }
}

/// After a successful run the folder holds that run's set: a 3-frame sequence rerun as 2
/// frames leaves no third frame, a cyclopean run without --focal/--baseline no old depth.
#[test]
fn the_previous_sets_leftovers_go_at_commit() {
    let d = scratch("r4-stale");
    let frames = d.join("frames");
    let o = bin()
        .args([
            "scene",
            "--width",
            "48",
            "--height",
            "32",
            "--frames",
            "3",
            "--out-dir",
            s(&frames),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let seq: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(frames.join("sequence.json")).unwrap()).unwrap();
    let two = frames.join("two.json");
    let first_two: Vec<_> = seq["frames"].as_array().unwrap()[..2].to_vec();
    std::fs::write(&two, serde_json::json!({ "frames": first_two }).to_string()).unwrap();
    for &backend in BACKENDS {
        let out = d.join(format!("seq-{backend}"));
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
        for file in [frames.join("sequence.json"), two.clone()] {
            let o = bin()
                .args([
                    "cyclopean",
                    "--sequence",
                    s(&file),
                    "--backend",
                    backend,
                    "--out-dir",
                    s(&out),
                ])
                .output()
                .unwrap();
            assert!(o.status.success(), "{backend}: {}", text(&o));
        }
        let left: Vec<String> = files_in(&out).into_iter().filter(|f| f.contains("00002")).collect();
        assert!(left.is_empty(), "{backend}: {left:?} of the 3-frame run stayed");
        assert_eq!(files_in(&out).len(), 7, "{backend}: {:?}", files_in(&out));
        assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
        let pair = d.join(format!("pair-{backend}"));
        let (left, right) = (frames.join("00000_left_rgb.png"), frames.join("00000_right_rgb.png"));
        let pair_args = [
            "cyclopean",
            "--left-rgb",
            s(&left),
            "--right-rgb",
            s(&right),
            "--max-disparity",
            "16",
            "--backend",
            backend,
            "--out-dir",
            s(&pair),
        ];
        for extra in [&["--focal", "60", "--baseline", "0.06"][..], &[]] {
            let o = bin().args(pair_args).args(extra).output().unwrap();
            assert!(o.status.success(), "{backend} {extra:?}: {}", text(&o));
        }
        assert_eq!(files_in(&pair), ["middle_mask.png", "middle_rgb.png"], "{backend}");
    }
}

/// `--json` naming a character device or FIFO writes it in place, without staging and
/// replacing nothing (it was refused: "a device is in the way").
#[test]
fn json_to_a_device_or_fifo_is_written_in_place() {
    let d = scratch("r4-json-stream");
    let (a, _) = frame(&d, "a", 16, 12, |_| 1.0);
    let base = ["compare", "--a-rgb", s(&a), "--b-rgb", s(&a)];
    let o = bin().args(base).args(["--json", "/dev/stdout"]).output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let json: serde_json::Value =
        serde_json::from_slice(&o.stdout[..o.stdout.iter().rposition(|&c| c == b'}').unwrap() + 1]).unwrap();
    assert_eq!(json["passed"], true);
    let o = bin().args(base).args(["--json", "/dev/null"]).output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let fifo = d.join("fifo");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    // The reader is open before the run starts (a reader thread racing the run's check for
    // one failed under load); the JSON fits the FIFO's buffer, so it is read after the run.
    let mut reader = {
        use std::os::unix::fs::OpenOptionsExt;
        std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NONBLOCK)
            .open(&fifo)
            .unwrap()
    };
    let o = bin().args(base).args(["--json", s(&fifo)]).output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let mut json = String::new();
    std::io::Read::read_to_string(&mut reader, &mut json).unwrap();
    assert!(json.contains("\"passed\": true"), "{json}");
    assert_eq!(temporaries(&d), Vec::<String>::new());
}

/// An out-dir that is a dangling symlink or a symlink loop is refused saying which (it said
/// "File exists (os error 17)"); a FIFO among the cube faces is not a regular file (it was
/// "missing colour").
#[test]
fn broken_out_dir_links_and_fifo_faces_are_named_as_such() {
    let d = scratch("r4-links");
    let (rgb, depth) = frame(&d, "in", 16, 12, |i| 1.0 + 0.01 * (i % 16) as f32);
    let dangling = d.join("dangling");
    std::os::unix::fs::symlink(d.join("nowhere"), &dangling).unwrap();
    let looping = d.join("loop");
    std::os::unix::fs::symlink(&looping, &looping).unwrap();
    for (out, says) in [(&dangling, "dangling symlink"), (&looping, "symlink loop")] {
        let o = bin().args(refocus_args(&rgb, &depth, out)).output().unwrap();
        let err = text(&o);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(err.contains(says) && err.contains(s(out)), "{err}");
    }
    let faces = d.join("faces");
    std::fs::create_dir_all(&faces).unwrap();
    assert!(Command::new("mkfifo")
        .arg(faces.join("left_pz.png"))
        .status()
        .unwrap()
        .success());
    let o = bin()
        .args(["stitch", "--faces", s(&faces), "--out-dir", s(&d.join("ods"))])
        .output()
        .unwrap();
    let err = text(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("left_pz.png") && err.contains("not a regular file"),
        "{err}"
    );
}
