//! The pipelined refocus batch: byte-identical to the synchronous path, shards that partition
//! the manifest, resume that redoes frames whose settings or files changed, and frame folders
//! that cannot lead outside --out-dir.

use super::common::gpu;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use viewsynth::convention::Conventions;
use viewsynth::io::FileFormats;
use viewsynth::io::{self, Encoding, PngCompression};
use viewsynth::refocus::batch::{load_manifest, run_batch, BatchOptions, Shard};
use viewsynth::refocus::{BreakRule, Method, OutputSet};
use viewsynth::scene;

/// A scratch folder with two distinct scene frames listed `n` times in a manifest.
fn setup(name: &str, n: usize) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::Builder::new().prefix(name).tempdir().unwrap();
    let mut csv = String::from("rgb,depth,fx,fy,cx,cy,name\n");
    for (i, (w, h)) in [(64u32, 48u32), (80, 60)].iter().enumerate() {
        let cam = scene::demo_camera(*w, *h);
        let (rgb, depth) = scene::render(&cam);
        io::save_rgb(&dir.path().join(format!("rgb{i}.png")), &rgb).unwrap();
        io::save_depth_npy(&dir.path().join(format!("depth{i}.npy")), &depth).unwrap();
    }
    for f in 0..n {
        let i = f % 2;
        let k = scene::demo_camera([64, 80][i], [48, 60][i]).k;
        csv += &format!("rgb{i}.png,depth{i}.npy,{},{},{},{},f{f}\n", k.fx, k.fy, k.cx, k.cy);
    }
    let manifest = dir.path().join("frames.csv");
    std::fs::write(&manifest, csv).unwrap();
    (dir, manifest)
}

fn options(jobs: usize) -> BatchOptions {
    BatchOptions {
        zoom_random: None,
        rgb_everywhere: false,
        scales: vec![0.5, 1.0, 1.75],
        size: None,
        principal: None,
        rule: BreakRule::default(),
        method: Method::Fullscreen,
        conv: Conventions::default(),
        files: FileFormats {
            outputs: OutputSet::default(),
            depth: viewsynth::io::DepthFormats {
                exr: true,
                npy: true,
                png16: true,
            },
            ..Default::default()
        },
        depth_trunc: None,
        resume: true,
        jobs,
        shard: None,
        index: true,
    }
}

/// Every file under `dir`'s frame folders except manifests (they hold timings), by relative
/// path (the index at the root lists the same files).
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    for frame in std::fs::read_dir(dir).unwrap().flatten().filter(|e| e.path().is_dir()) {
        for f in std::fs::read_dir(frame.path()).unwrap().flatten() {
            let name = f.file_name().to_string_lossy().into_owned();
            if name != "manifest.json" {
                let key = format!("{}/{name}", frame.file_name().to_string_lossy());
                out.insert(key, std::fs::read(f.path()).unwrap());
            }
        }
    }
    out
}

#[test]
fn pipelined_outputs_are_byte_identical_to_the_synchronous_path() {
    let g = gpu();
    let (dir, manifest) = setup("viewsynth-batch-ident-", 5);
    let frames = load_manifest(&manifest).unwrap();
    let sync = run_batch(&g, &frames, &dir.path().join("sync"), &options(0), || ()).unwrap();
    let piped = run_batch(&g, &frames, &dir.path().join("piped"), &options(2), || ()).unwrap();
    assert_eq!(
        (sync.rendered, piped.rendered),
        (5, 5),
        "{:?} {:?}",
        sync.failed,
        piped.failed
    );
    let (a, b) = (files(&dir.path().join("sync")), files(&dir.path().join("piped")));
    assert_eq!(a.len(), 5 * 3 * 5, "rgb, mask, exr, npy and png16 per scale");
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (k, v) in &a {
        assert!(
            v == &b[k],
            "{k} differs between the synchronous and the pipelined batch"
        );
    }
    // Stage times were measured for every frame.
    assert_eq!(piped.stages.decode.len(), 5);
    assert_eq!(piped.stages.encode.len(), 5);
    assert_eq!(piped.stages.readback.len(), 5);
}

#[test]
fn shards_partition_the_manifest() {
    let g = gpu();
    let (dir, manifest) = setup("viewsynth-batch-shard-", 7);
    let frames = load_manifest(&manifest).unwrap();
    let out = dir.path().join("out");
    let mut total = 0;
    for index in 0..3 {
        let opts = BatchOptions {
            shard: Some(Shard { index, count: 3 }),
            ..options(1)
        };
        let s = run_batch(&g, &frames, &out, &opts, || ()).unwrap();
        assert_eq!(s.rendered + s.other_shards, 7);
        total += s.rendered;
    }
    assert_eq!(total, 7);
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let frames: Vec<String> = (0..7).map(|i| format!("f{i}")).collect();
    // The frame folders, each shard's index part and the index the last shard joined.
    let parts = [
        "index.jsonl",
        "index.part-0-of-3.jsonl",
        "index.part-1-of-3.jsonl",
        "index.part-2-of-3.jsonl",
    ];
    assert_eq!(names, [&frames[..], &parts.map(String::from)[..]].concat());
    assert_eq!(
        viewsynth::refocus::batch::read_index(&out.join("index.jsonl"))
            .unwrap()
            .len(),
        7 * 3
    );
    assert!("3/3".parse::<Shard>().is_err() && "1/0".parse::<Shard>().is_err() && "a/2".parse::<Shard>().is_err());
    assert_eq!("2/5".parse::<Shard>().unwrap(), Shard { index: 2, count: 5 });
}

#[test]
fn resume_redoes_frames_whose_settings_or_files_changed() {
    let g = gpu();
    let (dir, manifest) = setup("viewsynth-batch-resume-", 3);
    let frames = load_manifest(&manifest).unwrap();
    let out = dir.path().join("out");
    let first = run_batch(&g, &frames, &out, &options(1), || ()).unwrap();
    assert_eq!(first.rendered, 3);
    let again = run_batch(&g, &frames, &out, &options(1), || ()).unwrap();
    assert_eq!((again.rendered, again.skipped), (0, 3), "same settings: all finished");

    // Other scales: every frame is redone.
    let other = BatchOptions {
        zoom_random: None,
        rgb_everywhere: false,
        scales: vec![0.5, 2.0],
        ..options(1)
    };
    let s = run_batch(&g, &frames, &out, &other, || ()).unwrap();
    assert_eq!((s.rendered, s.skipped), (3, 0));
    // A deleted and a truncated output: only those frames are redone.
    std::fs::remove_file(out.join("f0/s2_rgb.png")).unwrap();
    std::fs::write(out.join("f2/s0.5_mask.png"), b"x").unwrap();
    let s = run_batch(&g, &frames, &out, &other, || ()).unwrap();
    assert_eq!((s.rendered, s.skipped), (2, 1));
    assert!(out.join("f0/s2_rgb.png").is_file());
    // Other compression: redone (the bytes differ); the pixels do not.
    let before = io::load_rgb(&out.join("f1/s2_rgb.png")).unwrap();
    let mut fast = other.clone();
    fast.files.encoding = Encoding {
        png: PngCompression::Best,
        ..Default::default()
    };
    let s = run_batch(&g, &frames, &out, &fast, || ()).unwrap();
    assert_eq!(s.rendered, 3);
    assert_eq!(io::load_rgb(&out.join("f1/s2_rgb.png")).unwrap().data, before.data);
    // An empty manifest.json is not a finished frame.
    std::fs::write(out.join("f1/manifest.json"), b"").unwrap();
    let s = run_batch(&g, &frames, &out, &fast, || ()).unwrap();
    assert_eq!((s.rendered, s.skipped), (1, 2));
    // --force redoes everything.
    let forced = BatchOptions { resume: false, ..fast };
    assert_eq!(run_batch(&g, &frames, &out, &forced, || ()).unwrap().rendered, 3);
    // No temporaries left behind.
    for f in std::fs::read_dir(out.join("f1")).unwrap().flatten() {
        assert!(!f.file_name().to_string_lossy().starts_with(io::TEMP_PREFIX));
    }
}

#[cfg(unix)]
#[test]
fn a_frame_folder_that_is_a_symlink_is_refused_and_nothing_is_written_through_it() {
    let g = gpu();
    let (dir, manifest) = setup("viewsynth-batch-symlink-", 2);
    let frames = load_manifest(&manifest).unwrap();
    let out = dir.path().join("out");
    let elsewhere = dir.path().join("elsewhere");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::create_dir_all(&elsewhere).unwrap();
    std::os::unix::fs::symlink(&elsewhere, out.join("f1")).unwrap();
    let s = run_batch(&g, &frames, &out, &options(1), || ()).unwrap();
    assert_eq!(s.rendered, 1);
    assert_eq!(s.failed.len(), 1);
    assert!(
        s.failed[0].0 == "f1" && s.failed[0].1.contains("symlink"),
        "{:?}",
        s.failed
    );
    assert_eq!(
        std::fs::read_dir(&elsewhere).unwrap().count(),
        0,
        "nothing written outside --out-dir"
    );
}

#[test]
fn the_jobs_limit_is_an_error_not_a_panic() {
    let g = gpu();
    let (dir, manifest) = setup("viewsynth-batch-jobs-", 1);
    let frames = load_manifest(&manifest).unwrap();
    let e = run_batch(&g, &frames, &dir.path().join("o"), &options(30_000), || ()).unwrap_err();
    assert!(e.to_string().contains("jobs"), "{e}");
}
