//! Resume that verifies: a folder edited after the run and float settings read back bit-equal
//! decide whether a frame is redone.

use crate::common::assert_no_failures;
use std::collections::BTreeMap;

use crate::cli::{bin, files_in, scratch};
use crate::safety::support::{copy_dir, inputs, p};

#[test]
fn resume_verifies_folders_and_float_settings() {
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
    assert_no_failures(failures, cases);
}
