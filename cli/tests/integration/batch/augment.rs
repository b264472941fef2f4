//! `refocus --batch` for augmentation, through the binary: `--zoom-random` draws the same scales
//! for a frame under a rerun and under shards, and `index.jsonl` lists one row per target after
//! a run, after two shards (the last joins; `viewsynth index` joins by hand) and after a killed
//! and resumed run, and a run killed after an earlier complete one leaves no stale index.

use crate::batch::resume::setup;
use crate::cli::bin;
use std::path::Path;
use std::process::{Output, Stdio};
use viewsynth::refocus::batch::{read_index, IndexRow, INDEX_NAME};

const RANDOM: [&str; 6] = ["--zoom-random", "0.6,1.8", "--samples", "3", "--seed", "7"];

fn run(manifest: &Path, out: &Path, extra: &[&str]) -> Output {
    let o = bin()
        .args(["refocus", "--jobs", "1", "--batch"])
        .arg(manifest)
        .arg("--out-dir")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// The scales and colour file names each frame's manifest records, by frame.
fn frame_scales(out: &Path, frames: usize) -> Vec<(Vec<f64>, Vec<String>)> {
    (0..frames)
        .map(|f| {
            let text = std::fs::read_to_string(out.join(format!("f{f}/manifest.json"))).unwrap();
            let m: serde_json::Value = serde_json::from_str(&text).unwrap();
            let outputs = m["outputs"].as_array().unwrap();
            let recorded: Vec<f64> = m["settings"]["zoom_random"]["scales"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_f64().unwrap())
                .collect();
            let scales: Vec<f64> = outputs.iter().map(|o| o["scale"].as_f64().unwrap()).collect();
            assert_eq!(scales, recorded, "f{f}: targets are not the recorded draw");
            let names = outputs.iter().map(|o| o["rgb"].as_str().unwrap().to_string()).collect();
            (scales, names)
        })
        .collect()
}

fn index(out: &Path) -> Vec<IndexRow> {
    read_index(&out.join(INDEX_NAME)).unwrap()
}

/// One row per target of every frame, in manifest order, and every file it names is there.
fn check_index(out: &Path, frames: usize, per_frame: usize) -> Vec<IndexRow> {
    let rows = index(out);
    assert_eq!(rows.len(), frames * per_frame, "{rows:?}");
    for (i, r) in rows.iter().enumerate() {
        assert_eq!((r.frame_index, r.target), (i / per_frame, i % per_frame));
        assert_eq!(r.frame, format!("f{}", i / per_frame));
        for f in [&r.rgb, &r.depth, &r.mask].into_iter().flatten() {
            assert!(out.join(f).is_file(), "{f} listed but missing");
        }
        assert!(r.coverage.is_some_and(|c| c > 0.0 && c <= 1.0));
        assert!((r.intrinsics.fx / 40.0 - r.scale).abs() < 1e-9);
    }
    rows
}

#[test]
fn zoom_random_draws_three_scales_per_frame_the_same_under_rerun_and_two_shards() {
    let (dir, manifest) = setup("augment-zoom", 2);
    let one = dir.join("one");
    run(&manifest, &one, &RANDOM);
    let drawn = frame_scales(&one, 2);
    for (f, (scales, names)) in drawn.iter().enumerate() {
        assert_eq!(scales.len(), 3);
        assert!(scales.iter().all(|s| (0.6..=1.8).contains(s)), "f{f}: {scales:?}");
        let mut distinct = scales.clone();
        distinct.dedup();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        assert_eq!(distinct.len(), 3, "f{f}: {scales:?}");
        let mut unique = names.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), 3, "f{f}: {names:?}");
    }
    assert_ne!(drawn[0].0, drawn[1].0, "both frames drew the same scales");
    let rows = check_index(&one, 2, 3);

    // A forced rerun draws the same.
    let again = dir.join("again");
    run(&manifest, &again, &[&RANDOM[..], &["--force"]].concat());
    assert_eq!(frame_scales(&again, 2), drawn);

    // Two shards: the first writes its part only, the second joins.
    let shards = dir.join("shards");
    run(&manifest, &shards, &[&RANDOM[..], &["--shard", "0/2"]].concat());
    assert!(!shards.join(INDEX_NAME).exists(), "joined before the last shard");
    run(&manifest, &shards, &[&RANDOM[..], &["--shard", "1/2"]].concat());
    assert_eq!(frame_scales(&shards, 2), drawn);
    let sharded = check_index(&shards, 2, 3);
    let paths = |rows: &[IndexRow]| {
        rows.iter()
            .map(|r| (r.scale, r.rgb.clone(), r.coverage))
            .collect::<Vec<_>>()
    };
    assert_eq!(paths(&sharded), paths(&rows));

    // `viewsynth index` joins the parts by hand; with a part missing it names it.
    std::fs::remove_file(shards.join(INDEX_NAME)).unwrap();
    let o = bin().arg("index").arg(&shards).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(index(&shards), sharded);
    std::fs::remove_file(shards.join("index.part-1-of-2.jsonl")).unwrap();
    let o = bin().arg("index").arg(&shards).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("index.part-1-of-2.jsonl"));
}

#[test]
fn index_has_one_row_per_target_after_a_killed_and_resumed_run() {
    let (dir, manifest) = setup("augment-kill", 12);
    let out = dir.join("out");
    let heavy = ["--width-out", "800", "--height-out", "600", "--zoom-range", "0.5,1.5"];
    kill_batch_when(&manifest, &out, &heavy, "no frame finished", || {
        out.join("f2/manifest.json").exists()
    });
    assert!(!out.join(INDEX_NAME).exists(), "a killed run wrote an index");
    let o = run(&manifest, &out, &heavy);
    assert!(String::from_utf8_lossy(&o.stdout).contains("already done"));
    check_index(&out, 12, 2);
}

/// Runs `refocus --jobs 1 --batch MANIFEST --out-dir OUT ARGS` and kills it (SIGKILL) as soon
/// as `reached()` holds (`what` within 120 s), asserting that it was still running then.
fn kill_batch_when(manifest: &Path, out: &Path, args: &[&str], what: &str, reached: impl Fn() -> bool) {
    use std::os::unix::process::ExitStatusExt;
    let mut child = bin()
        .args(["refocus", "--jobs", "1", "--batch"])
        .arg(manifest)
        .arg("--out-dir")
        .arg(out)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while !reached() {
        assert!(t0.elapsed().as_secs() < 120, "{what} in 120 s");
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    child.kill().unwrap();
    assert_eq!(
        child.wait().unwrap().signal(),
        Some(9),
        "the batch ended before the kill"
    );
}

/// Every row of `index.jsonl` and of each part still there names files that are on disk, and
/// the frame's manifest records the row's scale for its target: no row from before a redo.
fn assert_index_true_to_disk(out: &Path) {
    let mut lists: Vec<_> = std::fs::read_dir(out)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with("index") && n.ends_with(".jsonl"))
        .collect();
    lists.sort();
    for list in lists {
        for r in read_index(&out.join(&list)).unwrap() {
            for f in [&r.rgb, &r.depth, &r.mask].into_iter().flatten() {
                assert!(out.join(f).is_file(), "{list} lists {f}, which is not on disk");
            }
            let text = std::fs::read_to_string(out.join(&r.manifest)).unwrap();
            let m: serde_json::Value = serde_json::from_str(&text).unwrap();
            let scale = m["outputs"][r.target]["scale"].as_f64();
            assert_eq!(
                scale,
                Some(r.scale),
                "{list}: {} target {} is not as on disk",
                r.frame,
                r.target
            );
        }
    }
}

/// A complete run wrote its index; a run with other settings (other scales: each frame it redoes
/// loses the previous files) is killed mid-run. Neither the joined index nor a part may then name
/// the files it removed, nor may `viewsynth index` join such a part; the resumed run lists every
/// frame with the new settings. Before the fix the first run's `index.jsonl` and part stayed
/// until the end of a run, naming f0/s0.5_rgb.png and the like after the kill.
#[test]
fn a_run_killed_after_an_earlier_complete_run_leaves_no_stale_index() {
    let (dir, manifest) = setup("augment-kill-stale", 12);
    let out = dir.join("out");
    let size = ["--width-out", "800", "--height-out", "600"];
    let first = [&size[..], &["--zoom-range", "0.5,1.5"]].concat();
    let second = [&size[..], &["--zoom-range", "0.75"]].concat();
    run(&manifest, &out, &first);
    check_index(&out, 12, 2);

    // Until the third frame is redone: its manifest records the second run's one scale.
    let redone = |f: usize| {
        std::fs::read_to_string(out.join(format!("f{f}/manifest.json")))
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .is_some_and(|m| m["outputs"].as_array().is_some_and(|o| o.len() == 1))
    };
    kill_batch_when(&manifest, &out, &second, "no frame redone", || redone(2));
    assert!(!redone(11), "the last frame was redone before the kill");
    assert!(
        !out.join("f0/s0.5_rgb.png").exists(),
        "the redone frame kept its old set"
    );
    assert_index_true_to_disk(&out);
    // Joining by hand what the killed run left: an error (no part), never a stale index.
    let o = bin().arg("index").arg(&out).output().unwrap();
    assert_index_true_to_disk(&out);
    if o.status.success() {
        check_index(&out, 12, 1);
    }

    let o = run(&manifest, &out, &second);
    assert!(String::from_utf8_lossy(&o.stdout).contains("already done"));
    let rows = check_index(&out, 12, 1);
    assert!(rows.iter().all(|r| r.scale == 0.75), "{rows:?}");
    assert_index_true_to_disk(&out);
}

#[test]
fn zoom_random_on_one_frame_draws_its_samples_from_the_seed() {
    let dir = crate::cli::scratch("zoom-random-one-frame");
    let (data, _) = crate::batch::resume::setup("zoom-random-one-frame-in", 1);
    let run = |out: &str| {
        crate::cli::bin()
            .args(["refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"])
            .arg("--rgb")
            .arg(data.join("rgb0.png"))
            .arg("--depth")
            .arg(data.join("depth0.npy"))
            .args(["--zoom-random", "0.5,2", "--samples", "3", "--seed", "7", "--out-dir"])
            .arg(dir.join(out))
            .output()
            .unwrap()
    };
    let o = run("a");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rgbs = |out: &str| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir.join(out))
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with("_rgb.png"))
            .collect();
        v.sort();
        v
    };
    let a = rgbs("a");
    assert_eq!(a.len(), 3, "{a:?}");
    assert!(a.iter().all(|n| n.starts_with('z')), "{a:?}");
    assert!(run("b").status.success());
    assert_eq!(rgbs("b"), a, "the same seed draws the same scales");
}
