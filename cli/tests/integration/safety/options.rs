//! Every option of every command refuses an invalid value with exit 2 naming it (the options
//! read from each command's `--help`, so a new option is covered), and the named usage errors.

use crate::cli::{bin, files_in, scratch};
use crate::common::assert_no_failures;
use crate::safety::support::{inputs, p, run, s};

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
fn every_option_refuses_an_invalid_value_with_exit_2_naming_it() {
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
    assert_no_failures(failures, cases);
}

#[test]
fn named_usage_errors() {
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
    assert_no_failures(failures, n);
}
