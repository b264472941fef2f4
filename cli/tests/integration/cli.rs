//! The binary end to end: a successful run writes exactly the requested files and a manifest;
//! bad input exits non-zero with an error naming the file or parameter, without a panic and
//! without leaving output files behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use viewsynth::io::{self, DepthMap, RgbImage};

pub(crate) fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_viewsynth"))
}

pub(crate) fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("viewsynth-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small valid input pair (PNG colour, NPY depth) in `dir`.
fn inputs(dir: &Path, w: u32, h: u32) -> (PathBuf, PathBuf) {
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
    let depth: Vec<f32> = (0..w * h).map(|i| 1.0 + 0.01 * (i % w) as f32).collect();
    let (rp, dp) = (dir.join("rgb.png"), dir.join("depth.npy"));
    io::save_rgb(&rp, &RgbImage::new(w, h, rgb).unwrap()).unwrap();
    io::save_depth_npy(&dp, &DepthMap::new(w, h, depth).unwrap()).unwrap();
    (rp, dp)
}

fn refocus(rgb: &Path, depth: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut c = bin();
    c.args([
        "refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5", "--rgb",
    ])
    .arg(rgb)
    .arg("--depth")
    .arg(depth)
    .arg("--out-dir")
    .arg(out)
    .args(extra);
    c.output().expect("run viewsynth")
}

/// The temporaries (`.viewsynth-…` files and staging folders) directly in `dir`.
pub(crate) fn temporaries(dir: &Path) -> Vec<String> {
    files_in(dir)
        .into_iter()
        .filter(|f| f.starts_with(viewsynth::io::TEMP_PREFIX))
        .collect()
}

pub(crate) fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                // The hidden record of the run's set (`.viewsynth.<command>.set`, by which the
                // next run replaces it) is bookkeeping, not an output.
                .filter(|name| !(name.starts_with(".viewsynth.") && name.ends_with(".set")))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn refocus_writes_requested_files_and_a_manifest() {
    let d = scratch("ok");
    let (rgb, depth) = inputs(&d, 32, 24);
    let out = d.join("out");
    let o = refocus(
        &rgb,
        &depth,
        &out,
        &["--zoom-range", "0.5,2", "--depth-format", "exr,npy"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let files = files_in(&out);
    assert_eq!(
        files,
        [
            "manifest.json",
            "s0.5_depth.exr",
            "s0.5_depth.npy",
            "s0.5_mask.png",
            "s0.5_rgb.png",
            "s2_depth.exr",
            "s2_depth.npy",
            "s2_mask.png",
            "s2_rgb.png"
        ]
    );
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["outputs"][1]["intrinsics"]["fx"], 80.0);
    let z = io::load_depth(&out.join("s2_depth.npy"), &Default::default()).unwrap();
    assert_eq!((z.width, z.height), (32, 24));

    let only_depth = d.join("only-depth");
    let o = refocus(&rgb, &depth, &only_depth, &["--zoom-range", "1", "--outputs", "depth"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(files_in(&only_depth), ["manifest.json", "s1_depth.exr"]);
}

/// A single frame's manifest records its sources and depth scale (as a batch frame's settings
/// do), its notes agree with its row order, and the printed scales are short (the manifest keeps
/// the exact value).
#[test]
fn single_frame_manifest_records_its_inputs_and_scales_print_short() {
    let d = scratch("inputs");
    let (rgb, depth) = inputs(&d, 32, 24);
    let out = d.join("out");
    // fx' = 100/3 against fx = 40: s = 0.8333...
    let o = refocus(&rgb, &depth, &out, &["--focal-list", "33.333333333333336,80"]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let lines: Vec<&str> = stdout.lines().filter(|l| l.starts_with("s=")).collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    assert!(
        lines[0].starts_with("s=0.833 ") && lines[1].starts_with("s=2 "),
        "{stdout}"
    );
    let m: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["inputs"]["rgb"], rgb.to_str().unwrap());
    assert_eq!(m["inputs"]["depth"], depth.to_str().unwrap());
    assert!(m["inputs"]["depth_scale"].is_null(), "{}", m["inputs"]);
    assert!((m["outputs"][0]["scale"].as_f64().unwrap() - 5.0 / 6.0).abs() < 1e-12);
    // The framebuffers' row order is not the files': the notes say which one they mean.
    let notes = m["notes"].as_str().unwrap();
    assert_eq!(m["conventions"]["row_order"], "bottom-up");
    assert!(
        notes.contains("every file's rows run top-down") && notes.contains("conventions.row_order"),
        "{notes}"
    );

    // A depth scale given is recorded.
    let raw: Vec<u16> = (0..32 * 24).map(|i| 1000 + (i % 32) as u16).collect();
    let png = d.join("depth16.png");
    image::save_buffer(&png, bytemuck::cast_slice(&raw), 32, 24, image::ExtendedColorType::L16).unwrap();
    let scaled = d.join("scaled");
    let o = refocus(&rgb, &png, &scaled, &["--zoom-range", "1", "--depth-scale", "1000"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value = serde_json::from_slice(&std::fs::read(scaled.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["inputs"]["depth_scale"], 1000.0);
}

/// Exit status of a command-line problem (clap's refusals and the job's option checks); its
/// message ends "try '--help'".
pub(crate) const USAGE: i32 = 2;
/// Exit status of an error found while running (inputs, files, GPU).
pub(crate) const RUN_ERROR: i32 = 1;

/// A refusal with exit status `code` (pinned by the caller: [`USAGE`] or [`RUN_ERROR`]),
/// an error message containing `needle`, no panic and nothing left in `out`.
#[track_caller]
pub(crate) fn assert_clean_failure(code: i32, o: &Output, needle: &str, out: &Path) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "stderr: {err}");
    // The usage hint goes with exit 2 and only with it.
    assert_eq!(
        err.contains("try '--help'"),
        code == USAGE,
        "usage hint vs exit {code}: {err}"
    );
    assert!(
        err.contains("error:") && err.contains(needle),
        "expected '{needle}' in: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    let left: Vec<String> = files_in(out)
        .into_iter()
        .filter(|f| !f.starts_with(".viewsynth-write-test"))
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

#[test]
fn bad_input_fails_cleanly() {
    let d = scratch("bad");
    let (rgb, depth) = inputs(&d, 32, 24);
    let out = d.join("out");

    let missing = d.join("nope.png");
    assert_clean_failure(RUN_ERROR, &refocus(&missing, &depth, &out, &[]), "nope.png", &out);

    let small = scratch("bad-small");
    let (_, depth_small) = inputs(&small, 16, 12);
    assert_clean_failure(
        RUN_ERROR,
        &refocus(&rgb, &depth_small, &out, &[]),
        "size mismatch",
        &out,
    );

    let empty = d.join("empty.npy");
    std::fs::write(&empty, b"").unwrap();
    assert_clean_failure(RUN_ERROR, &refocus(&rgb, &empty, &out, &[]), "empty.npy", &out);

    let corrupt = d.join("corrupt.png");
    std::fs::write(&corrupt, b"\x89PNG\r\n\x1a\nthis is not a png").unwrap();
    assert_clean_failure(RUN_ERROR, &refocus(&corrupt, &depth, &out, &[]), "corrupt.png", &out);

    assert_clean_failure(
        USAGE,
        &refocus(&rgb, &depth, &out, &["--width-out", "16385", "--height-out", "10"]),
        "width",
        &out,
    );
    assert_clean_failure(
        USAGE,
        &refocus(&rgb, &depth, &out, &["--zoom-range", "0"]),
        "--zoom-range 0",
        &out,
    );
    assert_clean_failure(USAGE, &refocus(&rgb, &depth, &out, &["--tau-rel=-1"]), "tau-rel", &out);
    assert_clean_failure(
        USAGE,
        &refocus(&rgb, &depth, &out, &["--outputs", "rgb,normals"]),
        "outputs",
        &out,
    );

    // Non-finite and non-positive intrinsics.
    for (flag, value, needle) in [
        ("--fx", "0", "fx"),
        ("--fy", "-3", "fy"),
        ("--cx", "nan", "cx"),
        ("--fx", "inf", "fx"),
    ] {
        let mut c = bin();
        let mut args = vec!["refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"];
        let pos = args.iter().position(|a| *a == flag).unwrap();
        args[pos + 1] = value;
        let o = c
            .args(&args)
            .arg("--rgb")
            .arg(&rgb)
            .arg("--depth")
            .arg(&depth)
            .arg("--out-dir")
            .arg(&out)
            .output()
            .unwrap();
        assert_clean_failure(USAGE, &o, needle, &out);
    }

    // Unwritable output directory: a path below a regular file (fails for root too).
    let blocker = d.join("blocker");
    std::fs::write(&blocker, b"x").unwrap();
    let o = refocus(&rgb, &depth, &blocker.join("out"), &[]);
    assert_clean_failure(RUN_ERROR, &o, "blocker", &blocker.join("out"));
}

#[test]
fn info_reports_the_renderer() {
    let o = bin().args(["info"]).output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(text.contains("renderer:") && text.contains("GL version:"), "{text}");
}

#[test]
fn missing_libegl_is_a_clear_error_not_a_crash() {
    // A directory whose libEGL.so.1 is not a shared library shadows the system one.
    let d = scratch("no-egl");
    for name in ["libEGL.so.1", "libEGL.so"] {
        std::fs::write(d.join(name), b"not an ELF file").unwrap();
    }
    let o = bin().arg("info").env("LD_LIBRARY_PATH", &d).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("libEGL") && !err.contains("panicked"), "{err}");
}

#[test]
fn batch_reports_a_corrupt_frame_completes_the_rest_and_resumes() {
    let d = scratch("batch");
    let mut lines = vec!["name,rgb,depth,fx,fy,cx,cy".to_string()];
    for i in 0..3 {
        let sub = d.join(format!("f{i}"));
        std::fs::create_dir_all(&sub).unwrap();
        let (rgb, depth) = inputs(&sub, 32, 24);
        if i == 1 {
            std::fs::write(&rgb, b"\x89PNG\r\n\x1a\nbroken").unwrap();
        }
        lines.push(format!(
            "frame{i},{},{},40,40,15.5,11.5",
            rgb.display(),
            depth.display()
        ));
    }
    let manifest = d.join("frames.csv");
    std::fs::write(&manifest, lines.join("\n")).unwrap();
    let run = |out: &Path, extra: &[&str]| {
        bin()
            .args(["refocus", "--zoom-range", "0.5,2", "--batch"])
            .arg(&manifest)
            .arg("--out-dir")
            .arg(out)
            .args(extra)
            .output()
            .unwrap()
    };
    let out = d.join("out");
    let o = run(&out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("failed: frame1") && err.contains("rgb.png") && !err.contains("panicked"),
        "{err}"
    );
    for ok in ["frame0", "frame2"] {
        assert!(out.join(ok).join("manifest.json").is_file(), "{ok} not finished");
        assert!(out.join(ok).join("s2_rgb.png").is_file());
    }
    assert!(!out.join("frame1").join("manifest.json").exists());
    let before = std::fs::read(out.join("frame2").join("s0.5_depth.exr")).unwrap();

    // Repair the frame and resume: only it is rendered; finished frames are left alone, and a
    // temporary left by an interrupted write in the unfinished frame is cleared.
    std::fs::create_dir_all(out.join("frame1")).unwrap();
    // (pid 999999999 cannot run: above Linux's pid_max, so the temporary is stale)
    let stale = out.join("frame1").join(".viewsynth-999999999-stale.tmp");
    std::fs::write(&stale, b"partial").unwrap();
    // Unlocked and not touched for a while: a killed writer's (a live one holds its lock).
    std::fs::File::options()
        .write(true)
        .open(&stale)
        .unwrap()
        .set_modified(std::time::SystemTime::now() - std::time::Duration::from_secs(3600))
        .unwrap();
    let (rgb, _) = inputs(&d.join("f1"), 32, 24);
    assert!(rgb.is_file());
    let o = run(&out, &[]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(text.contains("1 rendered, 2 already done"), "{text}");
    assert!(!out.join("frame1").join(".viewsynth-999999999-stale.tmp").exists());
    assert_eq!(
        std::fs::read(out.join("frame2").join("s0.5_depth.exr")).unwrap(),
        before
    );

    // Writing on the render thread gives byte-identical files.
    let serial = d.join("serial");
    let o = run(&serial, &["--writer-threads", "0"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["s0.5_rgb.png", "s2_depth.exr", "s2_mask.png"] {
        assert_eq!(
            std::fs::read(serial.join("frame1").join(f)).unwrap(),
            std::fs::read(out.join("frame1").join(f)).unwrap(),
            "{f}"
        );
    }
}

#[test]
fn bench_batch_prints_throughput_and_stage_medians_as_json() {
    let o = bin()
        .args([
            "bench",
            "--batch",
            "2",
            "--jobs",
            "1",
            "--png-compression",
            "fast",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON object on stdout");
    assert_eq!(v["frames"], 2);
    assert!(v["frames_per_s"].as_f64().unwrap() > 0.0);
    // Stage medians (ms per frame). Every working stage did work on every frame, so each is
    // above zero (Instant has ns resolution; a stage never timed reads 0). The synchronous run
    // does all stages in turn on one thread and never waits: wait is 0 and, over its 2 frames
    // (median of 2 = mean), the stages add up to at most its wall time. A stage timed in the
    // wrong unit, twice, or not at all fails one of these.
    let work = ["decode", "upload", "render", "readback", "encode"];
    for run in ["pipelined", "synchronous"] {
        let r = &v[run];
        let ms = |stage: &str| {
            r["stages_ms"][stage]
                .as_f64()
                .unwrap_or_else(|| panic!("{run} {stage}: {v}"))
        };
        for stage in work {
            assert!(ms(stage) > 0.0 && ms(stage).is_finite(), "{run} {stage}: {v}");
        }
        let wall_ms = r["wall_s"].as_f64().unwrap() * 1000.0;
        let fps = r["frames"].as_f64().unwrap() / r["wall_s"].as_f64().unwrap();
        assert!(
            (r["frames_per_s"].as_f64().unwrap() - fps).abs() <= 1e-9 * fps,
            "{run}: {v}"
        );
        if run == "synchronous" {
            assert_eq!(ms("wait"), 0.0, "{v}");
            let sum: f64 = work.iter().map(|s| ms(s)).sum();
            assert!(
                2.0 * sum <= wall_ms,
                "{run}: stages {sum} ms x 2 frames > wall {wall_ms} ms: {v}"
            );
        } else {
            assert!(ms("wait") >= 0.0 && ms("wait") < wall_ms, "{v}");
        }
    }
    assert_eq!(
        v["stages_ms"], v["pipelined"]["stages_ms"],
        "the flat fields are the pipelined run's"
    );
    // The renderer measured is the one `info` names (GL_RENDERER of the same device choice).
    let info = bin().args(["info", "--json"]).output().unwrap();
    assert!(info.status.success(), "{}", String::from_utf8_lossy(&info.stderr));
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(v["renderer"], info["renderer"], "{v}");
    assert!(!v["renderer"].as_str().unwrap().is_empty(), "{v}");
    assert_eq!(v["synchronous"]["frames"], 2);
    assert!(!v["bound_by"].as_str().unwrap().is_empty());
    // Bad values are usage errors that name the option, never a panic.
    for (args, needle) in [
        (vec!["bench", "--batch", "0"], "--batch 0"),
        (vec!["bench", "--batch", "2", "--jobs", "30000"], "--jobs"),
        (
            vec!["bench", "--batch", "2", "--png-compression", "max"],
            "png-compression",
        ),
    ] {
        let o = bin().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}
