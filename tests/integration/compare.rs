//! `compare`: the same frame written under every convention compares equal after conversion;
//! flipped rows, NDC z stored as window depth, and a reversed-Z mismatch are detected and named.

use viewsynth::camera::Pose;
use viewsynth::compare::{compare, DepthStorage, Side};
use viewsynth::convention::{Conventions, DepthPlanes, RowOrder};
use viewsynth::io::{DepthMap, RgbImage};

const PLANES: DepthPlanes = DepthPlanes { near: 0.05, far: 50.0 };

/// One rendering of the scene, stored as a renderer under `conv` would store it: rows in
/// `conv.row_order`, window depth under `conv` (the far value where nothing was hit).
fn stored(conv: Conventions) -> Side {
    let cam = viewsynth::scene::demo_camera(96, 72);
    let (color, z) = viewsynth::scene::render_scene(&viewsynth::scene::builtin("demo").unwrap(), &cam, &Pose::IDENTITY);
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
    Side {
        color: RgbImage::new(96, 72, conv.row_order.convert_rows(color.data, 96 * 3)).unwrap(),
        depth: Some(DepthMap::new(96, 72, depth).unwrap()),
        storage: DepthStorage::Device(PLANES),
        conv,
    }
}

#[test]
fn every_convention_compares_equal_to_every_other_after_conversion() {
    // Depth is stored as f32 window depth: back to view Z within its resolution (standard Z,
    // near 0.05 m, scene up to 6 m: ~1e-5 relative). Colour is the same rendering: identical.
    let a = stored(Conventions::default());
    for conv in Conventions::all() {
        let (c, _) = compare(&a, &stored(conv)).unwrap();
        assert_eq!(c.max_color_diff, 0, "{}: {c:?}", conv.label());
        assert_eq!(c.mask_disagreement, Some(0), "{}", conv.label());
        assert!(c.depth_max_rel.unwrap() < 2e-5, "{}: {c:?}", conv.label());
        assert!(c.suspicion.is_none(), "{}: {c:?}", conv.label());
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
    assert!(c.suspicion.as_deref().is_some_and(|s| s.contains("flipped")), "{c:?}");
    // GL NDC z in [-1, 1] stored where window depth is declared.
    let mut b = stored(Conventions::default());
    for v in b.depth.as_mut().unwrap().data.iter_mut() {
        *v = 2.0 * *v - 1.0;
    }
    let (c, _) = compare(&a, &b).unwrap();
    assert!(c.suspicion.as_deref().is_some_and(|s| s.contains("NDC z")), "{c:?}");
    // Written with reversed-Z, declared standard.
    let mut b = stored(Conventions {
        reversed_z: true,
        ..Conventions::default()
    });
    b.conv.reversed_z = false;
    let (c, _) = compare(&a, &b).unwrap();
    assert!(
        c.suspicion
            .as_deref()
            .is_some_and(|s| s.contains("reversed-Z true (declared false)")),
        "{c:?}"
    );
    // Sizes must match.
    let small = Side {
        color: RgbImage::new(1, 1, vec![0; 3]).unwrap(),
        depth: None,
        storage: DepthStorage::ViewZ,
        conv: Conventions::default(),
    };
    assert!(compare(&a, &small).is_err());
}
