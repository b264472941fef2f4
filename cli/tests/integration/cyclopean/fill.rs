//! `cyclopean --fill` on Middlebury Cones: a complete spectator frame of at least 28 dB (the fill
//! pass against its twin is `viewsynth_tests`' `cyclopean::fill`).

use crate::common::data_dir;

/// The bar: with `--fill`, the default method's middle view of Cones (im2 + im6 with
/// their ground-truth disparities) scores at least 28 dB over every pixel against im4, where
/// the unfilled view's holes make an all-pixel score meaningless; filled pixels are 128 in the
/// mask, rendered ones 255, and without `--fill` no pixel is 128. Measured on llvmpipe when
/// written: 28.01 dB filled, 21.08 dB unfilled (holes hold the eyes' fallback mean).
#[test]
fn cones_with_fill_is_a_complete_frame_of_at_least_28_db() {
    let cones = data_dir().join("middlebury2003_cones");
    let f = |n: &str| cones.join(n).to_str().unwrap().to_string();
    let dir = crate::cli::scratch("cyclopean-fill");
    let run = |fill: bool, out: &std::path::Path| {
        let mut args = vec![
            "cyclopean".to_string(),
            "--left-rgb".into(),
            f("im2.png"),
            "--right-rgb".into(),
            f("im6.png"),
            "--left-disparity".into(),
            f("disp2.pgm"),
            "--right-disparity".into(),
            f("disp6.pgm"),
            "--disparity-scale".into(),
            "4".into(),
            "--out-dir".into(),
            out.to_str().unwrap().into(),
        ];
        if fill {
            args.push("--fill".into());
        }
        let o = crate::cli::bin().args(&args).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mask = image::open(out.join("middle_mask.png"))
            .unwrap()
            .into_luma8()
            .into_raw();
        let rgb = viewsynth::io::load_rgb(&out.join("middle_rgb.png")).unwrap();
        (mask, rgb)
    };
    let truth = viewsynth::io::load_rgb(&cones.join("im4.png")).unwrap();
    let psnr = |rgb: &viewsynth::io::RgbImage| {
        let se: f64 = rgb
            .data
            .iter()
            .zip(&truth.data)
            .map(|(a, b)| (*a as f64 - *b as f64).powi(2))
            .sum();
        viewsynth::metrics::psnr_from_mse(se / rgb.data.len() as f64)
    };
    let (plain_mask, plain) = run(false, &dir.join("plain"));
    let (mask, filled) = run(true, &dir.join("filled"));
    assert!(!plain_mask.contains(&128), "no pixel is filled without --fill");
    assert!(plain_mask.contains(&0), "Cones has holes to fill");
    assert!(
        mask.iter().all(|m| [128, 255].contains(m)),
        "with --fill every pixel is rendered or filled"
    );
    for (m, p) in mask.iter().zip(&plain_mask) {
        assert_eq!(*m == 128, *p == 0, "filled exactly where the plain view has holes");
    }
    let (a, b) = (psnr(&filled), psnr(&plain));
    println!("Cones all pixels vs im4: {a:.2} dB with --fill, {b:.2} dB without");
    assert!(a >= 28.0, "Cones with --fill: {a:.2} dB over all pixels (bar 28)");
}
