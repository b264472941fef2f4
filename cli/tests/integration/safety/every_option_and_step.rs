//! Hostile input, round 3 (issue 23), one table per class: exit codes of every option,
//! numerics over the f32/f64 range (valid => finite), inputs bounded before decoding, the
//! commit protocol killed or failed after every step (for every command that writes files), and
//! resume that verifies.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use viewsynth::io::{self, DepthMap, RgbImage};

use crate::cli::{bin, files_in, scratch, temporaries};

const W: u32 = 32;
const H: u32 = 24;

fn inputs(dir: &Path) -> (PathBuf, PathBuf) {
    let rgb: Vec<u8> = (0..W * H * 3).map(|i| (i % 251) as u8).collect();
    let depth: Vec<f32> = (0..W * H).map(|i| 1.0 + 0.01 * (i % W) as f32).collect();
    let (r, d) = (dir.join("rgb.png"), dir.join("depth.npy"));
    io::save_rgb(&r, &RgbImage::new(W, H, rgb).unwrap()).unwrap();
    io::save_depth_npy(&d, &DepthMap::new(W, H, depth).unwrap()).unwrap();
    (r, d)
}

/// The binary with `args` under a 20 s limit and a 1.5 GB address-space limit (a refusal that
/// came after decoding would show as a crash or a timeout, not pass).
fn run(args: &[String]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1500000; exec timeout 20 \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_viewsynth"))
        .args(args)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

fn s(v: &[&str]) -> Vec<String> {
    v.iter().map(|x| x.to_string()).collect()
}

fn p(path: &Path) -> String {
    path.to_str().unwrap().to_string()
}

fn report(failures: Vec<String>, cases: usize) {
    assert!(
        failures.is_empty(),
        "{} of {cases} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The value-taking options of a command, read from its --help (so a new option is covered
/// without editing this test).
fn value_options(cmd: &str) -> Vec<String> {
    let o = bin().args([cmd, "--help"]).output().unwrap();
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    let mut out = Vec::new();
    for line in help.lines() {
        let t = line.trim_start();
        let t = t.strip_prefix("-h, ").unwrap_or(t);
        if let Some(rest) = t.strip_prefix("--") {
            let mut parts = rest.split_whitespace();
            let name = parts.next().unwrap_or_default().to_string();
            if parts.next().is_some_and(|v| v.starts_with('<')) {
                out.push(name);
            }
        }
    }
    out
}

/// A value each option refuses (by name; "" refuses paths and lists alike).
fn invalid_value(cmd: &str, opt: &str) -> &'static str {
    match (cmd, opt) {
        ("bench", "batch") => "0",
        ("bench", "sizes") => "0x0",
        (_, "device") => "-1",
        (_, "shard") => "0/0",
        (_, "outputs") => "foo",
        (_, "only") => "junk",
        (_, "dominant") => "middle:1",
        (_, "zoom-range") => "0",
        (_, "focal-list") => "-5",
        (_, "jobs" | "repeats" | "refine-steps" | "steps" | "width" | "height" | "width-out" | "height-out")
        | (_, "face-size" | "max-pixels") => "-1",
        (
            _,
            "fx" | "fy" | "cx" | "cy" | "focal" | "baseline" | "doffs" | "position" | "separation" | "convergence"
            | "near" | "far" | "tau-rel" | "tau-abs" | "depth-scale" | "disparity-scale" | "depth-trunc" | "cx-out"
            | "cy-out" | "z-threshold" | "fov" | "overlap" | "ipd" | "pole-fade" | "min-psnr" | "max-colour-rmse"
            | "max-depth-rel",
        ) => "nan",
        (_, "scene") => "no/such key",
        (_, "method" | "ndc" | "rows" | "backend" | "depth-kind" | "from" | "to" | "rgb-format" | "depth-format")
        | (_, "png-compression" | "exr-compression" | "a-depth-kind" | "b-depth-kind" | "a-ndc" | "b-ndc")
        | (_, "a-rows" | "b-rows" | "blend") => "junk-value",
        // Paths (and the npz key): an empty value names nothing.
        _ => "",
    }
}

#[test]
fn round3_every_option_refuses_an_invalid_value_with_exit_2_naming_it() {
    let root = scratch("r3-options");
    let (rgb, depth) = inputs(&root);
    let out = root.join("out");
    let (r, d, o) = (p(&rgb), p(&depth), p(&out));
    // Valid command lines: only the option under test is made wrong.
    let bases: Vec<(&str, Vec<(&str, String)>)> = vec![
        (
            "refocus",
            vec![
                ("rgb", r.clone()),
                ("depth", d.clone()),
                ("fx", "40".into()),
                ("fy", "40".into()),
                ("cx", "15.5".into()),
                ("cy", "11.5".into()),
                ("out-dir", o.clone()),
            ],
        ),
        (
            "cyclopean",
            vec![
                ("left-rgb", r.clone()),
                ("right-rgb", r.clone()),
                ("left-disparity", d.clone()),
                ("right-disparity", d.clone()),
                ("out-dir", o.clone()),
            ],
        ),
        (
            "reproject",
            vec![
                ("color", r.clone()),
                ("depth", d.clone()),
                ("fx", "40".into()),
                ("fy", "40".into()),
                ("cx", "15.5".into()),
                ("cy", "11.5".into()),
                ("baseline", "0.1".into()),
                ("out-dir", o.clone()),
            ],
        ),
        ("stitch", vec![("scene", "demo".into()), ("out-dir", o.clone())]),
        ("scene", vec![("out-dir", o.clone())]),
        ("compare", vec![("a-rgb", r.clone()), ("b-rgb", r.clone())]),
        ("bench", vec![]),
        ("stress", vec![]),
        ("demo", vec![("out-dir", o.clone())]),
        ("report", vec![("out-dir", o.clone())]),
        ("info", vec![]),
    ];
    let mut failures = Vec::new();
    let mut cases = 0;
    for (cmd, base) in &bases {
        let options = value_options(cmd);
        assert!(options.len() >= 3, "{cmd}: options not found in --help: {options:?}");
        for opt in options {
            let bad = invalid_value(cmd, &opt);
            let mut args = vec![cmd.to_string()];
            for (k, v) in base.iter().filter(|(k, _)| *k != opt) {
                args.push(format!("--{k}"));
                args.push(v.clone());
            }
            args.push(format!("--{opt}"));
            args.push(bad.to_string());
            cases += 1;
            let out_before = files_in(&out);
            let res = run(&args);
            let err = String::from_utf8_lossy(&res.stderr);
            let mut problems = Vec::new();
            if res.status.code() != Some(2) {
                problems.push(format!("exit {:?}", res.status.code()));
            }
            if !err.contains(opt.as_str()) {
                problems.push("message does not name the option".to_string());
            }
            if files_in(&out) != out_before {
                problems.push("the out-dir changed".to_string());
            }
            if !problems.is_empty() {
                failures.push(format!(
                    "{cmd} --{opt} '{bad}': {} -- {}",
                    problems.join("; "),
                    err.trim()
                ));
            }
        }
    }
    assert!(cases >= 120, "only {cases} options enumerated");
    report(failures, cases);
}

#[test]
fn round3_named_usage_errors() {
    let root = scratch("r3-named");
    let (rgb, depth) = inputs(&root);
    let (r, d, o) = (p(&rgb), p(&depth), p(&root.join("out")));
    let refocus = |extra: &[&str]| {
        let mut a = s(&["refocus", "--rgb", &r, "--depth", &d, "--out-dir", &o]);
        a.extend(s(&["--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"]));
        a.extend(s(extra));
        a
    };
    let cyclopean = |extra: &[&str]| {
        let mut a = s(&["cyclopean", "--left-rgb", &r, "--right-rgb", &r]);
        a.extend(s(&["--left-disparity", &d, "--right-disparity", &d, "--out-dir", &o]));
        a.extend(s(extra));
        a
    };
    let cases: Vec<(&str, Vec<String>, &str)> = vec![
        (
            "disparity-scale 0",
            cyclopean(&["--disparity-scale", "0"]),
            "disparity-scale",
        ),
        (
            "disparity-scale -1",
            cyclopean(&["--disparity-scale", "-1"]),
            "disparity-scale",
        ),
        ("bench sizes 0x0", s(&["bench", "--sizes", "0x0"]), "--sizes"),
        ("bench sizes 0x5", s(&["bench", "--sizes", "0x5"]), "--sizes"),
        ("bench sizes abc", s(&["bench", "--sizes", "abc"]), "--sizes"),
        ("bench sizes 5xq", s(&["bench", "--sizes", "5xq"]), "--sizes"),
        ("stress only empty", s(&["stress", "--only", ""]), "--only"),
        ("stress only junk", s(&["stress", "--only", "junk"]), "--only"),
        ("refocus fx 1e-300", refocus(&["--fx", "1e-300"]), "fx"),
        ("refocus zoom 0", refocus(&["--zoom-range", "0"]), "--zoom-range"),
        ("refocus zoom -1", refocus(&["--zoom-range", "-1"]), "--zoom-range"),
        ("refocus focal list 0", refocus(&["--focal-list", "0"]), "--focal-list"),
        ("cyclopean position nan", cyclopean(&["--position", "nan"]), "position"),
        ("cyclopean position 2", cyclopean(&["--position", "2"]), "position"),
        ("refocus depth-scale 0", refocus(&["--depth-scale", "0"]), "depth-scale"),
        ("refocus device -1", refocus(&["--device", "-1"]), "--device"),
        ("refocus outputs foo", refocus(&["--outputs", "foo"]), "outputs"),
        (
            "reproject baseline with separation",
            {
                let mut a = s(&["reproject", "--color", &r, "--depth", &d, "--out-dir", &o]);
                a.extend(s(&["--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"]));
                a.extend(s(&["--baseline", "0.1", "--separation", "0.02", "--convergence", "3"]));
                a
            },
            "--baseline",
        ),
    ];
    let mut failures = Vec::new();
    let n = cases.len();
    for (label, args, needle) in cases {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        if o.status.code() != Some(2) || !err.contains(needle) {
            failures.push(format!("{label}: exit {:?} -- {}", o.status.code(), err.trim()));
        }
    }
    report(failures, n);
}

fn npy_bytes(shape: &str, descr: &str, payload: &[u8]) -> Vec<u8> {
    let mut dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + dict.len() + 1) % 64 != 0 {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend((dict.len() as u16).to_le_bytes());
    out.extend(dict.as_bytes());
    out.extend(payload);
    out
}

/// An `.npz` as numpy's savez writes one (zip64 local headers, real CRCs, a central
/// directory): each member is `bytes` and then `zeros` zero bytes (streamed, never held),
/// deflated at the best level with `deflate`.
fn npz(members: &[(&str, &[u8], u64)], deflate: bool) -> Vec<u8> {
    use std::io::Write;
    let method = if deflate {
        zip::CompressionMethod::Deflated
    } else {
        zip::CompressionMethod::Stored
    };
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(method)
        .compression_level(deflate.then_some(9))
        .large_file(true);
    let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let chunk = vec![0u8; 1 << 20];
    for &(name, bytes, zeros) in members {
        w.start_file(name, options).unwrap();
        w.write_all(bytes).unwrap();
        let mut left = zeros;
        while left > 0 {
            let n = left.min(chunk.len() as u64) as usize;
            w.write_all(&chunk[..n]).unwrap();
            left -= n as u64;
        }
    }
    w.finish().unwrap().into_inner()
}

fn mkfifo(path: &Path) {
    let st = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(st.success());
}

#[test]
fn round3_every_input_is_bounded_before_it_is_read() {
    let root = scratch("r3-inputs");
    let (rgb, depth) = inputs(&root);
    let (r, d, o) = (p(&rgb), p(&depth), p(&root.join("out")));
    // The NPZ bomb of the issue: (4, 8192, 8192) float64 declared, 2 GB inflated, ~2 MB stored.
    let header = npy_bytes("(4, 8192, 8192)", "<f8", &[]);
    let payload = 4u64 * 8192 * 8192 * 8;
    let bomb = root.join("bomb.npz");
    std::fs::write(&bomb, npz(&[("arr_0.npy", &header, payload)], true)).unwrap();
    // Two members of one name.
    let one = npy_bytes(&format!("({H}, {W})"), "<f4", &vec![0u8; (W * H * 4) as usize]);
    let dup = root.join("dup.npz");
    // The zip writer refuses a repeated name: the second is renamed in its headers after.
    let mut two = npz(&[("arr_0.npy", &one, 0), ("arr_1.npy", &one, 0)], false);
    while let Some(at) = two.windows(9).position(|w| w == b"arr_1.npy") {
        two[at..at + 9].copy_from_slice(b"arr_0.npy");
    }
    std::fs::write(&dup, two).unwrap();
    // A 3-D member within the value budget but no depth: refused from its header.
    let cube = npy_bytes("(3, 2, 2)", "<f4", &[0u8; 48]);
    let cube_npz = root.join("cube.npz");
    std::fs::write(&cube_npz, npz(&[("arr_0.npy", &cube, 0)], false)).unwrap();
    // Intrinsics: huge sparse text file, FIFO, device, huge/subnormal values.
    let big = root.join("big.txt");
    std::fs::File::create(&big).unwrap().set_len(128 << 20).unwrap();
    let fifo = root.join("k.fifo");
    mkfifo(&fifo);
    let k = |name: &str, text: &str| {
        let path = root.join(name);
        std::fs::write(&path, text).unwrap();
        p(&path)
    };
    let k_huge = k("k_huge.txt", "1e300 0 16 0 40 12 0 0 1");
    let k_tiny = k("k_tiny.txt", "5e-324 0 16 0 40 12 0 0 1");
    let k_cx = k("k_cx.txt", "40 0 1e9 0 40 12 0 0 1");
    // A 15 MB JSON key.
    let key_json = root.join("cams.json");
    std::fs::write(&key_json, format!("{{\"{}\": 1}}", "k".repeat(15 << 20))).unwrap();
    let manifest_long = root.join("long.csv");
    std::fs::write(
        &manifest_long,
        format!("rgb,depth,fx,fy,cx,cy\n{},{d},40,40,15,11\n", "r".repeat(15 << 20)),
    )
    .unwrap();
    let refocus_k = |k: &str| {
        s(&[
            "refocus",
            "--rgb",
            &r,
            "--depth",
            &d,
            "--out-dir",
            &o,
            "--intrinsics",
            k,
        ])
    };
    let refocus_depth = |dp: &Path| {
        s(&[
            "refocus",
            "--rgb",
            &r,
            "--depth",
            &p(dp),
            "--out-dir",
            &o,
            "--fx",
            "40",
            "--fy",
            "40",
            "--cx",
            "15",
            "--cy",
            "11",
        ])
    };
    let cases: Vec<(&str, Vec<String>, i32, &str)> = vec![
        ("npz bomb", refocus_depth(&bomb), 1, "pixel budget"),
        (
            "npz duplicate members",
            refocus_depth(&dup),
            1,
            "two arrays named 'arr_0'",
        ),
        ("npz 3-D member", refocus_depth(&cube_npz), 1, "(H, W)"),
        ("intrinsics 128 MB", refocus_k(&p(&big)), 1, "big.txt"),
        ("intrinsics FIFO", refocus_k(&p(&fifo)), 1, "FIFO"),
        ("intrinsics /dev/zero", refocus_k("/dev/zero"), 1, "character device"),
        ("intrinsics fx 1e300", refocus_k(&k_huge), 1, "fx"),
        ("intrinsics fx 5e-324", refocus_k(&k_tiny), 1, "fx"),
        ("intrinsics cx 1e9", refocus_k(&k_cx), 1, "cx"),
        (
            "cameras 15 MB key",
            s(&[
                "cyclopean",
                "--left-rgb",
                &r,
                "--right-rgb",
                &r,
                "--left-depth",
                &d,
                "--right-depth",
                &d,
            ])
            .into_iter()
            .chain(s(&["--cameras", &p(&key_json), "--out-dir", &o]))
            .collect(),
            1,
            "cams.json",
        ),
        (
            "manifest 15 MB cell",
            s(&["refocus", "--batch", &p(&manifest_long), "--out-dir", &o]),
            1,
            "long.csv",
        ),
    ];
    let mut failures = Vec::new();
    let n = cases.len();
    for (label, args, code, needle) in cases {
        let res = run(&args);
        let err = String::from_utf8_lossy(&res.stderr);
        let mut problems = Vec::new();
        if res.status.code() != Some(code) {
            problems.push(format!("exit {:?}", res.status.code()));
        }
        if !err.contains(needle) {
            problems.push(format!("message lacks '{needle}'"));
        }
        // Whatever the input holds, the message quotes a short excerpt of it.
        if err.len() > 8192 {
            problems.push(format!("message of {} bytes", err.len()));
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{label}: {} -- {}",
                problems.join("; "),
                &err[..err.len().min(400)]
            ));
        }
    }
    assert!(!root.join("out").exists() || files_in(&root.join("out")).is_empty());
    report(failures, n);
}

#[test]
fn round3_outputs_never_replace_what_is_not_ours_and_compare_is_all_or_none() {
    let root = scratch("r3-compare");
    let (rgb, _) = inputs(&root);
    let r = p(&rgb);
    let fifo = root.join("node.fifo");
    mkfifo(&fifo);
    let diff = root.join("d.png");
    let cases: Vec<(&str, Vec<String>)> = vec![
        (
            "diff then missing json folder",
            s(&[
                "compare",
                "--a-rgb",
                &r,
                "--b-rgb",
                &r,
                "--diff",
                &p(&diff),
                "--json",
                "/nonexistent/x.json",
            ]),
        ),
        (
            "json is a FIFO",
            s(&[
                "compare",
                "--a-rgb",
                &r,
                "--b-rgb",
                &r,
                "--diff",
                &p(&diff),
                "--json",
                &p(&fifo),
            ]),
        ),
        (
            "diff is a FIFO",
            s(&["compare", "--a-rgb", &r, "--b-rgb", &r, "--diff", &p(&fifo)]),
        ),
        (
            "json is /dev/null",
            s(&["compare", "--a-rgb", &r, "--b-rgb", &r, "--json", "/dev/null"]),
        ),
        (
            "stress json is a FIFO",
            s(&["stress", "--quick", "--only", "camera", "--json", &p(&fifo)]),
        ),
        (
            "stress json is /dev/null",
            s(&["stress", "--quick", "--only", "camera", "--json", "/dev/null"]),
        ),
    ];
    let mut failures = Vec::new();
    let n = cases.len();
    for (label, args) in cases {
        let res = run(&args);
        let err = String::from_utf8_lossy(&res.stderr);
        let mut problems = Vec::new();
        // Round 4 (issue 33): a device is written in place, not refused; a FIFO no process
        // reads is refused at once (it would block the run).
        let expected = if label.ends_with("/dev/null") { 0 } else { 1 };
        if label.contains("json is a FIFO") && !err.contains("no process reads") {
            problems.push("the FIFO without a reader was not named".into());
        }
        if res.status.code() != Some(expected) {
            problems.push(format!("exit {:?}", res.status.code()));
        }
        if diff.exists() {
            problems.push("d.png was written".to_string());
            let _ = std::fs::remove_file(&diff);
        }
        use std::os::unix::fs::FileTypeExt;
        if !std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo() {
            problems.push("the FIFO was replaced".into());
        }
        if !std::fs::symlink_metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
        {
            problems.push("/dev/null was replaced".into());
        }
        let temps = temporaries(&root);
        if !temps.is_empty() {
            problems.push(format!("temporaries left: {temps:?}"));
        }
        if !problems.is_empty() {
            failures.push(format!("{label}: {} -- {}", problems.join("; "), err.trim()));
        }
    }
    report(failures, n);
}

/// Per file the manifest lists, whether it is there with the CRC-32 recorded; and the method.
fn manifest_state(dir: &Path) -> (bool, String) {
    let text = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    let m: serde_json::Value = serde_json::from_str(&text).unwrap();
    let files = m["files"].as_array().unwrap();
    let complete = !files.is_empty()
        && files.iter().all(|f| {
            let name = f["name"].as_str().unwrap();
            let want = f["crc32"].as_u64();
            let bytes = std::fs::read(dir.join(name)).ok();
            bytes.is_some_and(|b| {
                let mut c = flate2::Crc::new();
                c.update(&b);
                Some(u64::from(c.sum())) == want
            })
        });
    (complete, m["method"].to_string())
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

#[test]
fn round3_commit_survives_a_kill_or_a_failure_after_every_step() {
    let root = scratch("r3-commit");
    let (rgb, depth) = inputs(&root);
    let refocus = |out: &Path, method: &str, fault: Option<String>| {
        let mut c = bin();
        c.args(["refocus", "--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"])
            .args(["--zoom-range", "0.5,1.5", "--method", method])
            .arg("--rgb")
            .arg(&rgb)
            .arg("--depth")
            .arg(&depth)
            .arg("--out-dir")
            .arg(out)
            .stdout(Stdio::null());
        match fault {
            Some(f) => c.env("VIEWSYNTH_FAULT_AFTER", f),
            None => c.env_remove("VIEWSYNTH_FAULT_AFTER"),
        };
        c.output().unwrap()
    };
    let old = root.join("old");
    assert!(refocus(&old, "fullscreen", None).status.success());
    let (old_complete, old_method) = manifest_state(&old);
    assert!(old_complete);
    // Steps: the journal, 2 scales x 3 files + the manifest renamed, then the staging
    // folder's journal, lock file and folder removed.
    let steps = 1 + 7 + 3;
    let mut failures = Vec::new();
    let mut cases = 0;
    let mut new_method = String::new();
    for k in 1..=steps + 1 {
        for mode in ["", ":fail"] {
            cases += 1;
            let out = root.join(format!("k{k}{mode}"));
            copy_dir(&old, &out);
            let res = refocus(&out, "mesh", Some(format!("{k}{mode}")));
            let code = res.status.code();
            let expect = match (k > steps, mode) {
                (true, _) => Some(0),
                (false, "") => Some(137),
                (false, _) => Some(1),
            };
            let mut problems = Vec::new();
            if code != expect {
                problems.push(format!("exit {code:?}, expected {expect:?}"));
            }
            // Before any recovery the manifest is one run's, whole (never half written).
            let (_, method) = manifest_state(&out);
            if method != old_method && k == 1 && mode.is_empty() {
                problems.push("the manifest changed before a rename".into());
            }
            // The next run's start (OutDir::prepare) recovers: the old set or the new one, complete.
            io::OutDir::prepare(&out).unwrap();
            let (complete, method) = manifest_state(&out);
            if !complete {
                problems.push(format!(
                    "after recovery the manifest ({method}) does not match its files"
                ));
            }
            if k > steps {
                new_method = method.clone();
            }
            // From the journal on, the set is the new one.
            if method == old_method {
                problems.push("after recovery the old set is back although the journal was written".into());
            }
            let temps = temporaries(&out);
            if !temps.is_empty() {
                problems.push(format!("temporaries left: {temps:?}"));
            }
            if !problems.is_empty() {
                failures.push(format!("after step {k}{mode}: {}", problems.join("; ")));
            }
        }
    }
    assert_ne!(new_method, old_method);
    // Killed before the journal (while rendering): the old set, complete, and nothing else.
    let out = root.join("before-journal");
    copy_dir(&old, &out);
    let staging = out.join(".viewsynth-1-killed");
    std::fs::create_dir(&staging).unwrap();
    std::fs::write(staging.join(".viewsynth-lock"), b"").unwrap();
    std::fs::write(staging.join("s0.5_rgb.png"), b"partial").unwrap();
    io::OutDir::prepare(&out).unwrap();
    cases += 1;
    if manifest_state(&out) != (true, old_method.clone()) || out.join(".viewsynth-1-killed").exists() {
        failures.push("killed before the journal: not the old set, or staging left".into());
    }
    report(failures, cases);
}

#[test]
fn round3_depth_and_focal_values_over_the_whole_range_are_never_valid_and_non_finite() {
    let root = scratch("r3-numerics");
    let (rgb, _) = inputs(&root);
    let values: [f32; 14] = [
        1e-45,
        1e-40,
        f32::MIN_POSITIVE,
        1e-30,
        1e-7,
        1e-6,
        1.0,
        1e6,
        1.1e6,
        1e20,
        1e38,
        f32::MAX,
        -1e-40,
        -1e38,
    ];
    let mut failures = Vec::new();
    let mut cases = 0;
    for (i, v) in values.iter().enumerate() {
        let depth = root.join(format!("d{i}.npy"));
        io::save_depth_npy(&depth, &DepthMap::new(W, H, vec![*v; (W * H) as usize]).unwrap()).unwrap();
        for method in ["fullscreen", "mesh"] {
            for fx in ["40", "1e-3", "1e6"] {
                cases += 1;
                let out = root.join(format!("o{i}-{method}-{fx}"));
                let res = bin()
                    .args([
                        "refocus",
                        "--fy",
                        "40",
                        "--cx",
                        "15.5",
                        "--cy",
                        "11.5",
                        "--zoom-range",
                        "0.5,2",
                    ])
                    .args(["--fx", fx, "--method", method, "--depth-format", "exr"])
                    .arg("--rgb")
                    .arg(&rgb)
                    .arg("--depth")
                    .arg(&depth)
                    .arg("--out-dir")
                    .arg(&out)
                    .output()
                    .unwrap();
                let err = String::from_utf8_lossy(&res.stderr);
                if !res.status.success() {
                    // A refusal must be a clear run or usage error naming the value.
                    if !matches!(res.status.code(), Some(1 | 2)) || err.contains("panicked") {
                        failures.push(format!("depth {v:e} {method} fx {fx}: {err}"));
                    }
                    continue;
                }
                let usable = v.abs() >= 1e-6 && v.abs() <= 1e6;
                for tag in ["s0.5", "s2"] {
                    let d = io::load_depth(&out.join(format!("{tag}_depth.exr")), &Default::default()).unwrap();
                    let m = io::load_mask_png(&out.join(format!("{tag}_mask.png"))).unwrap();
                    let bad = d
                        .data
                        .iter()
                        .zip(&m.data)
                        .filter(|(z, m)| **m != 0 && !z.is_finite())
                        .count();
                    let valid = m.data.iter().filter(|m| **m != 0).count();
                    if bad > 0 {
                        failures.push(format!(
                            "depth {v:e} {method} fx {fx} {tag}: {bad} valid pixels not finite"
                        ));
                    }
                    if !usable && valid > 0 {
                        failures.push(format!("depth {v:e} {method} fx {fx} {tag}: {valid} valid pixels"));
                    }
                }
            }
        }
    }
    report(failures, cases);
}

#[test]
fn round3_resume_verifies_folders_and_float_settings() {
    let root = scratch("r3-resume");
    let (rgb, depth) = inputs(&root);
    let manifest = root.join("m.csv");
    std::fs::write(
        &manifest,
        format!(
            "name,rgb,depth,fx,fy,cx,cy\na,{},{},40,40,15.5,11.5\n",
            p(&rgb),
            p(&depth)
        ),
    )
    .unwrap();
    let out = root.join("out");
    let batch = |zoom: &str| {
        bin()
            .args(["refocus", "--zoom-range", zoom, "--batch"])
            .arg(&manifest)
            .arg("--out-dir")
            .arg(&out)
            .output()
            .unwrap()
    };
    let mut failures = Vec::new();
    let mut cases = 0;
    for zoom in [
        "1.1400000000000001",
        "0.1+0.2",
        "0.30000000000000004",
        "1e-1",
        "2.5000000000000004",
    ] {
        let first = batch(zoom);
        if !first.status.success() {
            // Not a number clap takes: a usage error, never a run.
            cases += 1;
            if first.status.code() != Some(2) {
                failures.push(format!("zoom {zoom}: exit {:?}", first.status.code()));
            }
            continue;
        }
        cases += 1;
        let again = String::from_utf8_lossy(&batch(zoom).stdout).into_owned();
        if !again.contains("0 rendered, 1 already done") {
            failures.push(format!("zoom {zoom}: identical rerun re-rendered: {again}"));
        }
    }
    // A finished frame folder replaced by a symlink to a copy elsewhere: refused, by name.
    let copy = root.join("elsewhere");
    copy_dir(&out.join("a"), &copy);
    std::fs::remove_dir_all(out.join("a")).unwrap();
    std::os::unix::fs::symlink(&copy, out.join("a")).unwrap();
    let before: BTreeMap<String, Vec<u8>> = files_in(&copy)
        .into_iter()
        .map(|f| (f.clone(), std::fs::read(copy.join(&f)).unwrap()))
        .collect();
    let o = batch("2.5000000000000004");
    let err = String::from_utf8_lossy(&o.stderr);
    cases += 1;
    if o.status.code() != Some(1) || !err.contains("symlink") {
        failures.push(format!("symlinked frame folder: exit {:?} -- {err}", o.status.code()));
    }
    let after: BTreeMap<String, Vec<u8>> = files_in(&copy)
        .into_iter()
        .map(|f| (f.clone(), std::fs::read(copy.join(&f)).unwrap()))
        .collect();
    cases += 1;
    if before != after {
        failures.push("the folder the symlink points to changed".into());
    }
    report(failures, cases);
}

/// The chunk offset table of an EXR `save_depth_exr` wrote: (position, entries). Found as the
/// run of increasing u64s whose first entry points just past the table.
fn exr_offset_table(bytes: &[u8]) -> (usize, usize) {
    let at = |p: usize| u64::from_le_bytes(bytes[p..p + 8].try_into().unwrap()) as usize;
    for count in 1..64 {
        for p in 8..bytes.len().saturating_sub(8 * count) {
            if at(p) == p + 8 * count && (1..count).all(|i| at(p + 8 * i) > at(p + 8 * (i - 1))) {
                return (p, count);
            }
        }
    }
    panic!("no offset table found");
}

/// Runs `args`, expecting exit `code`, every one of `words` in stderr and `out` unchanged.
fn expect_exit(out: &Path, what: &str, args: Vec<String>, code: i32, words: &[&str], failures: &mut Vec<String>) {
    let before = files_in(out);
    let res = run(&args);
    let err = String::from_utf8_lossy(&res.stderr);
    let mut problems = Vec::new();
    if res.status.code() != Some(code) {
        problems.push(format!("exit {:?}, expected {code}", res.status.code()));
    }
    for w in words {
        if !err.contains(w) {
            problems.push(format!("message lacks '{w}'"));
        }
    }
    if files_in(out) != before {
        problems.push("the out-dir changed".into());
    }
    if !problems.is_empty() {
        failures.push(format!("{what}: {} -- {}", problems.join("; "), err.trim()));
    }
}

#[test]
fn round3_class6_leftovers_are_refused_by_name() {
    let root = scratch("r3-class6");
    let (rgb, npy) = inputs(&root);
    let out = root.join("out");
    let (r, d, o) = (p(&rgb), p(&npy), p(&out));
    let mut failures = Vec::new();
    let mut cases = 0;

    // --npz-key on a depth file that is no .npz: the command line is wrong, before any work.
    let npz_key_lines: Vec<(&str, Vec<String>)> = vec![
        (
            "refocus",
            s(&[
                "refocus",
                "--rgb",
                &r,
                "--depth",
                &d,
                "--fx",
                "40",
                "--fy",
                "40",
                "--cx",
                "15.5",
                "--cy",
                "11.5",
                "--out-dir",
                &o,
            ]),
        ),
        (
            "reproject",
            s(&[
                "reproject",
                "--color",
                &r,
                "--depth",
                &d,
                "--fx",
                "40",
                "--fy",
                "40",
                "--cx",
                "15.5",
                "--cy",
                "11.5",
                "--baseline",
                "0.1",
                "--out-dir",
                &o,
            ]),
        ),
        (
            "cyclopean",
            s(&[
                "cyclopean",
                "--left-rgb",
                &r,
                "--right-rgb",
                &r,
                "--left-disparity",
                &d,
                "--right-disparity",
                &d,
                "--out-dir",
                &o,
            ]),
        ),
        (
            "compare",
            s(&[
                "compare",
                "--a-rgb",
                &r,
                "--b-rgb",
                &r,
                "--a-depth",
                &d,
                "--b-depth",
                &d,
            ]),
        ),
        (
            "stitch (built-in scene)",
            s(&["stitch", "--scene", "demo", "--out-dir", &o]),
        ),
    ];
    for (cmd, args) in npz_key_lines {
        for key in ["depth", "arr_0", ""] {
            let mut a = args.clone();
            a.extend(s(&["--npz-key", key]));
            cases += 1;
            expect_exit(
                &out,
                &format!("{cmd} --npz-key '{key}'"),
                a,
                2,
                &["--npz-key"],
                &mut failures,
            );
        }
    }

    // report --case that is no case folder: exit 2 naming --case, before the GPU opens.
    for case in [p(&root.join("no-such-case")), p(&rgb), p(&root)] {
        cases += 1;
        expect_exit(
            &out,
            &format!("report --case {case}"),
            s(&["report", "--out-dir", &o, "--case", &case]),
            2,
            &["--case", "cameras.json"],
            &mut failures,
        );
    }

    // cyclopean rig values: out of the flags' bounds (exit 2), or in bounds but putting every
    // disparity outside the usable depths (exit 1), named either way, never a silent 0 % view.
    let cyc = s(&[
        "cyclopean",
        "--left-rgb",
        &r,
        "--right-rgb",
        &r,
        "--left-disparity",
        &d,
        "--right-disparity",
        &d,
        "--out-dir",
        &o,
    ]);
    for (focal, baseline, code, name) in [
        ("1e300", "0.1", 2, "--focal"),
        ("5e-324", "0.1", 2, "--focal"),
        ("1e-4", "0.1", 2, "--focal"),
        ("100", "1e300", 2, "--baseline"),
        ("100", "1e-300", 2, "--baseline"),
        ("1e6", "1e6", 1, "--focal/--baseline"),
        ("1e-3", "1e-6", 1, "--focal/--baseline"),
    ] {
        let mut a = cyc.clone();
        a.extend(s(&["--focal", focal, "--baseline", baseline]));
        cases += 1;
        expect_exit(
            &out,
            &format!("cyclopean --focal {focal} --baseline {baseline}"),
            a,
            code,
            &[name],
            &mut failures,
        );
    }

    // compare: all-NaN depth on both sides compares no depth, so a depth limit fails.
    let nan = root.join("nan.npy");
    io::save_depth_npy(&nan, &DepthMap::new(W, H, vec![f32::NAN; (W * H) as usize]).unwrap()).unwrap();
    let n = p(&nan);
    for extra in [vec![], s(&["--b-depth-kind", "view-z"])] {
        let mut a = s(&[
            "compare",
            "--a-rgb",
            &r,
            "--b-rgb",
            &r,
            "--a-depth",
            &n,
            "--b-depth",
            &n,
            "--max-depth-rel",
            "0.001",
        ]);
        a.extend(extra);
        cases += 1;
        let res = run(&a);
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&res.stdout),
            String::from_utf8_lossy(&res.stderr)
        );
        if res.status.success() || !text.contains("no depth was compared") {
            failures.push(format!(
                "compare all-NaN depth: exit {:?} -- {}",
                res.status.code(),
                text.trim()
            ));
        }
    }
    // ... while one finite pixel on each side is compared (and passes).
    let mut one = vec![f32::NAN; (W * H) as usize];
    one[5] = 2.0;
    let one_path = root.join("one.npy");
    io::save_depth_npy(&one_path, &DepthMap::new(W, H, one).unwrap()).unwrap();
    let o1 = p(&one_path);
    cases += 1;
    let res = run(&s(&[
        "compare",
        "--a-rgb",
        &r,
        "--b-rgb",
        &r,
        "--a-depth",
        &o1,
        "--b-depth",
        &o1,
        "--max-depth-rel",
        "0.001",
    ]));
    if !res.status.success() {
        failures.push(format!(
            "compare with one finite depth: {}",
            String::from_utf8_lossy(&res.stderr)
        ));
    }

    // Corrupt EXR offset tables: every entry at line 0, past the end, before the table,
    // swapped; each refused by name (library and CLI), the intact file loads.
    let exr = root.join("d.exr");
    let depth: Vec<f32> = (0..W * H).map(|i| 1.0 + 0.01 * (i % W) as f32).collect();
    io::save_depth_exr(&exr, &DepthMap::new(W, H, depth.clone()).unwrap()).unwrap();
    let good = std::fs::read(&exr).unwrap();
    let (table, count) = exr_offset_table(&good);
    assert!(count >= 2, "{count} chunks: too few to corrupt");
    assert_eq!(io::load_depth(&exr, &Default::default()).unwrap().data, depth);
    let entry = |b: &[u8], i: usize| b[table + 8 * i..table + 8 * i + 8].to_vec();
    type Corrupt<'a> = Box<dyn Fn(&mut Vec<u8>) + 'a>;
    let corruptions: Vec<(&str, Corrupt)> = vec![
        (
            "every entry at the first chunk",
            Box::new(|b: &mut Vec<u8>| {
                let first = entry(b, 0);
                (1..count).for_each(|i| b[table + 8 * i..table + 8 * i + 8].copy_from_slice(&first));
            }),
        ),
        (
            "an entry past the end",
            Box::new(|b: &mut Vec<u8>| {
                let past = (b.len() as u64 + 100).to_le_bytes();
                b[table + 8..table + 16].copy_from_slice(&past);
            }),
        ),
        (
            "an entry inside the header",
            Box::new(|b: &mut Vec<u8>| b[table..table + 8].copy_from_slice(&8u64.to_le_bytes())),
        ),
        (
            "two entries swapped",
            Box::new(|b: &mut Vec<u8>| {
                let (a, c) = (entry(b, 0), entry(b, 1));
                b[table..table + 8].copy_from_slice(&c);
                b[table + 8..table + 16].copy_from_slice(&a);
            }),
        ),
    ];
    for (what, corrupt) in corruptions {
        let mut bytes = good.clone();
        corrupt(&mut bytes);
        let bad = root.join("bad.exr");
        std::fs::write(&bad, &bytes).unwrap();
        cases += 1;
        match io::load_depth(&bad, &Default::default()) {
            Err(e) if e.to_string().contains("bad.exr") && e.to_string().contains("offset table") => {}
            other => failures.push(format!("EXR {what}: {:?}", other.map(|d| d.data.len()))),
        }
        let b = p(&bad);
        cases += 1;
        expect_exit(
            &out,
            &format!("refocus with an EXR whose table has {what}"),
            s(&[
                "refocus",
                "--rgb",
                &r,
                "--depth",
                &b,
                "--fx",
                "40",
                "--fy",
                "40",
                "--cx",
                "15.5",
                "--cy",
                "11.5",
                "--out-dir",
                &o,
            ]),
            1,
            &["bad.exr", "offset table"],
            &mut failures,
        );
    }
    report(failures, cases);
}

/// The files of a folder by name, for comparing whole sets: a refocus manifest (it holds
/// timings, so never the same bytes twice) is left out once it is checked to list its files
/// with their CRC-32s.
fn file_set_snapshot(dir: &Path) -> Result<BTreeMap<String, Vec<u8>>, String> {
    let mut files = BTreeMap::new();
    // Every entry, the hidden record of the set (`.viewsynth.<command>.set`) included: it is
    // part of what one commit replaces.
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    for name in names {
        if name.starts_with(".viewsynth-") {
            return Err(format!("temporary left: {name}"));
        }
        if name == "manifest.json" {
            if !manifest_state(dir).0 {
                return Err("the manifest does not match its files".into());
            }
            continue;
        }
        files.insert(name.clone(), std::fs::read(dir.join(&name)).unwrap());
    }
    Ok(files)
}

/// Every command that writes files commits them all-or-none, whatever step it is ended after:
/// each command runs once into a folder holding its output of other settings (the old set),
/// with the fault hook (`VIEWSYNTH_FAULT_AFTER`, a kill or a failure) after step k = 1, 2, ...
/// until a run gets past every step. After the next start's recovery the folder is the old set
/// or the new one (as clean runs make them), every file alike, and no temporary is left.
#[test]
fn round3_every_writing_command_is_all_or_none_after_any_commit_step() {
    let root = scratch("r3-commit-all");
    let (rgb, depth) = inputs(&root);
    // One stereo frame, and a two-frame sequence for cyclopean --sequence.
    let (scene, frames) = (root.join("scene"), root.join("frames"));
    for (dir, extra) in [
        (&scene, vec![]),
        (&frames, s(&["--frames", "2", "--spectator-offset", "0.1"])),
    ] {
        let args = [
            s(&["scene", "--width", "64", "--height", "48", "--out-dir", &p(dir)]),
            extra,
        ]
        .concat();
        let made = run(&args);
        assert!(made.status.success(), "{}", String::from_utf8_lossy(&made.stderr));
    }
    let (r, d) = (p(&rgb), p(&depth));
    let eye = |e: &str, what: &str| p(&scene.join(format!("{e}_{what}")));
    // Each command with the one setting that differs between its old and new set (same names,
    // other contents).
    type Variant = (&'static str, Vec<String>, [Vec<String>; 2]);
    let intrinsics = s(&["--fx", "40", "--fy", "40", "--cx", "15.5", "--cy", "11.5"]);
    let commands: Vec<Variant> = vec![
        (
            "refocus",
            [
                s(&["refocus", "--rgb", &r, "--depth", &d, "--zoom-range", "0.5,1.5"]),
                intrinsics.clone(),
            ]
            .concat(),
            [
                s(&["--cx-out", "15.5", "--cy-out", "11.5"]),
                s(&["--cx-out", "13.5", "--cy-out", "11.5"]),
            ],
        ),
        (
            "cyclopean",
            [
                s(&[
                    "cyclopean",
                    "--left-rgb",
                    &eye("left", "rgb.png"),
                    "--right-rgb",
                    &eye("right", "rgb.png"),
                ]),
                s(&["--left-depth", &eye("left", "device_depth.exr")]),
                s(&["--right-depth", &eye("right", "device_depth.exr")]),
                s(&["--cameras", &p(&scene.join("cameras.json"))]),
            ]
            .concat(),
            [s(&["--method", "seed"]), s(&["--method", "splat-gather"])],
        ),
        (
            "cyclopean-sequence",
            s(&["cyclopean", "--sequence", &p(&frames.join("sequence.json")), "--fill"]),
            [s(&["--method", "seed"]), s(&["--method", "splat-gather"])],
        ),
        (
            "reproject",
            [s(&["reproject", "--color", &r, "--depth", &d]), intrinsics.clone()].concat(),
            [s(&["--baseline", "0.1"]), s(&["--baseline", "0.2"])],
        ),
        (
            "stitch",
            s(&["stitch", "--scene", "demo", "--width", "64", "--height", "32"]),
            [s(&["--ipd", "0.064"]), s(&["--ipd", "0.07"])],
        ),
        (
            "scene",
            s(&["scene", "--width", "64", "--height", "48"]),
            [s(&["--ipd", "0.064"]), s(&["--ipd", "0.07"])],
        ),
    ];
    let mut failures = Vec::new();
    let mut cases = 0;
    for (name, base, [old_args, new_args]) in &commands {
        let args = |settings: &[String], out: &Path| -> Vec<String> {
            let mut a = base.clone();
            a.extend(settings.iter().cloned());
            a.extend(s(&["--out-dir", &p(out)]));
            a
        };
        let clean = |settings: &[String], tag: &str| {
            let out = root.join(format!("{name}-{tag}"));
            let o = run(&args(settings, &out));
            assert!(
                o.status.success(),
                "{name} {tag}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            (out.clone(), file_set_snapshot(&out).unwrap())
        };
        let (old_dir, old) = clean(old_args, "old");
        let (_, new) = clean(new_args, "new");
        assert_eq!(
            old.keys().collect::<Vec<_>>(),
            new.keys().collect::<Vec<_>>(),
            "{name}: the two settings must write the same names"
        );
        assert_ne!(old, new, "{name}: the two settings must write other contents");
        let mut steps = None;
        for k in 1..=100 {
            for mode in ["", ":fail"] {
                cases += 1;
                let label = format!("{name} after step {k}{mode}");
                let out = root.join(format!("{name}-k{k}{mode}"));
                copy_dir(&old_dir, &out);
                let mut c = Command::new(env!("CARGO_BIN_EXE_viewsynth"));
                c.args(args(new_args, &out))
                    .env("VIEWSYNTH_FAULT_AFTER", format!("{k}{mode}"))
                    .stdout(Stdio::null())
                    .stderr(Stdio::null());
                let code = c.status().unwrap().code();
                match (code, mode) {
                    (Some(0), _) => steps = Some(k - 1),
                    (Some(137), "") | (Some(1), ":fail") => {}
                    _ => failures.push(format!("{label}: exit {code:?}")),
                }
                io::OutDir::prepare(&out).unwrap();
                match file_set_snapshot(&out) {
                    Ok(now) if now == old || now == new => {}
                    Ok(now) => {
                        let mixed: Vec<_> = now.keys().filter(|f| now.get(*f) != new.get(*f)).collect();
                        failures.push(format!("{label}: neither the old nor the new set (not new: {mixed:?})"));
                    }
                    Err(e) => failures.push(format!("{label}: {e}")),
                }
            }
            if steps.is_some() {
                break;
            }
        }
        // A journal, one rename a file, and the three removals of the staging folder.
        let files = old.len() + usize::from(*name == "refocus");
        assert_eq!(steps, Some(1 + files + 3), "{name}: steps of one commit");
    }
    report(failures, cases);
}
