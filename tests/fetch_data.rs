//! `ci/fetch-data.py` with `VIEWSYNTH_DATA_MIRROR` (no network): from a copy of the data folder
//! it fetches and verifies every file `ci/data-sources.txt` lists, and a changed byte in the
//! mirror fails the run, naming the file, with nothing written. The list covers every data file
//! of the data folder (`VIEWSYNTH_DATA_DIR`, default `../shared/data`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn data_dir() -> PathBuf {
    let dir = std::env::var_os("VIEWSYNTH_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(ROOT).join("../shared/data"));
    assert!(
        dir.is_dir(),
        "test data missing: {} (fetch it with `python3 ci/fetch-data.py`, or set VIEWSYNTH_DATA_DIR)",
        dir.display()
    );
    dir
}

/// Paths under the data folder that `ci/data-sources.txt` lists.
fn listed() -> Vec<String> {
    let text = std::fs::read_to_string(Path::new(ROOT).join("ci/data-sources.txt")).unwrap();
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().nth(1).expect("SHA256  PATH  URL").to_string())
        .collect()
}

/// Every file under `dir`, as paths relative to it with `/` separators.
fn files_under(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap();
                out.push(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    out.sort();
    out
}

fn copy_tree(from: &Path, to: &Path) {
    for rel in files_under(from) {
        let dst = to.join(&rel);
        std::fs::create_dir_all(dst.parent().unwrap()).unwrap();
        std::fs::copy(from.join(&rel), dst).unwrap();
    }
}

fn fetch(mirror: &str, dest: &Path) -> Output {
    Command::new("python3")
        .arg(Path::new(ROOT).join("ci/fetch-data.py"))
        .arg("--dest")
        .arg(dest)
        .env("VIEWSYNTH_DATA_MIRROR", mirror)
        .env_remove("VIEWSYNTH_DATA_DIR")
        .output()
        .expect("python3 runs ci/fetch-data.py")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("viewsynth-fetch-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_sources_list_covers_every_data_file() {
    let data = data_dir();
    let mut list = listed();
    list.sort();
    // The folder's own notes (README.md files, verify.py) are documentation, not data.
    let data_files: Vec<String> = files_under(&data)
        .into_iter()
        .filter(|f| !f.ends_with("README.md") && f != "verify.py")
        .collect();
    assert_eq!(list, data_files, "ci/data-sources.txt against {}", data.display());
}

#[test]
fn a_mirror_copy_verifies_every_file_and_a_changed_byte_fails() {
    let work = scratch("mirror");
    let mirror = work.join("mirror");
    copy_tree(&data_dir(), &mirror);
    let list = listed();

    // A file:// URL, into an empty folder: every listed file fetched, verified, byte-identical.
    let dest = work.join("fetched");
    let out = fetch(&format!("file://{}", mirror.display()), &dest);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains(&format!("{} files verified", list.len())), "{stdout}");
    for rel in &list {
        assert_eq!(
            std::fs::read(dest.join(rel)).unwrap(),
            std::fs::read(mirror.join(rel)).unwrap(),
            "{rel}"
        );
    }

    // One byte changed in the mirror (a plain folder path this time): exit 1 naming the file,
    // and nothing written to the fresh destination.
    let victim = "rgbd_open3d_testdata/TUM_depth.png";
    let mut bytes = std::fs::read(mirror.join(victim)).unwrap();
    bytes[1000] ^= 0x01;
    std::fs::write(mirror.join(victim), bytes).unwrap();
    let dest = work.join("refused");
    let out = fetch(mirror.to_str().unwrap(), &dest);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(victim) && stderr.contains("SHA-256"), "{stderr}");
    assert!(files_under(&dest).is_empty(), "files written: {:?}", files_under(&dest));

    // A mirror that is not a folder is a usage error.
    let out = fetch(work.join("absent").to_str().unwrap(), &dest);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::remove_dir_all(&work).unwrap();
}
