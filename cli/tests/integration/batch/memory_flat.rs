//! Memory per frame is flat on every sequence and batch path, on both backends: the peak
//! resident memory of a run of many frames is that of a run of a few. Tiny frames (16 x 12), so
//! what grows per frame is bookkeeping, not images. On Vulkan, lavapipe compiled a new shader
//! at every draw whose parameter block steered a loop or branch and never freed it (about 1.4
//! MB a frame of `cyclopean --sequence --method seed --fill`, 2.7 MB a frame of `scene
//! --frames`); the block is a storage buffer there now (shaders/common/vulkan.glsl).

use crate::cli::{bin, scratch};
use crate::safety::bounds::peak_memory;
use std::path::{Path, PathBuf};

#[cfg(feature = "vulkan")]
const BACKENDS: &[&str] = &["gl", "vulkan"];
#[cfg(not(feature = "vulkan"))]
const BACKENDS: &[&str] = &["gl"];

/// Frames of the short and the long run.
const FEW: usize = 16;
const MANY: usize = 160;
/// Growth allowed from the short run to the long one: run-to-run noise of the allocator and
/// driver threads (up to about 30 MB measured, either way), far below the growth of a megabyte
/// a frame (144 MB here; 199 MB and 389 MB measured before the fix).
const NOISE: u64 = 48 << 20;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// One 16 x 12 scene frame (colour, device depth, cameras) in `dir`.
fn scene_frame(dir: &Path) -> PathBuf {
    let out = dir.join("frame");
    let o = bin()
        .args(["scene", "--width", "16", "--height", "12", "--out-dir", s(&out)])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

/// A sequence file listing `frame`'s pair `n` times.
fn sequence(dir: &Path, frame: &Path, n: usize) -> PathBuf {
    let f = |name: &str| frame.join(name).display().to_string();
    let one = serde_json::json!({
        "left_rgb": f("left_rgb.png"),
        "right_rgb": f("right_rgb.png"),
        "left_depth": f("left_device_depth.exr"),
        "right_depth": f("right_device_depth.exr"),
        "cameras": f("cameras.json"),
    });
    let path = dir.join(format!("sequence-{n}.json"));
    std::fs::write(&path, serde_json::json!({ "frames": vec![one; n] }).to_string()).unwrap();
    path
}

/// A batch manifest listing `frame`'s left view `n` times.
fn manifest(dir: &Path, frame: &Path, n: usize) -> PathBuf {
    let (rgb, depth) = (frame.join("left_rgb.png"), frame.join("left_view_z.exr"));
    let rows: String = (0..n)
        .map(|k| format!("{},{},16,16,7.5,5.5,f{k}\n", s(&rgb), s(&depth)))
        .collect();
    let path = dir.join(format!("frames-{n}.csv"));
    std::fs::write(&path, format!("rgb,depth,fx,fy,cx,cy,name\n{rows}")).unwrap();
    path
}

/// The peak memory of `args(n)` for FEW and MANY frames differs by less than [`NOISE`].
fn flat(what: &str, args: impl Fn(usize) -> Vec<String>) {
    let peak = |n: usize| {
        let mut cmd = bin();
        cmd.args(args(n));
        let (peak, status, err) = peak_memory(cmd);
        assert!(status.success(), "{what}, {n} frames: {status:?} {err}");
        peak
    };
    let (few, many) = (peak(FEW), peak(MANY));
    assert!(
        many < few + NOISE,
        "{what}: {} MB peak at {FEW} frames, {} MB at {MANY} ({:.2} MB a frame)",
        few >> 20,
        many >> 20,
        (many.saturating_sub(few)) as f64 / (MANY - FEW) as f64 / (1 << 20) as f64
    );
}

#[test]
fn every_sequence_and_batch_path_keeps_memory_flat_over_frames() {
    let d = scratch("memory-flat");
    let frame = scene_frame(&d);
    for &backend in BACKENDS {
        // A folder per run: a batch over an earlier run's frames would skip them (resume).
        let out = |what: &str, n: usize| d.join(format!("{what}-{backend}-{n}")).display().to_string();
        flat(
            &format!("cyclopean --sequence --method seed --fill on {backend}"),
            |n| {
                let seq = sequence(&d, &frame, n);
                [
                    "cyclopean",
                    "--sequence",
                    s(&seq),
                    "--method",
                    "seed",
                    "--fill",
                    "--backend",
                    backend,
                ]
                .into_iter()
                .map(String::from)
                .chain(["--out-dir".into(), out("seed", n)])
                .collect()
            },
        );
        flat(&format!("cyclopean --sequence (splat-gather) on {backend}"), |n| {
            let seq = sequence(&d, &frame, n);
            [
                "cyclopean",
                "--sequence",
                s(&seq),
                "--backend",
                backend,
                "--out-dir",
                &out("splat", n),
            ]
            .into_iter()
            .map(String::from)
            .collect()
        });
        flat(&format!("scene --frames on {backend}"), |n| {
            let (dir, n) = (out("scene", n), n.to_string());
            [
                "scene",
                "--width",
                "16",
                "--height",
                "12",
                "--frames",
                &n,
                "--backend",
                backend,
                "--out-dir",
                &dir,
            ]
            .into_iter()
            .map(String::from)
            .collect()
        });
        flat(&format!("refocus --batch on {backend}"), |n| {
            let m = manifest(&d, &frame, n);
            [
                "refocus",
                "--batch",
                s(&m),
                "--zoom-range",
                "1,2",
                "--backend",
                backend,
                "--out-dir",
                &out("batch", n),
            ]
            .into_iter()
            .map(String::from)
            .collect()
        });
    }
}
