//! What a user's terminal sees: a closed stdout or stderr ends every command quietly (SIGPIPE,
//! status 141 in a shell, no panic), and `demo`/`report` print a summary, not their tables.

use crate::cli::{bin, scratch};
use std::os::fd::{FromRawFd, OwnedFd};
use std::os::unix::process::ExitStatusExt;
use std::process::{Command, Output, Stdio};

/// The write end of a pipe whose read end is already closed: every write to it fails with
/// EPIPE, whatever the timing (a reader that closes later would race the child's writes).
fn closed_pipe() -> Stdio {
    let mut fds = [0; 2];
    // SAFETY: pipe() fills two fresh descriptors, each owned exactly once below.
    assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0, "pipe()");
    let (read, write) = unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) };
    drop(read);
    Stdio::from(write)
}

/// Runs `c` with stdout (or stderr) into a closed pipe; the other stream is captured.
fn into_closed(mut c: Command, stream: &str) -> Output {
    match stream {
        "stdout" => c.stdout(closed_pipe()).stderr(Stdio::piped()),
        _ => c.stderr(closed_pipe()).stdout(Stdio::piped()),
    };
    c.spawn().expect("run viewsynth").wait_with_output().expect("wait")
}

fn assert_quiet_sigpipe(o: &Output, what: &str) {
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        o.status.signal(),
        Some(libc::SIGPIPE),
        "{what}: expected the end by SIGPIPE, got {:?}\nstdout: {out}\nstderr: {err}",
        o.status
    );
    for text in [&out, &err] {
        assert!(
            !text.contains("panicked") && !text.contains("Broken pipe"),
            "{what}: {text}"
        );
    }
}

const COMMANDS: [&str; 11] = [
    "info",
    "refocus",
    "cyclopean",
    "reproject",
    "stitch",
    "scene",
    "compare",
    "demo",
    "report",
    "bench",
    "stress",
];

#[test]
fn a_closed_pipe_ends_every_command_quietly() {
    let d = scratch("closed-pipe");
    // Every command's help, and the top level's, into a closed stdout.
    for cmd in COMMANDS.iter().map(|c| vec![*c, "--help"]).chain([vec!["--help"]]) {
        let mut c = bin();
        c.args(&cmd);
        assert_quiet_sigpipe(&into_closed(c, "stdout"), &cmd.join(" "));
    }
    // Real runs whose first write is to stdout (their progress and summaries come later).
    let scene = d.join("scene");
    let runs: [Vec<String>; 3] = [
        vec!["info".into()],
        ["scene", "--width", "32", "--height", "24", "--out-dir"]
            .map(String::from)
            .into_iter()
            .chain([scene.display().to_string()])
            .collect(),
        [
            "stitch",
            "--scene",
            "demo",
            "--face-size",
            "16",
            "--width",
            "64",
            "--height",
            "32",
            "--out-dir",
        ]
        .map(String::from)
        .into_iter()
        .chain([d.join("ods").display().to_string()])
        .collect(),
    ];
    for args in &runs {
        let mut c = bin();
        c.args(args);
        assert_quiet_sigpipe(&into_closed(c, "stdout"), &args.join(" "));
    }
    // stderr closed: the demo's first stage line and refocus's input summary go there.
    let mut c = bin();
    c.arg("demo").arg("--out-dir").arg(d.join("demo"));
    assert_quiet_sigpipe(&into_closed(c, "stderr"), "demo (stderr closed)");
    let mut c = bin();
    c.args([
        "refocus", "--fx", "30", "--fy", "30", "--cx", "15.5", "--cy", "11.5", "--rgb",
    ])
    .arg(scene.join("left_rgb.png"))
    .arg("--depth")
    .arg(scene.join("left_view_z.exr"))
    .arg("--out-dir")
    .arg(d.join("refocus"));
    assert_quiet_sigpipe(&into_closed(c, "stderr"), "refocus (stderr closed)");
    // A usage error's message goes to stderr too: the same quiet end, not exit 2 with a panic.
    let mut c = bin();
    c.args(["refocus", "--no-such-option"]);
    assert_quiet_sigpipe(&into_closed(c, "stderr"), "usage error (stderr closed)");
}

#[test]
fn demo_prints_a_summary_and_report_verbose_the_whole_table() {
    let d = scratch("quiet");
    let o = bin().arg("demo").arg("--out-dir").arg(d.join("demo")).output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let lines = out.lines().count();
    assert!(lines <= 40, "demo printed {lines} lines:\n{out}");
    assert!(out.contains("report.md") && out.contains("--verbose"), "{out}");
    // One summary line per method, each with its median PSNR.
    for method in ["fullscreen", "refine 3, hard", "shift scan", "border-weight"] {
        assert!(
            out.lines().any(|l| l.contains(method) && l.contains(" dB")),
            "{method}: {out}"
        );
    }
    let table = std::fs::read_to_string(d.join("demo/report.md")).unwrap();
    assert!(table.lines().count() > 60, "report.md holds the full table:\n{table}");
    // Progress went to stderr, not stdout.
    assert!(!out.contains("[1/10]"), "{out}");
    assert!(String::from_utf8_lossy(&o.stderr).contains("[1/10]"));

    let o = bin()
        .args(["report", "--repeats", "0", "--verbose", "--out-dir"])
        .arg(d.join("report"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let table = std::fs::read_to_string(d.join("report/report.md")).unwrap();
    assert!(out.starts_with(&table), "--verbose prints report.md as written:\n{out}");
    assert!(out.lines().count() > table.lines().count(), "{out}");
}

#[test]
fn a_shard_from_unset_slurm_variables_is_a_usage_error_naming_them() {
    let d = scratch("shard");
    // What `--shard "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT"` expands to outside an array
    // job, then one with a count but no index, then one out of range.
    for (shard, hint) in [("/", true), ("/4", true), ("4/4", false)] {
        let o = bin()
            .args(["refocus", "--batch", "frames.csv", "--shard", shard, "--out-dir"])
            .arg(&d)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--shard {shard}: {err}");
        assert!(err.contains("--shard") && err.contains("0 <= K < N"), "{err}");
        assert_eq!(err.contains("SLURM_ARRAY_TASK_ID"), hint, "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}
