//! The pipelined refocus batch: byte-identical to the synchronous path, shards that partition
//! the manifest, resume that redoes frames whose settings or files changed, and frame folders
//! that cannot lead outside --out-dir.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use viewsynth::convention::Conventions;
use viewsynth::output::FileFormats;

use viewsynth::io::{self, Encoding, PngCompression};
use viewsynth::refocus::batch::{load_manifest, run_batch, BatchOptions, Shard};
use viewsynth::refocus::{BreakRule, Method, OutputSet};
use viewsynth::world;
use viewsynth_tests::gpu;

/// A scratch folder with two distinct scene frames listed `n` times in a manifest.
fn setup(name: &str, n: usize) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::Builder::new().prefix(name).tempdir().unwrap();
    let mut csv = String::from("rgb,depth,fx,fy,cx,cy,name\n");
    for (i, (w, h)) in [(64u32, 48u32), (80, 60)].iter().enumerate() {
        let cam = world::demo_camera(*w, *h);
        let (rgb, depth) = world::render(&cam);
        io::save_rgb(&dir.path().join(format!("rgb{i}.png")), &rgb).unwrap();
        io::save_depth_npy(&dir.path().join(format!("depth{i}.npy")), &depth).unwrap();
    }
    for f in 0..n {
        let i = f % 2;
        let k = world::demo_camera([64, 80][i], [48, 60][i]).k;
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
            depth: viewsynth::output::DepthFormats {
                exr: true,
                npy: true,
                png16: true,
                png16_units: Default::default(),
            },
            ..Default::default()
        },
        depth_trunc: None,
        resume: true,
        verify: false,
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

/// Every output kind the batch writes decodes to the values rendered (issue 35: the faster
/// encode paths change no pixel or depth): colour PNG and EXR, depth EXR and NPY and the mask
/// bit for bit, depth PNG16 to the millimetre it rounds to, JPEG within its loss. The TUM frame,
/// the default scales, the synchronous and the pipelined batch; the reference is the same frame
/// rendered by a `Refocuser` and kept in memory.
#[test]
fn every_output_kind_reads_back_as_rendered() {
    use viewsynth::io::DepthDecode;
    use viewsynth::output::{DepthFormats, RgbFormat};
    use viewsynth::refocus::manifest::{scale_tag, TargetSpec, DEFAULT_SCALES};
    use viewsynth::refocus::{RefocusSource, Refocuser};
    let data = viewsynth_tests::data_dir().join("rgbd_open3d_testdata");
    let (rgb_path, depth_path) = (data.join("TUM_color.png"), data.join("TUM_depth.png"));
    let dir = tempfile::Builder::new().prefix("readback-kinds").tempdir().unwrap();
    let manifest = dir.path().join("frames.csv");
    std::fs::write(
        &manifest,
        format!(
            "rgb,depth,fx,fy,cx,cy,depth_scale,name\n{},{},525,525,319.5,239.5,5000,tum\n",
            rgb_path.display(),
            depth_path.display()
        ),
    )
    .unwrap();
    let frames = load_manifest(&manifest).unwrap();

    // The rendered values, in memory.
    let decode = DepthDecode {
        scale: Some(5000.0),
        ..Default::default()
    };
    let src = RefocusSource::new(
        io::load_rgb(&rgb_path).unwrap(),
        io::load_depth(&depth_path, &decode).unwrap(),
        viewsynth::camera::Intrinsics {
            fx: 525.0,
            fy: 525.0,
            cx: 319.5,
            cy: 239.5,
        },
    )
    .unwrap();
    let gpu = gpu();
    let mut refocuser = Refocuser::with_settings(
        &gpu,
        &BreakRule::default(),
        Method::Fullscreen,
        OutputSet::default(),
        Conventions::default(),
    )
    .unwrap();
    refocuser.set_source(&src).unwrap();
    let targets = TargetSpec {
        scales: DEFAULT_SCALES.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&src.camera())
    .unwrap();
    let rendered: Vec<_> = targets
        .iter()
        .map(|t| refocuser.submit(t).unwrap().wait().unwrap())
        .collect();

    let bits = |v: &[f32]| v.iter().map(|z| z.to_bits()).collect::<Vec<_>>();
    for (jobs, rgb_format) in [(0, RgbFormat::Png), (2, RgbFormat::Exr), (0, RgbFormat::Jpeg)] {
        let mut opts = options(jobs);
        opts.scales = DEFAULT_SCALES.to_vec();
        opts.files = FileFormats {
            rgb: rgb_format,
            depth: DepthFormats {
                exr: true,
                npy: true,
                png16: true,
                png16_units: Default::default(),
            },
            ..Default::default()
        };
        let out = dir.path().join(format!("out-{jobs}-{}", rgb_format.extension()));
        let summary = run_batch(&gpu, &frames, &out, &opts, || ()).unwrap();
        assert!(summary.failed.is_empty(), "{:?}", summary.failed);
        for (&scale, want) in DEFAULT_SCALES.iter().zip(&rendered) {
            let tag = scale_tag(scale);
            let file = |suffix: &str| out.join("tum").join(format!("{tag}_{suffix}"));
            let (rgb, depth, mask) = (
                want.rgb.as_ref().unwrap(),
                want.depth.as_ref().unwrap(),
                want.mask.as_ref().unwrap(),
            );
            let back = io::load_rgb(&file(&format!("rgb.{}", rgb_format.extension()))).unwrap();
            assert_eq!((back.width, back.height), (rgb.width, rgb.height), "{tag}");
            if rgb_format == RgbFormat::Jpeg {
                // Lossy: quality 95 keeps the mean error of these frames near one level.
                let mean = back
                    .data
                    .iter()
                    .zip(&rgb.data)
                    .map(|(a, b)| (i32::from(*a) - i32::from(*b)).unsigned_abs() as f64)
                    .sum::<f64>()
                    / rgb.data.len() as f64;
                assert!(mean < 3.0, "{tag}: JPEG mean error {mean} levels");
            } else {
                assert!(back.data == rgb.data, "{tag}: colour ({rgb_format:?}) differs");
            }
            let exr = io::load_depth(&file("depth.exr"), &DepthDecode::default()).unwrap();
            assert!(bits(&exr.data) == bits(&depth.data), "{tag}: EXR depth differs");
            let npy = io::load_depth(&file("depth.npy"), &DepthDecode::default()).unwrap();
            assert!(bits(&npy.data) == bits(&depth.data), "{tag}: NPY depth differs");
            let mm = DepthDecode {
                scale: Some(1000.0),
                ..Default::default()
            };
            let png16 = io::load_depth(&file("depth.png"), &mm).unwrap();
            for (i, (&got, &z)) in png16.data.iter().zip(&depth.data).enumerate() {
                let units = (f64::from(z) * 1000.0).round();
                let expect = if z > 0.0 && units <= 65535.0 {
                    units / 1000.0
                } else {
                    0.0
                };
                // f32 of the millimetres: within an f32 rounding of the exact value.
                assert!(
                    (f64::from(got) - expect).abs() <= 1e-6 * expect.max(1.0),
                    "{tag}: PNG16 pixel {i}: {got} for z = {z} (expected {expect})"
                );
            }
            let mask_file = file("mask.png");
            assert!(
                io::load_mask_png(&mask_file).unwrap().data == mask.data,
                "{tag}: mask differs"
            );
            let on_disk = image::open(&mask_file).unwrap();
            assert_eq!(on_disk.color(), image::ColorType::L8, "{tag}");
            let expect: Vec<u8> = mask.data.iter().map(|&m| if m == 0 { 0 } else { 255 }).collect();
            assert!(
                on_disk.into_luma8().into_raw() == expect,
                "{tag}: mask bytes are not 0 / 255"
            );
        }
    }
}
