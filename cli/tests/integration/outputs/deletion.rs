//! What a run may delete (issue 46): only files that a regular file it wrote itself (a frame's
//! `manifest.json`, a set record) says it wrote, never one of its own inputs (by identity), never
//! a user file whose name merely looks like one of its own (index parts are known by their exact
//! names), and nothing before it knows it will succeed: a failed run leaves the folder
//! byte-identical, its index included.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Output;

use crate::cli::{bin, scratch};
use crate::outputs::over_inputs_and_leftovers::{frame, K};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn ok(args: &[&str]) {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", text(&o));
}

/// Every entry under `dir` (hidden ones included) by relative path: a file's size and the hash
/// of its bytes, a symlink's target, a folder as "dir". Two snapshots are equal only if the
/// folder is byte-identical (up to a 64-bit hash collision).
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, String> {
    fn walk(root: &Path, dir: &Path, into: &mut BTreeMap<PathBuf, String>) {
        use std::hash::{DefaultHasher, Hash, Hasher};
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let (path, t) = (e.path(), e.file_type().unwrap());
            let rel = path.strip_prefix(root).unwrap().to_path_buf();
            if t.is_symlink() {
                let target = std::fs::read_link(&path).unwrap();
                into.insert(rel, format!("-> {}", target.display()));
            } else if t.is_dir() {
                into.insert(rel.clone(), "dir".to_string());
                walk(root, &path, into);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                let mut h = DefaultHasher::new();
                bytes.hash(&mut h);
                into.insert(rel, format!("{} bytes, hash {:016x}", bytes.len(), h.finish()));
            }
        }
    }
    let mut all = BTreeMap::new();
    walk(dir, dir, &mut all);
    all
}

fn refocus(rgb: &Path, depth: &Path, zoom: &str, out: &Path) -> Output {
    let mut args = vec!["refocus", "--zoom-range", zoom, "--depth-format", "npy"];
    args.extend(K);
    args.extend(["--rgb", s(rgb), "--depth", s(depth), "--out-dir", s(out)]);
    run(&args)
}

fn batch(manifest: &Path, zoom: &str, out: &Path) -> Output {
    run(&[
        "refocus",
        "--jobs",
        "1",
        "--zoom-range",
        zoom,
        "--depth-format",
        "npy",
        "--batch",
        s(manifest),
        "--out-dir",
        s(out),
    ])
}

fn csv(rows: &[(&str, &Path, &Path)]) -> String {
    let mut text = "rgb,depth,fx,fy,cx,cy,name\n".to_string();
    for (name, rgb, depth) in rows {
        text += &format!("{},{},16,16,7.5,5.5,{name}\n", s(rgb), s(depth));
    }
    text
}

// A previous run's outputs given back as this run's inputs, into the same folder: the run
// would remove them as files of the previous set it does not write again. Refused before any
// work (refocus and reproject: a usage error, exit 2; a batch reads its frame list, exit 1),
// naming the input, and the folder is untouched. On the old tree each ran (exit 0) and
// deleted its own inputs.

/// refocus: scale 2, then its scale-2 output refocused at scale 1 into the same folder.
#[test]
fn refocus_never_deletes_its_inputs_among_the_previous_outputs() {
    let d = scratch("del-inputs-refocus");
    let (rgb, depth) = frame(&d, "src", 16, 12);
    let out = d.join("refocus");
    let o = refocus(&rgb, &depth, "2", &out);
    assert!(o.status.success(), "{}", text(&o));
    let before = snapshot(&out);
    let o = refocus(&out.join("s2_rgb.png"), &out.join("s2_depth.npy"), "1", &out);
    let err = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--rgb") && err.contains("s2_rgb.png"), "{err}");
    assert_eq!(snapshot(&out), before, "refocus changed its folder");
}

/// refocus --batch: the same through a frame's folder.
#[test]
fn a_batch_never_deletes_its_inputs_among_the_previous_outputs() {
    let d = scratch("del-inputs-batch");
    let (rgb, depth) = frame(&d, "src", 16, 12);
    let out = d.join("batch");
    let manifest = d.join("frames.csv");
    std::fs::write(&manifest, csv(&[("f", &rgb, &depth)])).unwrap();
    let o = batch(&manifest, "2", &out);
    assert!(o.status.success(), "{}", text(&o));
    let (again_rgb, again_depth) = (out.join("f/s2_rgb.png"), out.join("f/s2_depth.npy"));
    std::fs::write(&manifest, csv(&[("f", &again_rgb, &again_depth)])).unwrap();
    let before = snapshot(&out);
    let o = batch(&manifest, "1", &out);
    let err = text(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--batch rgb") && err.contains("s2_rgb.png"), "{err}");
    assert_eq!(snapshot(&out), before, "the batch changed its folder");
}

/// reproject: left to right, then the right eye back to the left into the same folder.
#[test]
fn reproject_never_deletes_its_inputs_among_the_previous_outputs() {
    let d = scratch("del-inputs-reproject");
    let (rgb, depth) = frame(&d, "src", 16, 12);
    let out = d.join("reproject");
    let reproject = |color: &Path, depth: &Path, from: &str, to: &str| {
        let mut args = vec!["reproject", "--baseline", "0.06", "--depth-format", "npy"];
        args.extend(K);
        args.extend(["--from", from, "--to", to]);
        args.extend(["--color", s(color), "--depth", s(depth), "--out-dir", s(&out)]);
        run(&args)
    };
    let o = reproject(&rgb, &depth, "left", "right");
    assert!(o.status.success(), "{}", text(&o));
    let before = snapshot(&out);
    let o = reproject(
        &out.join("right_rgb.png"),
        &out.join("right_depth.npy"),
        "right",
        "left",
    );
    let err = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--color") && err.contains("right_rgb.png"), "{err}");
    assert_eq!(snapshot(&out), before, "reproject changed its folder");
}

/// A `manifest.json` that is a symlink was not written by the run: what its target lists stays.
/// On the old tree the link was followed and the user's file it named was deleted.
#[test]
fn a_symlinked_manifest_deletes_nothing() {
    let d = scratch("del-symlink");
    let (rgb, depth) = frame(&d, "src", 16, 12);
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "the user's").unwrap();
    let elsewhere = d.join("elsewhere.json");
    std::fs::write(&elsewhere, r#"{"files": [{"name": "notes.txt"}]}"#).unwrap();
    std::os::unix::fs::symlink(&elsewhere, out.join("manifest.json")).unwrap();
    let o = refocus(&rgb, &depth, "1", &out);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "the user's");
    assert!(std::fs::read_to_string(&elsewhere).unwrap().contains("notes.txt"));
}

/// A file is never removed because its name looks like an output's: cyclopean removed every
/// `middle_*` file of its folder on the old tree (a user's notes included); now only what its
/// previous run's record lists goes.
#[test]
fn a_users_file_named_like_an_output_stays() {
    let d = scratch("del-look-alike");
    let (left, _) = frame(&d, "left", 16, 12);
    let (right, _) = frame(&d, "right", 16, 12);
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("middle_notes.txt"), "the user's").unwrap();
    let cyclopean = |extra: &[&str]| {
        let mut args = vec!["cyclopean", "--left-rgb", s(&left), "--right-rgb", s(&right)];
        args.extend(["--max-disparity", "4", "--out-dir", s(&out)]);
        args.extend(extra);
        ok(&args);
    };
    cyclopean(&[]);
    assert!(out.join("middle_depth.exr").is_file() || out.join("middle_rgb.png").is_file());
    // A rerun with colour alone: the first run's other files go, the user's stays.
    cyclopean(&["--outputs", "rgb"]);
    let visible: Vec<String> = crate::cli::files_in(&out)
        .into_iter()
        .filter(|f| !f.starts_with('.'))
        .collect();
    assert_eq!(visible, ["middle_notes.txt", "middle_rgb.png"]);
    assert_eq!(
        std::fs::read_to_string(out.join("middle_notes.txt")).unwrap(),
        "the user's"
    );
}

// Index parts are known by their exact names: a user's file whose name merely parses as one
// stays, `of-0` is no part, and no frame may take one of the index's names.

/// On the old tree the look-alikes were deleted by the batch.
#[test]
fn files_named_almost_as_index_parts_are_the_users() {
    let d = scratch("del-index-look-alikes");
    let (rgb, depth) = frame(&d, "src", 16, 12);
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let look_alikes = ["index.part-00-of-01.jsonl", "index.part-+0-of-+1.jsonl"];
    for name in look_alikes {
        std::fs::write(out.join(name), "the user's").unwrap();
    }
    let manifest = d.join("frames.csv");
    std::fs::write(&manifest, csv(&[("f", &rgb, &depth)])).unwrap();
    let o = batch(&manifest, "1", &out);
    assert!(o.status.success(), "{}", text(&o));
    assert!(out.join("index.jsonl").is_file());
    for name in look_alikes {
        assert_eq!(std::fs::read_to_string(out.join(name)).unwrap(), "the user's", "{name}");
    }
}

/// On the old tree `viewsynth index` joined a lone `index.part-0-of-0.jsonl` into an empty
/// index (exit 0).
#[test]
fn a_part_of_zero_parts_is_no_part() {
    let d = scratch("del-index-of-0");
    let lone = d.join("lone");
    std::fs::create_dir_all(&lone).unwrap();
    std::fs::write(lone.join("index.part-0-of-0.jsonl"), "").unwrap();
    let o = run(&["index", s(&lone)]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(!lone.join("index.jsonl").exists());
}

/// On the old tree frames named as the index were rendered (and broke every later index).
#[test]
fn no_frame_takes_an_index_name() {
    let d = scratch("del-index-frame-names");
    let (rgb, depth) = frame(&d, "src", 16, 12);
    let manifest = d.join("frames.csv");
    for name in ["index.jsonl", "index.part-0-of-2.jsonl"] {
        let out = d.join(format!("named-{name}"));
        std::fs::write(&manifest, csv(&[(name, &rgb, &depth)])).unwrap();
        let o = batch(&manifest, "1", &out);
        let err = text(&o);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(name), "{name}: {err}");
        assert!(!out.join(name).exists(), "{name}");
    }
}

/// A batch whose every frame fails (here: a depth file that is not one) removes nothing, index
/// included: the folder is byte-identical after. On the old tree the run removed `index.jsonl`
/// and its part before the first frame and wrote them again without the frame's rows.
#[test]
fn a_failed_batch_leaves_its_folder_byte_identical() {
    let d = scratch("del-failed-batch");
    let (rgb, depth) = frame(&d, "src", 16, 12);
    let out = d.join("out");
    let manifest = d.join("frames.csv");
    std::fs::write(&manifest, csv(&[("f", &rgb, &depth)])).unwrap();
    ok(&[
        "refocus",
        "--jobs",
        "1",
        "--zoom-range",
        "1",
        "--batch",
        s(&manifest),
        "--out-dir",
        s(&out),
    ]);
    assert!(out.join("index.jsonl").is_file());
    let before = snapshot(&out);
    let broken = d.join("broken.npy");
    std::fs::write(&broken, "not a depth map").unwrap();
    std::fs::write(&manifest, csv(&[("f", &rgb, &broken)])).unwrap();
    let o = batch(&manifest, "2", &out);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert_eq!(snapshot(&out), before);
}
