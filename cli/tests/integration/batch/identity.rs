//! Resume by identity: a finished frame is recognised by its inputs' identity (size and mtime,
//! or content) and the settings, never by how the manifest's path was spelt, from which working
//! folder, or where a copy of the data sits. And a row's identity in the other sense: the
//! intrinsics a row lacks come from `--fx/--fy/--cx/--cy`.

use crate::batch::resume::setup;
use crate::cli::bin;
use std::path::Path;
use std::process::Output;

/// `refocus --batch MANIFEST` run in `cwd`, into the absolute `out`.
fn batch_in(cwd: &Path, manifest: &str, out: &Path, extra: &[&str]) -> Output {
    bin()
        .current_dir(cwd)
        .args(["refocus", "--zoom-range", "0.5,1.5", "--jobs", "1", "--batch", manifest])
        .arg("--out-dir")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

/// The summary's "R rendered, S already done", checked to be a success.
fn rendered_done(o: &Output) -> String {
    let text = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{text}");
    let at = text
        .find(" rendered")
        .unwrap_or_else(|| panic!("no summary in: {text}"));
    let start = text[..at].rfind(' ').map_or(0, |i| i + 1);
    let end = text[at..]
        .find(" already done")
        .map(|i| at + i)
        .unwrap_or_else(|| panic!("{text}"));
    text[start..end].to_string()
}

#[test]
fn a_rerun_with_the_manifest_spelt_otherwise_or_from_another_folder_renders_nothing() {
    let (dir, _) = setup("batch-identity-spellings", 2);
    let out = dir.join("out");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let abs = dir.join("frames.csv").to_string_lossy().into_owned();
    assert_eq!(rendered_done(&batch_in(&dir, "frames.csv", &out, &[])), "2 rendered, 0");
    for (cwd, spelling) in [
        (dir.clone(), "./frames.csv"),
        (dir.clone(), abs.as_str()),
        (dir.clone(), "sub/../frames.csv"),
        (dir.join("sub"), "../frames.csv"),
        (std::env::temp_dir(), abs.as_str()),
    ] {
        let o = batch_in(&cwd, spelling, &out, &[]);
        assert_eq!(rendered_done(&o), "0 rendered, 2", "{spelling} from {}", cwd.display());
    }
    // The same data copied elsewhere (new paths, new mtimes: a container's mount, a synced
    // disk) is recognised by content.
    let copy = dir.join("copy");
    std::fs::create_dir_all(&copy).unwrap();
    for f in ["frames.csv", "rgb0.png", "rgb1.png", "depth0.npy", "depth1.npy"] {
        std::fs::copy(dir.join(f), copy.join(f)).unwrap();
    }
    let o = batch_in(&copy, "frames.csv", &out, &[]);
    assert_eq!(rendered_done(&o), "0 rendered, 2", "a copy of the data");
    // --verify checks content too, and finds the same.
    let o = batch_in(&copy, "frames.csv", &out, &["--verify"]);
    assert_eq!(rendered_done(&o), "0 rendered, 2", "--verify");

    // A finished file changed in place with its size kept: only --verify sees it.
    let rgb = out.join("f0").join("s1.5_rgb.png");
    let mut bytes = std::fs::read(&rgb).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0xff;
    std::fs::write(&rgb, &bytes).unwrap();
    assert_eq!(rendered_done(&batch_in(&dir, "frames.csv", &out, &[])), "0 rendered, 2");
    assert_eq!(
        rendered_done(&batch_in(&dir, "frames.csv", &out, &["--verify"])),
        "1 rendered, 1",
        "--verify redoes the frame whose file no longer matches its CRC"
    );
}

#[test]
fn fx_fy_cx_cy_are_the_defaults_of_rows_that_lack_them() {
    let (dir, _) = setup("batch-intrinsics-defaults", 2);
    // No fx column; cx, cy empty on the second row; the first row's own cx wins.
    std::fs::write(
        dir.join("k.csv"),
        "rgb,depth,fy,cx,cy,name\nrgb0.png,depth0.npy,40,15,11.5,a\nrgb1.png,depth1.npy,40,,,b\n",
    )
    .unwrap();
    let out = dir.join("out");
    let defaults = ["--fx", "40", "--cx", "15.5", "--cy", "11.5"];
    let o = batch_in(&dir, "k.csv", &out, &defaults);
    assert_eq!(rendered_done(&o), "2 rendered, 0");
    let k = |f: &str| -> serde_json::Value {
        let m: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join(f).join("manifest.json")).unwrap()).unwrap();
        m["settings"]["intrinsics"].clone()
    };
    assert_eq!(k("a"), serde_json::json!([40.0, 40.0, 15.0, 11.5]));
    assert_eq!(k("b"), serde_json::json!([40.0, 40.0, 15.5, 11.5]));
    // Without the default, the missing value is refused by name, nothing written.
    let o = batch_in(&dir, "k.csv", &dir.join("out2"), &["--fx", "40"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_ne!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("cx"), "{err}");
    assert!(!dir.join("out2").join("b").exists());
}
