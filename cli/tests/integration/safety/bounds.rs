//! Every count or range the user gives is held against the work it implies before that work
//! starts: shard counts against the frames and the index's part names, zoom samples against
//! the distinct file tags of the range, the matcher's search against its bound, FLIP's memory
//! against the image, and the flow peer's files against the report they would end. Each case
//! failed (or hung, hence the time limits) before its check existed.

use crate::cli::{bin, files_in, scratch, RUN_ERROR, USAGE};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};
use viewsynth::io::{self, DepthMap, RgbImage};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `cmd` for at most `limit`: its output, or a panic naming the command when it ran past
/// (it is killed first, so a hang fails the test instead of the suite).
fn within(mut cmd: Command, limit: Duration) -> Output {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            child.kill().unwrap();
            let _ = child.wait();
            panic!("{cmd:?} still ran after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A manifest of `n` frames (one 8 x 6 colour and view-Z depth) in `dir`.
fn manifest(dir: &Path, n: usize) -> std::path::PathBuf {
    let (w, h) = (8u32, 6u32);
    let (rgb, depth) = (dir.join("f_rgb.png"), dir.join("f_depth.npy"));
    io::save_rgb(
        &rgb,
        &RgbImage::new(w, h, (0..w * h * 3).map(|i| (i * 7 % 251) as u8).collect()).unwrap(),
    )
    .unwrap();
    io::save_depth_npy(&depth, &DepthMap::new(w, h, vec![2.0; (w * h) as usize]).unwrap()).unwrap();
    let rows: String = (0..n)
        .map(|k| format!("{},{},8,8,3.5,2.5,f{k}\n", s(&rgb), s(&depth)))
        .collect();
    let path = dir.join("frames.csv");
    std::fs::write(&path, format!("rgb,depth,fx,fy,cx,cy,name\n{rows}")).unwrap();
    path
}

/// `viewsynth index` over the part a `--shard 0/100000000` run left: the missing parts are
/// counted and a few named (it built all 99,999,999 names and aborted on allocation), within a
/// 1 GB address space.
#[test]
fn index_counts_the_missing_parts_of_a_huge_shard_count() {
    let d = scratch("bounds-index");
    std::fs::write(d.join("index.part-0-of-100000000.jsonl"), "").unwrap();
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg("ulimit -v 1000000; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_viewsynth"))
        .args(["index", s(&d)]);
    let o = within(cmd, Duration::from_secs(60));
    let err = text(&o);
    assert_eq!(o.status.code(), Some(RUN_ERROR), "{err}");
    assert!(
        err.contains("99999999 of 100000000 parts missing")
            && err.contains("index.part-1-of-100000000.jsonl")
            && err.contains("and 99999991 more"),
        "{err}"
    );
    assert!(err.len() < 2000, "{} bytes of message", err.len());
}

/// A shard count above the manifest's frames is refused by name before anything is written
/// (shards past the last frame would have nothing to do, and the index would wait for them).
#[test]
fn a_shard_count_above_the_frame_count_is_refused() {
    let d = scratch("bounds-shards");
    let m = manifest(&d, 2);
    let out = d.join("out");
    let o = bin()
        .args([
            "refocus",
            "--batch",
            s(&m),
            "--zoom-range",
            "1",
            "--shard",
            "0/3",
            "--out-dir",
            s(&out),
        ])
        .output()
        .unwrap();
    let err = text(&o);
    assert_eq!(o.status.code(), Some(RUN_ERROR), "{err}");
    assert!(
        err.contains("shard") && err.contains("0/3") && err.contains("lists 2 frames"),
        "{err}"
    );
    assert!(files_in(&out).is_empty(), "{:?}", files_in(&out));
}

/// `--zoom-random 1,1.0000001 --samples 2`: one file tag in the range, two samples asked for.
/// Refused as a usage error before any work (it drew forever at 100 % CPU).
#[test]
fn zoom_samples_beyond_the_ranges_distinct_tags_are_refused() {
    let d = scratch("bounds-zoom");
    let m = manifest(&d, 1);
    let out = d.join("out");
    let mut cmd = bin();
    cmd.args([
        "refocus",
        "--batch",
        s(&m),
        "--zoom-random",
        "1,1.0000001",
        "--samples",
        "2",
        "--out-dir",
        s(&out),
    ]);
    let o = within(cmd, Duration::from_secs(30));
    let err = text(&o);
    assert_eq!(o.status.code(), Some(USAGE), "{err}");
    assert!(
        err.contains("--zoom-random/--samples") && err.contains("1 distinct scale"),
        "{err}"
    );
    assert!(!out.exists());
}

/// The census matcher's search is bounded (its work grows with every disparity), not only by
/// the width: a lone `--max-disparity 1100` on a 1200 px pair is refused before the images are
/// read (it ran the whole search).
#[test]
fn the_matchers_search_is_bounded_before_the_images_are_read() {
    let d = scratch("bounds-disparity");
    let (w, h) = (1200u32, 8u32);
    let image =
        |seed: u32| RgbImage::new(w, h, (0..w * h * 3).map(|i| ((i * 37 + seed) % 251) as u8).collect()).unwrap();
    let (l, r) = (d.join("l.png"), d.join("r.png"));
    io::save_rgb(&l, &image(0)).unwrap();
    io::save_rgb(&r, &image(5)).unwrap();
    let out = d.join("out");
    // The option that sets the search is named: --max-disparity alone from 0, both when the
    // range reaches below 0.
    for (range, named) in [
        (&["--max-disparity", "1100"][..], "invalid --max-disparity:"),
        (
            &["--min-disparity", "-600", "--max-disparity", "600"],
            "--min-disparity/--max-disparity",
        ),
    ] {
        let mut cmd = bin();
        cmd.args([
            "cyclopean",
            "--left-rgb",
            s(&l),
            "--right-rgb",
            s(&r),
            "--out-dir",
            s(&out),
        ])
        .args(range);
        let o = within(cmd, Duration::from_secs(60));
        let err = text(&o);
        assert_eq!(o.status.code(), Some(USAGE), "{range:?}: {err}");
        assert!(
            err.contains(named) && err.contains("more than its 1024"),
            "{range:?}: {err}"
        );
        assert!(!out.exists(), "{range:?}");
    }
}

/// The peak resident memory of `cmd` run to its end, in bytes (the largest VmHWM read from
/// /proc/<pid>/status every 2 ms), and its output status.
///
/// Not wait4's ru_maxrss: the child is spawned by vfork from this test process, and Linux folds
/// the parent's high-water mark into the child's maxrss at exec, so a child of a test binary
/// holding 180 MB (the convention sweep, run beside this) "peaked" at 180 MB whatever it did.
/// VmHWM belongs to the child's own address space, made at exec. A peak in its last 2 ms before
/// exit could be missed; the measured commands peak mid-run (FLIP, a frame's render).
// The child is reaped by wait4, not by `Child::wait`.
#[allow(clippy::zombie_processes)]
pub(crate) fn peak_memory(mut cmd: Command) -> (u64, std::process::ExitStatus, String) {
    use std::os::unix::process::ExitStatusExt;
    let child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let mut stderr = child.stderr.unwrap();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        std::io::Read::read_to_string(&mut stderr, &mut text).unwrap();
        text
    });
    let hwm = || -> Option<u64> {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        line.split_whitespace()
            .nth(1)?
            .parse::<u64>()
            .ok()
            .map(|kib| kib * 1024)
    };
    let (mut peak, mut status) = (0u64, 0);
    loop {
        peak = peak.max(hwm().unwrap_or(0));
        // SAFETY: pid is our unwaited child; status is valid for writes.
        let waited = unsafe { libc::waitpid(pid, &mut status, libc::WNOHANG) };
        if waited == pid {
            break;
        }
        assert_eq!(waited, 0, "waitpid");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let err = reader.join().unwrap();
    (peak, std::process::ExitStatus::from_raw(status), err)
}

/// FLIP runs in strips: `compare` of a 2048 x 768 pair stays well under FLIP's whole-image
/// working set (about 91 bytes a pixel, 143 MB here: 1.5 GB at 4096^2, about 6 GB at the
/// default pixel budget). The bound: 40 bytes a pixel for the images, maps and error (about
/// 25 measured) and 64 MB for one strip and the process.
#[test]
fn flip_memory_does_not_grow_with_the_image() {
    let d = scratch("bounds-flip");
    let (w, h) = (2048u32, 768u32);
    let image = |seed: u32| {
        RgbImage::new(
            w,
            h,
            (0..w * h * 3)
                .map(|i| ((i.wrapping_mul(2_654_435_761) >> 7) ^ seed) as u8)
                .collect(),
        )
        .unwrap()
    };
    let (a, b) = (d.join("a.png"), d.join("b.png"));
    io::save_rgb(&a, &image(0)).unwrap();
    io::save_rgb(&b, &image(0x5a)).unwrap();
    let mut cmd = bin();
    cmd.args(["compare", "--a-rgb", s(&a), "--b-rgb", s(&b)]);
    let (peak, status, err) = peak_memory(cmd);
    assert!(status.success(), "{status:?} {err}");
    let pixels = u64::from(w * h);
    let bound = 40 * pixels + (64 << 20);
    assert!(
        peak < bound,
        "compare peaked at {} MB, bound {} MB",
        peak >> 20,
        bound >> 20
    );
}

/// A flow-peer image of the wrong size is refused from the headers, before any row is measured
/// (it was found after the whole report).
#[test]
fn a_wrong_size_flow_peer_image_is_refused_before_measuring() {
    let d = scratch("bounds-peer-size");
    let (data, peer) = (d.join("data"), d.join("flow_peer"));
    crate::lab::demo_and_report::fake_flow_peer(&data, &peer);
    let small = RgbImage::new(8, 6, vec![100; 8 * 6 * 3]).unwrap();
    io::save_rgb(&peer.join("tsukuba_1_5_3.png"), &small).unwrap();
    let out = d.join("report");
    let mut cmd = bin();
    cmd.args([
        "report",
        "--repeats",
        "1",
        "--out-dir",
        s(&out),
        "--data-dir",
        s(&data),
        "--flow-peer",
        s(&peer),
    ]);
    let o = within(cmd, Duration::from_secs(60));
    let err = text(&o);
    assert_eq!(o.status.code(), Some(RUN_ERROR), "{err}");
    assert!(
        err.contains("tsukuba_1_5_3.png is 8x6") && err.contains("40x30"),
        "{err}"
    );
    assert!(
        !err.contains("report: refocus rows") && !out.exists(),
        "measured first: {err}"
    );
}
