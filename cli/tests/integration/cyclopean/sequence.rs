//! `cyclopean --sequence` and `scene --frames`: a sequence renders each frame as one pair would
//! (without `--fill`, byte for byte), with `--fill` the holes take what the last frame's eyes saw
//! before the background fill, and every refusal names its file or flag and leaves the output
//! folder as it was.

use crate::cli::{bin, files_in, scratch, temporaries};
use std::path::{Path, PathBuf};
use std::process::Output;

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn ok(args: &[&str]) {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
}

/// A 320x240 scene sequence of `frames` frames, the head moving `dolly` m right a frame, the
/// spectator `offset` m right of the head.
fn sequence(dir: &Path, frames: u32, dolly: f64, offset: f64) -> PathBuf {
    let out = dir.join("frames");
    ok(&[
        "scene",
        "--width",
        "320",
        "--height",
        "240",
        "--frames",
        &frames.to_string(),
        "--dolly",
        &dolly.to_string(),
        "--spectator-offset",
        &offset.to_string(),
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    out
}

/// Frame `k` of the scene sequence alone, as one pair.
fn alone(frames: &Path, k: u32, fill: bool, out: &Path) {
    let f = |what: &str| frames.join(format!("{k:05}_{what}")).to_str().unwrap().to_string();
    let mut args = vec![
        "cyclopean".to_string(),
        "--left-rgb".into(),
        f("left_rgb.png"),
        "--right-rgb".into(),
        f("right_rgb.png"),
        "--left-depth".into(),
        f("left_device_depth.exr"),
        "--right-depth".into(),
        f("right_device_depth.exr"),
        "--cameras".into(),
        f("cameras.json"),
        "--out-dir".into(),
        out.to_str().unwrap().into(),
    ];
    if fill {
        args.push("--fill".into());
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&args);
}

fn rgb(p: &Path) -> Vec<u8> {
    image::open(p).unwrap().into_rgb8().into_raw()
}

fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let mse = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x as f64 - *y as f64).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    viewsynth::metrics::psnr_from_mse(mse)
}

/// With `--fill` the sequence is complete (mask 255 rendered, 128 filled, never 0), its first
/// frame is the pair's own, and the history helps where the last frame saw what this one
/// misses: against each frame rendered alone with `--fill`, scored over every pixel against
/// the ray-traced spectator view. The spectator sits 0.1 m right of the head, past the right
/// eye, so it sees behind the right side of objects where neither eye does; moving left 0.03 m
/// a frame, the last spectator saw more of that. Measured when written (llvmpipe): every later
/// frame gains 0.24-0.89 dB. The bounds: every frame after the first gains at least 0.1 dB (a
/// history that did nothing gains 0; one that put a foreground edge into a disocclusion, as
/// the first version did, lost up to 1.4 dB on some frames).
#[test]
fn a_filled_sequence_is_complete_and_the_history_fills_what_the_last_frame_saw() {
    let dir = scratch("sequence-fill");
    let frames = sequence(&dir, 6, -0.03, 0.1);
    let out = dir.join("middle");
    ok(&[
        "cyclopean",
        "--sequence",
        frames.join("sequence.json").to_str().unwrap(),
        "--fill",
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    let names = files_in(&out);
    assert_eq!(names.len(), 18, "{names:?}");
    assert!(temporaries(&out).is_empty());
    let mut gains = Vec::new();
    for k in 0..6u32 {
        let mask = image::open(out.join(format!("middle_{k:05}_mask.png")))
            .unwrap()
            .into_luma8();
        assert!(
            mask.iter().all(|m| *m == 255 || *m == 128),
            "frame {k}: a hole in a filled frame"
        );
        let one = dir.join(format!("alone-{k}"));
        alone(&frames, k, true, &one);
        let seq = rgb(&out.join(format!("middle_{k:05}_rgb.png")));
        let single = rgb(&one.join("middle_rgb.png"));
        if k == 0 {
            assert_eq!(seq, single, "the first frame has no history");
        }
        let truth = rgb(&frames.join(format!("{k:05}_middle_rgb.png")));
        gains.push(psnr(&seq, &truth) - psnr(&single, &truth));
    }
    println!("history gain per frame, dB: {gains:.2?}");
    assert!(
        gains[1..].iter().all(|g| *g >= 0.1),
        "a frame gained too little from its history: {gains:.2?}"
    );
}

/// Without `--fill` nothing is filled and nothing carried: each frame's files are those of the
/// pair rendered alone, byte for byte.
#[test]
fn an_unfilled_sequence_is_each_pair_alone() {
    let dir = scratch("sequence-plain");
    let frames = sequence(&dir, 3, -0.03, 0.1);
    let out = dir.join("middle");
    ok(&[
        "cyclopean",
        "--sequence",
        frames.join("sequence.json").to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    for k in 0..3u32 {
        let one = dir.join(format!("alone-{k}"));
        alone(&frames, k, false, &one);
        for (seq, single) in [
            ("rgb.png", "middle_rgb.png"),
            ("mask.png", "middle_mask.png"),
            ("depth.exr", "middle_depth.exr"),
        ] {
            assert_eq!(
                std::fs::read(out.join(format!("middle_{k:05}_{seq}"))).unwrap(),
                std::fs::read(one.join(single)).unwrap(),
                "frame {k} {seq}"
            );
        }
    }
}

/// Two images alone in a sequence: the census matcher is made once and its inputs rewritten in
/// place, and each frame is still byte for byte its pair alone.
#[test]
fn a_sequence_of_pairs_alone_matches_each_pair_alone() {
    let dir = scratch("sequence-images");
    let frames = sequence(&dir, 3, -0.03, 0.0);
    let list: Vec<String> = (0..3)
        .map(|k| format!(r#"{{"left_rgb": "{k:05}_left_rgb.png", "right_rgb": "{k:05}_right_rgb.png"}}"#))
        .collect();
    let file = frames.join("pairs.json");
    std::fs::write(&file, format!(r#"{{"frames": [{}]}}"#, list.join(","))).unwrap();
    let out = dir.join("middle");
    ok(&[
        "cyclopean",
        "--sequence",
        file.to_str().unwrap(),
        "--max-disparity",
        "32",
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    for k in 0..3u32 {
        let one = dir.join(format!("alone-{k}"));
        let f = |what: &str| frames.join(format!("{k:05}_{what}")).to_str().unwrap().to_string();
        ok(&[
            "cyclopean",
            "--left-rgb",
            &f("left_rgb.png"),
            "--right-rgb",
            &f("right_rgb.png"),
            "--max-disparity",
            "32",
            "--out-dir",
            one.to_str().unwrap(),
        ]);
        for (seq, single) in [("rgb.png", "middle_rgb.png"), ("mask.png", "middle_mask.png")] {
            assert_eq!(
                std::fs::read(out.join(format!("middle_{k:05}_{seq}"))).unwrap(),
                std::fs::read(one.join(single)).unwrap(),
                "frame {k} {seq}"
            );
        }
    }
}

/// Refusals: flags that name one pair's files (exit 2), a sequence file that is missing or
/// malformed, a frame's set-up that one pair would refuse, a frame whose file is missing
/// (exit 1, naming the file and the frame). The folder keeps what it held, with no temporary.
#[test]
fn sequence_refusals_name_the_file_or_flag_and_leave_the_folder_as_it_was() {
    let dir = scratch("sequence-refusals");
    let frames = sequence(&dir, 2, 0.03, 0.0);
    let seq = frames.join("sequence.json");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("middle_00000_rgb.png"), b"earlier result").unwrap();
    let check = |args: &[&str], code: i32, says: &[&str]| {
        let mut a = args.to_vec();
        a.extend(["--out-dir", out.to_str().unwrap()]);
        let o = run(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        for s in says {
            assert!(err.contains(s), "{args:?}: '{s}' not in: {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(files_in(&out), ["middle_00000_rgb.png"], "{args:?} changed the folder");
        assert_eq!(
            std::fs::read(out.join("middle_00000_rgb.png")).unwrap(),
            b"earlier result"
        );
    };
    let s = seq.to_str().unwrap();
    check(
        &["cyclopean", "--sequence", s, "--left-rgb", "l.png"],
        2,
        &["--left-rgb", "--sequence"],
    );
    check(&["cyclopean", "--sequence", s, "--confidence"], 2, &["--confidence"]);
    check(
        &["cyclopean", "--sequence", s, "--position", "0.3"],
        1,
        &["sequence.json", "frame 0", "--position"],
    );
    let missing = dir.join("none.json");
    check(
        &["cyclopean", "--sequence", missing.to_str().unwrap()],
        1,
        &["none.json"],
    );
    let write = |name: &str, text: &str| {
        let p = frames.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    // Bounded before reading: a sequence file past the JSON cap is refused by its length.
    let huge = frames.join("huge.json");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(viewsynth::io::MAX_JSON_BYTES + 1)
        .unwrap();
    check(&["cyclopean", "--sequence", huge.to_str().unwrap()], 1, &["huge.json"]);
    let bad = write("bad.json", r#"{"frames": [{"left_rgb": "00000_left_rgb.png"}]}"#);
    check(&["cyclopean", "--sequence", &bad], 1, &["bad.json", "right_rgb"]);
    let half = write(
        "half.json",
        r#"{"frames": [{"left_rgb": "00000_left_rgb.png", "right_rgb": "00000_right_rgb.png", "left_disparity": "d.pfm", "right_depth": "r.exr"}]}"#,
    );
    // A frame mixing set-ups (one eye's disparity alone is a set-up of its own).
    check(
        &["cyclopean", "--sequence", &half],
        1,
        &["half.json", "frame 0", "not both"],
    );
    // The second frame's left depth is missing: the first frame rendered, nothing is written.
    let text = std::fs::read_to_string(&seq)
        .unwrap()
        .replacen("00001_left_device_depth.exr", "gone.exr", 1);
    let gone = write("gone.json", &text);
    check(&["cyclopean", "--sequence", &gone, "--fill"], 1, &["gone.exr"]);
    assert!(temporaries(&out).is_empty());
    // scene: --frames in range, one frame for cube faces.
    for (args, says) in [
        (vec!["scene", "--frames", "0"], "--frames"),
        (vec!["scene", "--frames", "2", "--cube-faces", "8"], "--cube-faces"),
        (vec!["scene", "--frames", "2", "--dolly", "5"], "--dolly"),
    ] {
        let mut a = args.clone();
        a.extend(["--out-dir", out.to_str().unwrap()]);
        let o = run(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
}

/// `--spectator-offset` is metres from the head whatever the IPD: with the eyes together
/// (`--ipd 0`) the middle camera still sits 0.1 m to the right (it once stayed at the head,
/// the offset divided by the IPD).
#[test]
fn the_spectator_offset_is_metres_from_the_head_even_with_no_ipd() {
    let dir = scratch("spectator-offset");
    let out = dir.join("scene");
    ok(&[
        "scene",
        "--width",
        "32",
        "--height",
        "24",
        "--ipd",
        "0",
        "--spectator-offset",
        "0.1",
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    let cams: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("cameras.json")).unwrap()).unwrap();
    // GL view matrices, row-major: the translation's x is minus the camera's x.
    let tx = |eye: &str| cams[eye]["view"][0][3].as_f64().unwrap();
    assert!(
        (tx("left") - tx("middle") - 0.1).abs() < 1e-12,
        "left {} middle {}",
        tx("left"),
        tx("middle")
    );
}
