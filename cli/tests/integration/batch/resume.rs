//! `refocus --batch` from the command line, for the README's promises that no other test holds
//! through the binary: each resume invalidation rule (inputs' size and content, conventions,
//! outputs, formats), `--shard K/N` taking the frames with i % N == K over several K, resume per
//! shard, kill -9 mid-batch then resume, and a batch ended after each step of its file commits.

use crate::cli::{bin, files_in, scratch, temporaries};
use image::ImageEncoder;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Output, Stdio};
use viewsynth::io::{self, DepthMap, RgbImage};

/// Two input pairs (`rgb{0,1}.png`, `depth{0,1}.npy`, 32 x 24) and a manifest of `n` frames
/// `f0..` alternating between them (frame i uses pair i % 2).
pub(crate) fn setup(name: &str, n: usize) -> (PathBuf, PathBuf) {
    let dir = scratch(name);
    for p in 0..2u32 {
        let (w, h) = (32u32, 24u32);
        let rgb: Vec<u8> = (0..w * h * 3).map(|i| ((i * (7 + p)) % 251) as u8).collect();
        let depth: Vec<f32> = (0..w * h)
            .map(|i| 1.0 + 0.01 * (i % w) as f32 + 0.1 * p as f32)
            .collect();
        io::save_rgb(&dir.join(format!("rgb{p}.png")), &RgbImage::new(w, h, rgb).unwrap()).unwrap();
        io::save_depth_npy(&dir.join(format!("depth{p}.npy")), &DepthMap::new(w, h, depth).unwrap()).unwrap();
    }
    let mut csv = String::from("rgb,depth,fx,fy,cx,cy,name\n");
    for f in 0..n {
        csv += &format!("rgb{p}.png,depth{p}.npy,40,40,15.5,11.5,f{f}\n", p = f % 2);
    }
    let manifest = dir.join("frames.csv");
    std::fs::write(&manifest, csv).unwrap();
    (dir, manifest)
}

fn batch(manifest: &Path, out: &Path, extra: &[&str]) -> Output {
    bin()
        .args(["refocus", "--zoom-range", "0.5,1.5", "--jobs", "1", "--batch"])
        .arg(manifest)
        .arg("--out-dir")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

/// (rendered, already done) from the summary line "N frames ...: R rendered, S already done".
fn counts(o: &Output) -> (usize, usize) {
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "{text}");
    let num_before = |word: &str| -> usize {
        let at = text.find(word).unwrap_or_else(|| panic!("no '{word}' in: {text}"));
        let head = text[..at].trim_end();
        head[head.rfind(|c: char| !c.is_ascii_digit()).map_or(0, |i| i + 1)..]
            .parse()
            .unwrap_or_else(|_| panic!("no count before '{word}' in: {text}"))
    };
    (num_before(" rendered"), num_before(" already done"))
}

/// Each frame folder's manifest bytes (they hold timings: rewritten means redone).
fn manifests(out: &Path) -> BTreeMap<String, Vec<u8>> {
    files_in(out)
        .into_iter()
        .filter(|f| !f.starts_with(".viewsynth-"))
        .filter_map(|f| std::fs::read(out.join(&f).join("manifest.json")).ok().map(|m| (f, m)))
        .collect()
}

/// The frames whose manifest changed between `before` and `after`.
fn redone(before: &BTreeMap<String, Vec<u8>>, after: &BTreeMap<String, Vec<u8>>) -> Vec<String> {
    after
        .iter()
        .filter(|(k, v)| before.get(*k) != Some(*v))
        .map(|(k, _)| k.clone())
        .collect()
}

fn names(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// Every file a frame's manifest lists is there with its CRC-32.
fn frame_complete(dir: &Path) -> bool {
    let Ok(bytes) = std::fs::read(dir.join("manifest.json")) else {
        return false;
    };
    let m: serde_json::Value = serde_json::from_slice(&bytes).expect("a whole manifest");
    let files = m["files"].as_array().expect("files");
    !files.is_empty()
        && files.iter().all(|f| {
            std::fs::read(dir.join(f["name"].as_str().unwrap())).is_ok_and(|b| {
                let mut c = flate2::Crc::new();
                c.update(&b);
                Some(u64::from(c.sum())) == f["crc32"].as_u64()
            })
        })
}

#[test]
fn resume_redoes_a_frame_for_each_recorded_setting_that_changed() {
    let (dir, manifest) = setup("batch-resume-rules", 4);
    let out = dir.join("out");
    assert_eq!(counts(&batch(&manifest, &out, &[])), (4, 0));
    let mut before = manifests(&out);
    assert_eq!(
        counts(&batch(&manifest, &out, &[])),
        (0, 4),
        "nothing changed: all resumed"
    );
    assert_eq!(redone(&before, &manifests(&out)), Vec::<String>::new());

    // An input's mtime only (same bytes): the same file by content, so nothing is redone.
    let rgb0 = dir.join("rgb0.png");
    let f = std::fs::File::options().write(true).open(&rgb0).unwrap();
    let t = f.metadata().unwrap().modified().unwrap();
    f.set_modified(t - std::time::Duration::from_secs(3600)).unwrap();
    drop(f);
    assert_eq!(counts(&batch(&manifest, &out, &[])), (0, 4), "mtime of rgb0.png only");

    // An input's content, size kept (one depth value of depth0.npy): f0 and f2 are redone.
    let depth0 = dir.join("depth0.npy");
    let mut npy = std::fs::read(&depth0).unwrap();
    let last = npy.len() - 1;
    npy[last] ^= 0x01;
    std::fs::write(&depth0, &npy).unwrap();
    assert_eq!(counts(&batch(&manifest, &out, &[])), (2, 2), "content of depth0.npy");
    let after = manifests(&out);
    assert_eq!(redone(&before, &after), names(&["f0", "f2"]));
    before = after;

    // An input's size only: rgb1.png rewritten with other PNG settings (same pixels, another
    // size) and its mtime put back. f1 and f3 are redone.
    let rgb1 = dir.join("rgb1.png");
    let t = std::fs::metadata(&rgb1).unwrap().modified().unwrap();
    let img = io::load_rgb(&rgb1).unwrap();
    let len = std::fs::metadata(&rgb1).unwrap().len();
    // The first encoder setting that gives another size.
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let png = [FilterType::NoFilter, FilterType::Sub, FilterType::Paeth]
        .into_iter()
        .flat_map(|f| [CompressionType::Fast, CompressionType::Best].map(|c| (c, f)))
        .map(|(c, f)| {
            let mut png = Vec::new();
            PngEncoder::new_with_quality(&mut png, c, f)
                .write_image(&img.data, img.width, img.height, image::ExtendedColorType::Rgb8)
                .unwrap();
            png
        })
        .find(|png| png.len() as u64 != len)
        .expect("an encoding of another size");
    assert_ne!(png.len() as u64, len, "the rewrite must change the size");
    std::fs::write(&rgb1, &png).unwrap();
    std::fs::File::options()
        .write(true)
        .open(&rgb1)
        .unwrap()
        .set_modified(t)
        .unwrap();
    assert_eq!(std::fs::metadata(&rgb1).unwrap().modified().unwrap(), t);
    assert_eq!(counts(&batch(&manifest, &out, &[])), (2, 2), "size of rgb1.png");
    let after = manifests(&out);
    assert_eq!(redone(&before, &after), names(&["f1", "f3"]));
    before = after;

    // Conventions, outputs, formats: each redoes every frame, and back again too.
    for (what, extra) in [
        ("conventions (--ndc vulkan)", vec!["--ndc", "vulkan"]),
        ("conventions (--rows top-down)", vec!["--rows", "top-down"]),
        ("conventions (--reversed-z)", vec!["--reversed-z"]),
        ("outputs", vec!["--outputs", "rgb,mask"]),
        ("depth formats", vec!["--depth-format", "exr,npy"]),
        ("colour format", vec!["--rgb-format", "jpeg"]),
        ("the defaults again", vec![]),
    ] {
        assert_eq!(counts(&batch(&manifest, &out, &extra)), (4, 0), "{what}");
        let after = manifests(&out);
        assert_eq!(redone(&before, &after), names(&["f0", "f1", "f2", "f3"]), "{what}");
        // And the same settings once more: all resumed.
        assert_eq!(counts(&batch(&manifest, &out, &extra)), (0, 4), "{what}, again");
        before = after;
    }
    for f in ["f0", "f1", "f2", "f3"] {
        assert!(frame_complete(&out.join(f)), "{f}");
    }
}

#[test]
fn shard_k_of_n_from_the_cli_takes_the_frames_with_i_mod_n_equal_k_and_resumes_per_shard() {
    let (dir, manifest) = setup("batch-shard", 7);
    for n in [2usize, 3] {
        let shared = dir.join(format!("shared-{n}"));
        for k in 0..n {
            // Alone in a folder: exactly its frames.
            let own = dir.join(format!("own-{k}-{n}"));
            let o = batch(&manifest, &own, &["--shard", &format!("{k}/{n}")]);
            let want: Vec<String> = (0..7).filter(|i| i % n == k).map(|i| format!("f{i}")).collect();
            assert_eq!(counts(&o), (want.len(), 0), "shard {k}/{n}");
            let text = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
            assert!(
                text.contains(&format!(
                    "shard {k}/{n}: {} frames belong to other shards",
                    7 - want.len()
                )),
                "{text}"
            );
            // The frame folders, beside the shard's index part.
            let frames: Vec<String> = files_in(&own)
                .into_iter()
                .filter(|f| !f.starts_with("index."))
                .collect();
            assert_eq!(frames, want, "shard {k}/{n}");
            assert!(own.join(format!("index.part-{k}-of-{n}.jsonl")).is_file());
            // Into a folder the earlier shards wrote: only its own frames are rendered, the
            // others' untouched; run again, all of its frames resume.
            let before = manifests(&shared);
            assert_eq!(
                counts(&batch(&manifest, &shared, &["--shard", &format!("{k}/{n}")])),
                (want.len(), 0)
            );
            let after = manifests(&shared);
            assert_eq!(redone(&before, &after), want, "shard {k}/{n} in the shared folder");
            assert_eq!(
                counts(&batch(&manifest, &shared, &["--shard", &format!("{k}/{n}")])),
                (0, want.len()),
                "shard {k}/{n} resumed"
            );
            assert_eq!(manifests(&shared), after);
        }
        // Together the shards made every frame once; unsharded, all resume.
        // (beside them the N index parts and the index the last shard joined)
        assert_eq!(files_in(&shared).len(), 7 + n + 1);
        assert_eq!(io_index_rows(&shared), 7 * 2);
        assert_eq!(counts(&batch(&manifest, &shared, &[])), (0, 7));
    }
}

#[test]
fn kill_9_mid_batch_then_resume_renders_only_the_unfinished_frames() {
    use std::os::unix::process::ExitStatusExt;
    let (dir, manifest) = setup("batch-kill", 16);
    let out = dir.join("out");
    // Large outputs so each frame takes tens of ms: the kill lands between frames 3 and 16.
    let heavy = ["--width-out", "800", "--height-out", "600"];
    let mut child = bin()
        .args(["refocus", "--zoom-range", "0.5,1.5", "--jobs", "1", "--batch"])
        .arg(&manifest)
        .arg("--out-dir")
        .arg(&out)
        .args(heavy)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while manifests(&out).len() < 3 {
        assert!(t0.elapsed().as_secs() < 120, "no frame finished in 120 s");
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_micros(500));
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.signal(), Some(9), "the batch ended before the kill ({status:?})");
    // Every frame with a manifest is complete; the others hold no final file (at most a
    // staging folder).
    let done: Vec<String> = manifests(&out).into_keys().collect();
    assert!(done.len() >= 3 && done.len() < 16, "{done:?}");
    for f in files_in(&out).into_iter().filter(|f| !f.starts_with(".viewsynth-")) {
        let frame = out.join(&f);
        if done.contains(&f) {
            assert!(frame_complete(&frame), "{f}: manifest without its files");
        } else {
            let finals: Vec<String> = files_in(&frame)
                .into_iter()
                .filter(|n| !n.starts_with(".viewsynth-"))
                .collect();
            assert!(finals.is_empty(), "{f}: unfinished frame with final files {finals:?}");
        }
    }
    // Resume: only the unfinished frames are rendered; the finished ones are untouched.
    let before = manifests(&out);
    let o = batch(&manifest, &out, &heavy);
    assert_eq!(counts(&o), (16 - done.len(), done.len()));
    let after = manifests(&out);
    assert_eq!(after.len(), 16);
    for f in &done {
        assert_eq!(before[f], after[f], "{f} was redone");
    }
    for f in after.keys() {
        let frame = out.join(f);
        assert!(frame_complete(&frame), "{f}");
        assert!(
            temporaries(&frame).is_empty(),
            "{f}: temporaries left: {:?}",
            files_in(&frame)
        );
    }
    assert!(temporaries(&out).is_empty(), "{:?}", files_in(&out));
}

/// Every place a batch can die in its file commits, not only where a timed kill happens to
/// land: the fault hook (`VIEWSYNTH_FAULT_AFTER`) ends the run (as SIGKILL, status 137) or fails
/// the frame (exit 1) after each step of each frame's set (journal, 7 renames, journal, lock
/// file and folder removed: 11 a frame). Before recovery a manifest only ever stands beside
/// its complete files; the resume then renders only what is unfinished, leaves the finished
/// frames untouched, and leaves every frame complete with no temporary anywhere.
#[test]
fn a_batch_ended_after_any_commit_step_resumes_to_every_frame_complete() {
    let (dir, manifest) = setup("batch-faults", 3);
    let steps = 3 * (1 + 7 + 3);
    let run = |out: &Path, fault: &str| {
        bin()
            .args(["refocus", "--zoom-range", "0.5,1.5", "--jobs", "1", "--batch"])
            .arg(&manifest)
            .arg("--out-dir")
            .arg(out)
            .env("VIEWSYNTH_FAULT_AFTER", fault)
            .output()
            .unwrap()
    };
    // In the out-dir and in each frame's folder.
    let all_temporaries = |out: &Path| -> Vec<String> {
        let frames = files_in(out).into_iter().filter(|f| out.join(f).is_dir());
        temporaries(out)
            .into_iter()
            .chain(frames.flat_map(|f| temporaries(&out.join(f))))
            .collect()
    };
    let mut failures = Vec::new();
    for k in 1..=steps + 1 {
        for mode in ["", ":fail"] {
            let out = dir.join(format!("k{k}{mode}"));
            let o = run(&out, &format!("{k}{mode}"));
            let want = match (k > steps, mode) {
                (true, _) => Some(0),
                (false, "") => Some(137),
                (false, _) => Some(1),
            };
            let label = format!("fault after step {k}{mode}");
            if o.status.code() != want {
                failures.push(format!("{label}: exit {:?}, expected {want:?}", o.status.code()));
            }
            let before = manifests(&out);
            for f in before.keys() {
                if !frame_complete(&out.join(f)) {
                    failures.push(format!("{label}: {f} has a manifest without its files"));
                }
            }
            // The resume: no fault this time.
            let o = batch(&manifest, &out, &[]);
            let (rendered, done) = counts(&o);
            if rendered + done != 3 || done < before.len() {
                failures.push(format!("{label}: resume rendered {rendered}, skipped {done}"));
            }
            let after = manifests(&out);
            for (f, m) in &before {
                if after.get(f) != Some(m) {
                    failures.push(format!("{label}: {f} was finished yet redone"));
                }
            }
            if after.len() != 3 || !after.keys().all(|f| frame_complete(&out.join(f))) {
                failures.push(format!("{label}: not every frame complete after the resume"));
            }
            let left = all_temporaries(&out);
            if !left.is_empty() {
                failures.push(format!("{label}: temporaries left: {left:?}"));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} problems:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Rows of the batch index under `out`.
fn io_index_rows(out: &Path) -> usize {
    viewsynth::refocus::batch::read_index(&out.join(viewsynth::refocus::batch::INDEX_NAME))
        .unwrap()
        .len()
}
