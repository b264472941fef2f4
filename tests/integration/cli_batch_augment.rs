//! `refocus --batch` for augmentation, through the binary: `--zoom-random` draws the same scales
//! for a frame under a rerun and under shards, and `index.jsonl` lists one row per target after
//! a run, after two shards (the last joins; `viewsynth index` joins by hand) and after a killed
//! and resumed run.

use crate::cli::bin;
use crate::cli_batch::setup;
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
    use std::os::unix::process::ExitStatusExt;
    let (dir, manifest) = setup("augment-kill", 12);
    let out = dir.join("out");
    let heavy = ["--width-out", "800", "--height-out", "600", "--zoom-range", "0.5,1.5"];
    let mut child = bin()
        .args(["refocus", "--jobs", "1", "--batch"])
        .arg(&manifest)
        .arg("--out-dir")
        .arg(&out)
        .args(heavy)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while !out.join("f2/manifest.json").exists() {
        assert!(t0.elapsed().as_secs() < 120, "no frame finished in 120 s");
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
    assert!(!out.join(INDEX_NAME).exists(), "a killed run wrote an index");
    let o = run(&manifest, &out, &heavy);
    assert!(String::from_utf8_lossy(&o.stdout).contains("already done"));
    check_index(&out, 12, 2);
}
