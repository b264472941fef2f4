//! Units are never assumed (issue 47). png16 depth is written in the units asked for
//! (`--depth-png-scale`), recorded, and depth beyond what the PNG holds is said. Disparity inputs
//! are checked as depth inputs are: a summary per map, a warning naming `--disparity-scale` and
//! the value the views agree with when another scale fits far better (Middlebury Cones read at 1
//! instead of 4 rendered a doubled view at exit 0, silently), and grey maps stored as palette or
//! RGB PNGs read as the grey they hold.

use crate::cli::{bin, scratch};
use crate::common::data_dir;
use std::path::{Path, PathBuf};
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

fn cones(file: &str) -> PathBuf {
    data_dir().join("middlebury2003_cones").join(file)
}

/// `cyclopean` of Cones with the given disparity files and extra options into `out`.
fn run(left: &Path, right: &Path, extra: &[&str], out: &Path) -> std::process::Output {
    bin()
        .args([
            "cyclopean",
            "--left-rgb",
            s(&cones("im2.png")),
            "--right-rgb",
            s(&cones("im6.png")),
        ])
        .args(["--left-disparity", s(left), "--right-disparity", s(right)])
        .args(["--out-dir", s(out)])
        .args(extra)
        .output()
        .unwrap()
}

/// The PGM's grey values (the 2003 maps: 4 units a pixel).
fn grey(pgm: &Path) -> (u32, u32, Vec<u8>) {
    let img = image::open(pgm).unwrap().into_luma8();
    (img.width(), img.height(), img.into_raw())
}

/// `values` as an 8-bit palette PNG whose entry i is (i, i, i).
fn write_palette_png(path: &Path, (w, h, values): &(u32, u32, Vec<u8>)) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut e = png::Encoder::new(file, *w, *h);
    e.set_color(png::ColorType::Indexed);
    e.set_depth(png::BitDepth::Eight);
    e.set_palette((0..=255u8).flat_map(|i| [i, i, i]).collect::<Vec<u8>>());
    e.write_header().unwrap().write_image_data(values).unwrap();
}

/// `values` as an RGB PNG with each channel equal to the grey value.
fn write_rgb_png(path: &Path, (w, h, values): &(u32, u32, Vec<u8>)) -> Vec<u8> {
    let rgb: Vec<u8> = values.iter().flat_map(|&v| [v, v, v]).collect();
    image::RgbImage::from_raw(*w, *h, rgb.clone())
        .unwrap()
        .save(path)
        .unwrap();
    rgb
}

#[test]
fn cones_without_its_disparity_scale_warns_naming_the_value_that_fits() {
    let d = scratch("disp-units-scale");
    let (left, right) = (cones("disp2.pgm"), cones("disp6.pgm"));
    let o = run(&left, &right, &[], &d.join("unscaled"));
    let t = text(&o);
    // Still rendered (a warning, not a refusal), but said, with the fix.
    assert!(o.status.success(), "{t}");
    assert!(
        t.contains("input disparity") && t.contains("at --disparity-scale 1"),
        "{t}"
    );
    let warnings: Vec<&str> = t.lines().filter(|l| l.starts_with("warning:")).collect();
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("disp2.pgm") && w.contains("--disparity-scale 4 ")),
        "{t}"
    );
    let o = run(&left, &right, &["--disparity-scale", "4"], &d.join("scaled"));
    let t = text(&o);
    assert!(o.status.success() && !t.contains("warning"), "{t}");
    assert!(t.contains("at --disparity-scale 4"), "{t}");
}

#[test]
fn palette_and_rgb_copies_of_grey_disparities_render_as_the_pgms_and_unequal_channels_are_refused() {
    let d = scratch("disp-units-png");
    let (left, right) = (cones("disp2.pgm"), cones("disp6.pgm"));
    let (left_png, right_png, bad_png) = (d.join("disp2.png"), d.join("disp6.png"), d.join("bad.png"));
    write_palette_png(&left_png, &grey(&left));
    let mut rgb = write_rgb_png(&right_png, &grey(&right));
    let scale = ["--disparity-scale", "4"];
    let pgm = run(&left, &right, &scale, &d.join("pgm"));
    assert!(pgm.status.success(), "{}", text(&pgm));
    let png = run(&left_png, &right_png, &scale, &d.join("png"));
    assert!(png.status.success(), "{}", text(&png));
    for file in ["middle_rgb.png", "middle_mask.png"] {
        let (a, b) = (d.join("pgm").join(file), d.join("png").join(file));
        assert!(
            std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
            "{file} differs"
        );
    }
    // Green of pixel (5, 3) one level off: a colour picture, refused naming the pixel.
    let (w, h, _) = grey(&right);
    rgb[3 * (3 * w as usize + 5) + 1] ^= 1;
    image::RgbImage::from_raw(w, h, rgb).unwrap().save(&bad_png).unwrap();
    let out = d.join("bad");
    let o = run(&left_png, &bad_png, &scale, &out);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(t.contains("bad.png") && t.contains("differ at pixel (5, 3)"), "{t}");
    assert!(!t.contains("panicked") && !out.exists(), "{t}");
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
