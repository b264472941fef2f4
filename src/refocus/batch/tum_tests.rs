use super::*;
use crate::refocus::batch::load_manifest;

const K: Intrinsics = Intrinsics {
    fx: 525.0,
    fy: 525.0,
    cx: 319.5,
    cy: 239.5,
};

/// A sequence folder with the two listings and an empty file for every path they list.
fn sequence(tag: &str, rgb: &str, depth: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("viewsynth-tum-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("rgb")).unwrap();
    std::fs::create_dir_all(dir.join("depth")).unwrap();
    for text in [rgb, depth] {
        for line in text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()) {
            if let Some((_, p)) = line.split_once(' ') {
                std::fs::write(dir.join(p.trim()), b"").unwrap();
            }
        }
    }
    std::fs::write(dir.join("rgb.txt"), rgb).unwrap();
    std::fs::write(dir.join("depth.txt"), depth).unwrap();
    dir
}

fn run(dir: &Path, max_difference: f64) -> Result<TumAssociation> {
    associate_tum(
        dir,
        &dir.join("rgb.txt"),
        &dir.join("depth.txt"),
        K,
        TUM_DEPTH_SCALE,
        max_difference,
    )
}

#[test]
fn pairs_nearest_frames_once_each_within_the_tolerance() {
    // As associate.py pairs them: 1.00 takes depth 1.004 (closer to it than to 1.01); 1.01
    // is left with 0.98 (0.03 s away) and stays unpaired, as does 2.00 (1.95 is 0.05 s away);
    // 3.00 pairs with 3.015. Comments and blank lines are no frames.
    let dir = sequence(
        "pairs",
        "# color images\n# timestamp filename\n1.00 rgb/1.00.png\n\n1.01 rgb/1.01.png\n2.00 rgb/2.00.png\n3.00 rgb/3.00.png\n",
        "# depth maps\n0.98 depth/0.98.png\n1.004 depth/1.004.png\n1.95 depth/1.95.png\n3.015 depth/3.015.png\n",
    );
    let a = run(&dir, TUM_MAX_DIFFERENCE).unwrap();
    let pairs: Vec<(&str, PathBuf)> = a
        .frames
        .iter()
        .map(|f| (f.name.as_deref().unwrap(), f.depth.clone()))
        .collect();
    assert_eq!(
        pairs,
        [
            ("1.00", dir.join("depth/1.004.png")),
            ("3.00", dir.join("depth/3.015.png"))
        ]
    );
    assert_eq!(a.listed, (4, 4));
    let f = &a.frames[0];
    assert_eq!(
        (f.rgb.clone(), f.fx, f.cy, f.depth_scale),
        (dir.join("rgb/1.00.png"), 525.0, 239.5, Some(5000.0))
    );
    // A wider tolerance pairs 1.01 with 0.98 and 2.00 with 1.95 as well.
    assert_eq!(run(&dir, 0.06).unwrap().frames.len(), 4);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_listings_are_refused_naming_the_file_and_line() {
    let cases = [
        (
            "1.0 rgb/a.png\nabc rgb/b.png\n",
            "rgb.txt",
            "line 2: 'abc' is not a timestamp",
        ),
        ("# only\n1.0\n", "rgb.txt", "line 2: no path after the timestamp"),
        ("# nothing\n\n", "rgb.txt", "lists no frame"),
        ("1.0 rgb/gone.png\n", "rgb.txt", "line 1: "),
        ("9.0 rgb/a.png\n", "depth.txt", "no depth frame lies within 0.02 s"),
    ];
    for (i, (rgb, file, says)) in cases.into_iter().enumerate() {
        let dir = sequence(&format!("bad{i}"), "1.0 rgb/a.png\n", "1.0 depth/a.png\n");
        std::fs::write(dir.join("rgb.txt"), rgb).unwrap();
        let e = run(&dir, TUM_MAX_DIFFERENCE).unwrap_err().to_string();
        assert!(
            e.contains(&dir.join(file).display().to_string()) && e.contains(says),
            "{rgb:?}: {e}"
        );
        if rgb.contains("gone") {
            assert!(e.contains("no such file"), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
    let dir = sequence("tolerance", "1.0 rgb/a.png\n", "1.0 depth/a.png\n");
    for bad in [0.0, -1.0, f64::NAN] {
        assert!(
            run(&dir, bad).unwrap_err().to_string().contains("max_difference"),
            "{bad}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_written_manifest_reads_back_with_paths_relative_under_its_folder() {
    let dir = sequence("csv", "1.5 rgb/a,b.png\n", "1.5 depth/a.png\n");
    let a = run(&dir, TUM_MAX_DIFFERENCE).unwrap();
    let inside = dir.join("frames.csv");
    write_manifest_csv(&inside, &a.frames).unwrap();
    let text = std::fs::read_to_string(&inside).unwrap();
    assert_eq!(
        text,
        "rgb,depth,fx,fy,cx,cy,depth_scale,name\n\"rgb/a,b.png\",depth/a.png,525,525,319.5,239.5,5000,1.5\n"
    );
    let back = load_manifest(&inside).unwrap();
    assert_eq!(
        (back[0].rgb.clone(), back[0].name.as_deref()),
        (dir.join("rgb/a,b.png"), Some("1.5"))
    );
    // Elsewhere: absolute paths, read back to the same files.
    std::fs::create_dir_all(dir.join("other")).unwrap();
    let outside = dir.join("other").join("elsewhere.csv");
    write_manifest_csv(&outside, &a.frames).unwrap();
    let back = load_manifest(&outside).unwrap();
    assert_eq!(back[0].depth, std::path::absolute(dir.join("depth/a.png")).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}
