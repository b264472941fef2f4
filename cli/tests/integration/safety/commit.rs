//! The commit protocol killed or failed after every step, for every command that writes files:
//! the folder holds the old set or the new one, complete, never a mixture.

use crate::common::assert_no_failures;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Stdio};

use viewsynth::io::{self};

use crate::cli::{bin, scratch, temporaries};
use crate::safety::support::{copy_dir, inputs, p, run, s};

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

#[test]
fn commit_survives_a_kill_or_a_failure_after_every_step() {
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
    assert_no_failures(failures, cases);
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
fn every_writing_command_is_all_or_none_after_any_commit_step() {
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
    assert_no_failures(failures, cases);
}
