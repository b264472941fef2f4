//! `compare`: the same frame written under every convention compares equal after conversion;
//! flipped rows, NDC z stored as window depth, and a reversed-Z mismatch are detected and named.

use viewsynth::camera::Pose;
use viewsynth::compare::{compare, Side};
use viewsynth::convention::{Conventions, DepthPlanes, RowOrder};
use viewsynth::depth::DepthEncoding;
use viewsynth::io::{DepthMap, RgbImage};

const PLANES: DepthPlanes = DepthPlanes { near: 0.05, far: 50.0 };

/// One rendering of the scene, stored as a renderer under `conv` would store it: rows in
/// `conv.row_order`, window depth under `conv` (the far value where nothing was hit).
fn stored(conv: Conventions) -> Side {
    let cam = viewsynth::world::demo_camera(96, 72);
    let (color, z) = viewsynth::world::render_scene(&viewsynth::world::builtin("demo").unwrap(), &cam, &Pose::IDENTITY);
    let window: Vec<f32> = z
        .data
        .iter()
        .map(|&v| {
            if v > 0.0 {
                DepthPlanes::window_depth_of_ndc_z(&conv, PLANES.ndc_z_of_view_z(&conv, v as f64)) as f32
            } else {
                conv.clear_depth() as f32
            }
        })
        .collect();
    let bytes: Vec<u8> = window.iter().flat_map(|v| v.to_ne_bytes()).collect();
    let depth = conv
        .row_order
        .convert_rows(bytes, 96 * 4)
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    Side::new(
        RgbImage::new(96, 72, conv.row_order.convert_rows(color.data, 96 * 3)).unwrap(),
        Some(DepthMap::new(96, 72, depth).unwrap()),
        DepthEncoding::Device { planes: PLANES },
        conv,
    )
}

#[test]
fn every_convention_compares_equal_to_every_other_after_conversion() {
    // Depth is stored as f32 window depth: back to view Z within its resolution (standard Z,
    // near 0.05 m, scene up to 6 m: ~1e-5 relative). Colour is the same rendering: identical.
    let a = stored(Conventions::default());
    for conv in Conventions::all() {
        let (c, _) = compare(&a, &stored(conv)).unwrap();
        assert_eq!(c.max_color_diff, 0.0, "{}: {c:?}", conv.label());
        assert_eq!(c.mask_disagreement, Some(0), "{}", conv.label());
        assert!(c.depth_max_rel.unwrap() < 2e-5, "{}: {c:?}", conv.label());
        assert!(c.suspicions.is_empty(), "{}: {c:?}", conv.label());
    }
}

#[test]
fn flipped_rows_ndc_stored_as_window_depth_and_reversed_z_mismatch_are_named() {
    let a = stored(Conventions::default());
    // Written top-down, declared bottom-up.
    let mut b = stored(Conventions {
        row_order: RowOrder::TopDown,
        ..Conventions::default()
    });
    b.conv.row_order = RowOrder::BottomUp;
    let (c, _) = compare(&a, &b).unwrap();
    assert!(
        matches!(&c.suspicions[..], [s] if s.contains("rows read as top-down")),
        "{c:?}"
    );
    // GL NDC z in [-1, 1] stored where window depth is declared.
    let mut b = stored(Conventions::default());
    for v in b.depth.as_mut().unwrap().data.iter_mut() {
        *v = 2.0 * *v - 1.0;
    }
    let (c, _) = compare(&a, &b).unwrap();
    assert!(
        matches!(&c.suspicions[..], [s] if s.contains("NDC z") && s.contains("--b-depth-kind ndc --b-ndc gl")),
        "{c:?}"
    );
    // Declared as such, it reads right.
    b.ndc_z = true;
    let (c, _) = compare(&a, &b).unwrap();
    assert!(c.suspicions.is_empty() && c.depth_max_rel.unwrap() < 2e-5, "{c:?}");
    // Written with reversed-Z, declared standard.
    let mut b = stored(Conventions {
        reversed_z: true,
        ..Conventions::default()
    });
    b.conv.reversed_z = false;
    let (c, _) = compare(&a, &b).unwrap();
    assert!(
        matches!(&c.suspicions[..], [s] if s.contains("reversed-Z true (declared false")),
        "{c:?}"
    );
    // Sizes must match.
    let small = Side::new(
        RgbImage::new(1, 1, vec![0; 3]).unwrap(),
        None,
        DepthEncoding::ViewZ,
        Conventions::default(),
    );
    assert!(compare(&a, &small).is_err());
}

/// A 4x1 top-down side: grey 100, pixel 3 at `last`, view Z 2 m with pixel 2 at `z2`.
fn strip(last: u8, z2: f32) -> Side {
    let mut color = vec![100u8; 12];
    color[9..12].fill(last);
    Side::new(
        RgbImage::new(4, 1, color).unwrap(),
        Some(DepthMap::new(4, 1, vec![2.0, 2.0, z2, 2.0]).unwrap()),
        DepthEncoding::ViewZ,
        Conventions {
            row_order: RowOrder::TopDown,
            ..Conventions::default()
        },
    )
}

#[test]
fn a_mask_restricts_every_measure_and_the_diff_image() {
    use viewsynth::compare::compare_masked;
    use viewsynth::io::Mask;
    let (a, b) = (strip(100, 2.0), strip(110, 2.2));
    // Whole image: 3 of 12 samples differ by 10 -> MSE 25, RMSE 5.
    let (c, diff) = compare(&a, &b).unwrap();
    assert_eq!((c.pixels, c.max_color_diff, c.color_rmse), (4, 10.0, 5.0));
    assert!((c.psnr_db - 10.0 * (255.0f64 * 255.0 / 25.0).log10()).abs() < 1e-12);
    assert!((c.depth_max_rel.unwrap() - 0.1).abs() < 1e-6, "{c:?}");
    // The largest difference is white, not 10 x 8 = 80 (or saturated at 255 for differences >= 32).
    assert_eq!(c.diff_scale, 25.5);
    assert_eq!(diff.data, [0, 0, 0, 0, 0, 0, 0, 0, 0, 255, 255, 255]);
    // Pixels 0 and 1 only: identical colour and depth.
    let mask = Mask::new(4, 1, vec![1, 1, 0, 0]).unwrap();
    let (m, diff) = compare_masked(&a, &b, Some(&mask)).unwrap();
    assert_eq!(
        (m.pixels, m.max_color_diff, m.color_rmse, m.depth_max_rel),
        (2, 0.0, 0.0, Some(0.0))
    );
    assert_eq!(m.psnr_db, f64::INFINITY);
    assert!(diff.data.iter().all(|v| *v == 0));
    let json = serde_json::to_value(&m).unwrap();
    assert_eq!(json["psnr_db"], "inf");
    // A mask of another size, or one selecting nothing, is refused.
    assert!(compare_masked(&a, &b, Some(&Mask::new(2, 2, vec![1; 4]).unwrap())).is_err());
    let none = compare_masked(&a, &b, Some(&Mask::new(4, 1, vec![0; 4]).unwrap())).unwrap_err();
    assert!(none.to_string().contains("mask"), "{none}");
}

#[test]
fn thresholds_name_each_limit_broken() {
    use viewsynth::compare::Thresholds;
    let (c, _) = compare(&strip(100, 2.0), &strip(110, 2.2)).unwrap();
    let all = Thresholds {
        max_color_rmse: Some(4.0),
        min_psnr_db: Some(40.0),
        max_depth_rel: Some(0.05),
        ..Default::default()
    };
    let broken = all.broken(&c);
    assert_eq!(broken.len(), 3, "{broken:?}");
    assert!(
        broken[0].contains("colour RMSE 5.0000 > 4") && broken[1].contains("< 40 dB"),
        "{broken:?}"
    );
    let loose = Thresholds {
        max_color_rmse: Some(5.0),
        min_psnr_db: Some(30.0),
        max_depth_rel: Some(0.11),
        ..Default::default()
    };
    assert!(loose.broken(&c).is_empty(), "{:?}", loose.broken(&c));
    let mut no_depth = strip(100, 2.0);
    no_depth.depth = None;
    let (c, _) = compare(&no_depth, &no_depth).unwrap();
    assert!(loose.broken(&c)[0].contains("no depth was compared"));
    assert!(Thresholds {
        max_color_rmse: Some(-1.0),
        ..Default::default()
    }
    .validate()
    .is_err());
}

#[test]
fn suspicion_names_row_orders_as_the_cli_spells_them() {
    let a = stored(Conventions::default());
    let mut b = stored(Conventions {
        row_order: RowOrder::TopDown,
        ..Conventions::default()
    });
    b.conv.row_order = RowOrder::BottomUp;
    let (c, _) = compare(&a, &b).unwrap();
    let s = &c.suspicions[0];
    assert!(
        s.contains("read as top-down") && s.contains("declared bottom-up") && s.contains("--b-rows top-down"),
        "{s}"
    );
}

/// The colour check's other readings: premultiplied alpha taken for straight, and sRGB values
/// declared linear (the reverse of the linear-for-sRGB mistake), each named with its option;
/// declared right, nothing is named.
#[test]
fn premultiplied_alpha_and_srgb_declared_linear_are_named() {
    use viewsynth::compare::{Alpha, Transfer};
    use viewsynth::io::ColourImage;
    let (w, h) = (32u32, 24u32);
    let rgb: Vec<f32> = (0..w * h)
        .flat_map(|i| {
            [
                (40 + (i % w) * 6) as f32 / 255.0,
                0.6,
                (30 + (i / w) * 8) as f32 / 255.0,
            ]
        })
        .collect();
    let alpha: Vec<f32> = (0..w * h).map(|i| 0.3 + 0.7 * (i % 7) as f32 / 6.0).collect();
    let side = |rgb: Vec<f32>, alpha: Option<Vec<f32>>| {
        let color = ColourImage {
            width: w,
            height: h,
            rgb,
            alpha,
            bits: 32,
        };
        let conv = Conventions {
            row_order: RowOrder::TopDown,
            ..Conventions::default()
        };
        Side::new(color, None, DepthEncoding::ViewZ, conv)
    };
    let a = side(rgb.clone(), None);
    let premultiplied: Vec<f32> = rgb
        .chunks_exact(3)
        .zip(&alpha)
        .flat_map(|(p, a)| p.iter().map(move |v| v * a))
        .collect();
    let mut b = side(premultiplied, Some(alpha));
    let (c, _) = compare(&a, &b).unwrap();
    assert!(
        matches!(&c.suspicions[..], [s] if s.contains("premultiplied alpha") && s.contains("(--b-alpha premultiplied)")),
        "{:?}",
        c.suspicions
    );
    b.colour.alpha = Alpha::Premultiplied;
    let (c, _) = compare(&a, &b).unwrap();
    assert!(c.suspicions.is_empty() && c.max_color_diff < 1e-3, "{c:?}");
    // sRGB values declared linear: encoded once more than A.
    let mut b = side(rgb, None);
    b.colour.transfer = Transfer::Linear;
    let (c, _) = compare(&a, &b).unwrap();
    assert!(
        matches!(&c.suspicions[..], [s] if s.contains("sRGB values where linear is expected") && s.contains("(--b-transfer srgb)")),
        "{:?}",
        c.suspicions
    );
}
