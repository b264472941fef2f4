//! A whole spectator frame from two images through the command (issue 38): the real pairs'
//! complete frames against the optical-flow peer (python/peers/flow_interpolation.py). The
//! densify pass against its twin is `viewsynth_tests`' `cyclopean::densify`.

use crate::common::data_dir;
use viewsynth::io::{load_rgb, RgbImage};

/// One pair of the table: its images, the true middle view, and the flow peer's PSNR
/// over all pixels (python/peers/flow_interpolation.py, OpenCV 5.0.0 DIS preset MEDIUM, run on
/// these very files when written; OpenCV is not a test dependency, so its figure is kept here).
struct Pair {
    name: &'static str,
    left: RgbImage,
    right: RgbImage,
    truth: RgbImage,
    flow_db: f64,
    /// The rendered (mask 255) pixels' PSNR of the unsigned matcher before issue 38 (its
    /// default search 0..=W/6), measured with this very command: precision is kept.
    before_db: f64,
}

/// `img`'s columns `from..from + width`.
pub(super) fn columns(img: &RgbImage, from: u32, width: u32) -> RgbImage {
    let data = img
        .data
        .chunks_exact(3 * img.width as usize)
        .flat_map(|row| row[3 * from as usize..3 * (from + width) as usize].to_vec())
        .collect();
    RgbImage::new(width, img.height, data).unwrap()
}

fn pairs() -> Vec<Pair> {
    let d = data_dir();
    let rgb = |set: &str, f: &str| load_rgb(&d.join(set).join(f)).unwrap();
    let cones = ("middlebury2003_cones", "im2.png", "im6.png", "im4.png");
    let (cl, cr, cm) = (rgb(cones.0, cones.1), rgb(cones.0, cones.2), rgb(cones.0, cones.3));
    // Disparities crossing zero: the left image loses its first 24 columns and the right its
    // last 24, so every disparity d becomes d - 24 (Cones: 0..55 -> -24..31); the true middle
    // view loses 12 on each side.
    let (c, w) = (24, cl.width - 24);
    let crossing = Pair {
        name: "Cones 2+6 -> 4 cropped (disparities -24..31)",
        left: columns(&cl, c, w),
        right: columns(&cr, 0, w),
        truth: columns(&cm, c / 2, w),
        flow_db: 26.40,
        before_db: 0.0,
    };
    let ts = |f: &str| rgb("tsukuba_5view_no_gt", f);
    vec![
        Pair {
            name: "Cones 2+6 -> 4",
            left: cl,
            right: cr,
            truth: cm,
            flow_db: 23.69,
            before_db: 29.16,
        },
        Pair {
            name: "Tsukuba 2+4 -> 3",
            left: ts("tsukuba2.png"),
            right: ts("tsukuba4.png"),
            truth: ts("tsukuba3.png"),
            flow_db: 29.22,
            before_db: 31.26,
        },
        Pair {
            name: "Tsukuba 1+5 -> 3",
            left: ts("tsukuba1.png"),
            right: ts("tsukuba5.png"),
            truth: ts("tsukuba3.png"),
            flow_db: 25.24,
            before_db: 29.63,
        },
        crossing,
    ]
}

/// PSNR of `img` against `truth` over the pixels `keep` holds.
pub(super) fn psnr(img: &RgbImage, truth: &RgbImage, keep: impl Fn(usize) -> bool) -> f64 {
    let (mut se, mut n) = (0.0, 0usize);
    for i in (0..img.data.len() / 3).filter(|&i| keep(i)) {
        for c in 0..3 {
            se += (img.data[3 * i + c] as f64 - truth.data[3 * i + c] as f64).powi(2);
        }
        n += 3;
    }
    viewsynth::metrics::psnr_from_mse(se / n.max(1) as f64)
}

/// The bar, with the same settings for every pair (the defaults): `cyclopean --fill`
/// from two images alone is never below the flow interpolation over all pixels, leads it by at
/// least 1 dB on average, and keeps the rendered pixels' precision; the zero-crossing pair's
/// range is found with its negative end.
#[test]
fn a_complete_frame_from_two_images_beats_flow_interpolation() {
    let dir = crate::cli::scratch("cyclopean-dense");
    let mut lead = Vec::new();
    for (k, pair) in pairs().into_iter().enumerate() {
        let case = dir.join(format!("pair{k}"));
        std::fs::create_dir_all(&case).unwrap();
        let (l, r) = (case.join("l.png"), case.join("r.png"));
        viewsynth::io::save_rgb(&l, &pair.left).unwrap();
        viewsynth::io::save_rgb(&r, &pair.right).unwrap();
        let out = case.join("out");
        let o = crate::cli::bin()
            .args(["cyclopean", "--left-rgb"])
            .arg(&l)
            .arg("--right-rgb")
            .arg(&r)
            .args(["--fill", "--out-dir"])
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{}: {stderr}", pair.name);
        assert!(
            stderr.contains("disparity range"),
            "{}: the range is printed: {stderr}",
            pair.name
        );
        let view = load_rgb(&out.join("middle_rgb.png")).unwrap();
        let mask = image::open(out.join("middle_mask.png"))
            .unwrap()
            .into_luma8()
            .into_raw();
        assert!(
            mask.iter().all(|m| [128, 255].contains(m)),
            "{}: a complete frame",
            pair.name
        );
        let all = psnr(&view, &pair.truth, |_| true);
        let rendered = psnr(&view, &pair.truth, |i| mask[i] == 255);
        println!(
            "{}: {all:.2} dB over all pixels (flow {:.2}), {rendered:.2} dB on the {:.1} % rendered; {}",
            pair.name,
            pair.flow_db,
            100.0 * mask.iter().filter(|m| **m == 255).count() as f64 / mask.len() as f64,
            stderr.lines().find(|l| l.contains("disparity range")).unwrap_or("")
        );
        assert!(
            all >= pair.flow_db,
            "{}: {all:.2} dB, below the flow peer's {:.2}",
            pair.name,
            pair.flow_db
        );
        // Rendered pixels: at least the unsigned matcher's, within the print's rounding.
        assert!(
            rendered >= pair.before_db - 0.03,
            "{}: {rendered:.2} dB on rendered pixels, before {:.2}",
            pair.name,
            pair.before_db
        );
        if pair.before_db == 0.0 {
            let min: i32 = stderr
                .split("disparity range ")
                .nth(1)
                .and_then(|s| s.split("..").next())
                .and_then(|s| s.parse().ok())
                .expect("the range is printed as MIN..MAX");
            assert!(
                min < -10,
                "{}: the negative disparities are searched ({min})",
                pair.name
            );
        }
        lead.push(all - pair.flow_db);
    }
    let mean = lead.iter().sum::<f64>() / lead.len() as f64;
    println!("mean lead over the flow interpolation: {mean:+.2} dB");
    assert!(
        mean >= 1.0,
        "mean lead {mean:+.2} dB over the flow interpolation (bar +1)"
    );
}
