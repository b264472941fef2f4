//! `viewsynth manifest`: a TUM-style sequence (rgb.txt, depth.txt) becomes a batch manifest
//! that `refocus --batch` renders; a bad listing is refused naming the file and line, with no
//! manifest written and an earlier one kept.

use crate::cli::{bin, scratch};
use crate::common::data_dir;
use std::path::{Path, PathBuf};

/// A sequence folder as TUM lays it out, its frames copies of ../shared/data's TUM frame: three
/// colour frames and two depth frames (the third colour frame has none within 0.02 s).
fn tum_sequence(name: &str) -> PathBuf {
    let dir = scratch(name);
    let data = data_dir().join("rgbd_open3d_testdata");
    std::fs::create_dir_all(dir.join("rgb")).unwrap();
    std::fs::create_dir_all(dir.join("depth")).unwrap();
    for t in ["1305031102.175304", "1305031102.211214", "1305031102.343278"] {
        std::fs::copy(data.join("TUM_color.png"), dir.join(format!("rgb/{t}.png"))).unwrap();
    }
    for t in ["1305031102.160407", "1305031102.226738"] {
        std::fs::copy(data.join("TUM_depth.png"), dir.join(format!("depth/{t}.png"))).unwrap();
    }
    std::fs::write(
        dir.join("rgb.txt"),
        "# color images\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n\
         1305031102.175304 rgb/1305031102.175304.png\n1305031102.211214 rgb/1305031102.211214.png\n\
         1305031102.343278 rgb/1305031102.343278.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("depth.txt"),
        "# depth maps\n# timestamp filename\n1305031102.160407 depth/1305031102.160407.png\n\
         1305031102.226738 depth/1305031102.226738.png\n",
    )
    .unwrap();
    dir
}

fn manifest(seq: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    bin()
        .arg("manifest")
        .arg(seq)
        .args(["--fx", "525", "--fy", "525", "--cx", "319.5", "--cy", "239.5", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn a_tum_listing_becomes_a_manifest_that_renders() {
    let seq = tum_sequence("manifest-tum");
    let csv = seq.join("frames.csv");
    let o = manifest(&seq, &csv, &[]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        stdout.contains("3 colour, 2 depth frames listed; paired 2 within 0.02 s"),
        "{stdout}"
    );
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        "rgb,depth,fx,fy,cx,cy,depth_scale,name\n\
         rgb/1305031102.175304.png,depth/1305031102.160407.png,525,525,319.5,239.5,5000,1305031102.175304\n\
         rgb/1305031102.211214.png,depth/1305031102.226738.png,525,525,319.5,239.5,5000,1305031102.211214\n"
    );
    let out = seq.join("out");
    let o = bin()
        .args(["refocus", "--zoom-range", "1", "--jobs", "1", "--batch"])
        .arg(&csv)
        .arg("--out-dir")
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && text.contains("2 frames: 2 rendered"), "{text}");
    // TUM's depth read at 5000 units per metre: at s = 1 every pixel with a depth is covered
    // (81 % of the frame; the rest has no measurement).
    let index = std::fs::read_to_string(out.join("index.jsonl")).unwrap();
    assert_eq!(index.lines().count(), 2, "{index}");
    for row in index.lines() {
        let row: serde_json::Value = serde_json::from_str(row).unwrap();
        let coverage = row["coverage"].as_f64().unwrap();
        assert!((0.75..0.9).contains(&coverage), "{row}");
    }
    let frame: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("1305031102.175304/manifest.json")).unwrap()).unwrap();
    assert!(frame.to_string().contains("\"depth_scale\":5000"), "{frame}");
}

#[test]
fn a_bad_listing_names_the_file_and_line_and_keeps_the_earlier_manifest() {
    let seq = tum_sequence("manifest-tum-bad");
    let csv = seq.join("frames.csv");
    std::fs::write(&csv, "earlier\n").unwrap();
    let rgb_txt = seq.join("rgb.txt");
    let good = std::fs::read_to_string(&rgb_txt).unwrap();
    for (listing, says) in [
        (
            good.replace("1305031102.211214 rgb", "13050311O2.211214 rgb"),
            "rgb.txt: line 5: '13050311O2.211214' is not a timestamp",
        ),
        (
            good.replace("rgb/1305031102.175304.png", "rgb/missing.png"),
            "rgb.txt: line 4: ",
        ),
        ("# nothing\n".to_string(), "rgb.txt: lists no frame"),
    ] {
        std::fs::write(&rgb_txt, &listing).unwrap();
        let o = manifest(&seq, &csv, &[]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains(says), "{says}: {stderr}");
        assert_eq!(std::fs::read_to_string(&csv).unwrap(), "earlier\n");
    }
    std::fs::write(&rgb_txt, &good).unwrap();
    // The numbers are the command line's: exit 2, naming the option.
    let o = manifest(&seq, &csv, &["--max-difference", "0"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--max-difference"), "{stderr}");
    // Without intrinsics: a usage error too.
    let o = bin().arg("manifest").arg(&seq).arg("--out").arg(&csv).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "earlier\n");
}
