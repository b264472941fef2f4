//! Units are never assumed (issue 47): png16 depth is written in the units asked for
//! (`--depth-png-scale`), recorded, and depth beyond what the PNG holds is said.

use crate::cli::{bin, scratch};
use std::path::Path;
use viewsynth::io::{self, DepthMap, RgbImage};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn png16_depth_is_written_in_the_units_asked_for_and_overflow_is_said() {
    let d = scratch("units-png16");
    let (w, h) = (32u32, 24u32);
    let rgb: Vec<u8> = (0..w * h * 3).map(|i| (i % 251) as u8).collect();
    io::save_rgb(&d.join("rgb.png"), &RgbImage::new(w, h, rgb).unwrap()).unwrap();
    // 1.5 m to 3.05 m across the columns.
    let z: Vec<f32> = (0..w * h).map(|i| 1.5 + 0.05 * (i % w) as f32).collect();
    io::save_depth_npy(&d.join("depth.npy"), &DepthMap::new(w, h, z.clone()).unwrap()).unwrap();
    let run = |extra: &[&str], out: &str| {
        bin()
            .args([
                "refocus",
                "--rgb",
                s(&d.join("rgb.png")),
                "--depth",
                s(&d.join("depth.npy")),
            ])
            .args([
                "--fx",
                "40",
                "--fy",
                "40",
                "--cx",
                "15.5",
                "--cy",
                "11.5",
                "--zoom-range",
                "1",
            ])
            .args(["--outputs", "depth", "--out-dir", s(&d.join(out))])
            .args(extra)
            .output()
            .unwrap()
    };
    let manifest = |out: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(d.join(out).join("manifest.json")).unwrap()).unwrap()
    };
    // TUM units: a plain division by 5000 gives the metres back (within half a unit).
    let o = run(&["--depth-format", "png16", "--depth-png-scale", "5000"], "tum");
    assert!(o.status.success() && !text(&o).contains("warning"), "{}", text(&o));
    assert_eq!(manifest("tum")["outputs"][0]["depth_png16_units_per_metre"], 5000.0);
    let raw = image::open(d.join("tum/s1_depth.png"))
        .unwrap()
        .into_luma16()
        .into_raw();
    let kept: Vec<(f32, u16)> = z.iter().copied().zip(raw).filter(|&(_, r)| r > 0).collect();
    assert!(kept.len() > 600, "{}", kept.len());
    for (metres, raw) in kept {
        assert!(
            (f64::from(raw) / 5000.0 - f64::from(metres)).abs() <= 0.5 / 5000.0 + 1e-6,
            "{metres} {raw}"
        );
    }
    // 30000 units a metre hold 2.18 m: the farther columns are written invalid, counted and said.
    let o = run(&["--depth-format", "png16", "--depth-png-scale", "30000"], "fine");
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let warning = t
        .lines()
        .find(|l| l.starts_with("warning:"))
        .unwrap_or_else(|| panic!("{t}"));
    assert!(
        warning.contains("2.184 m") && warning.contains("--depth-png-scale"),
        "{warning}"
    );
    assert!(manifest("fine")["outputs"][0]["depth_png16_clipped"].as_u64().unwrap() > 0);
    // A unit that would change nothing, or none a PNG can hold, is refused by name.
    for (extra, out) in [
        (&["--depth-png-scale", "5000"][..], "no_png16"),
        (&["--depth-format", "png16", "--depth-png-scale=-5000"][..], "negative"),
    ] {
        let o = run(extra, out);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        assert!(
            text(&o).contains("--depth-png-scale") && !d.join(out).exists(),
            "{}",
            text(&o)
        );
    }
}
