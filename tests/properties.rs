//! Property tests (proptest) for the image operations the passes and files rest on: row order,
//! NDC depth round trips under every convention, depth encodings, and each loader against its
//! writer. No GPU. Bounds are derived beside each property.

use proptest::prelude::*;
use viewsynth::convention::{Conventions, DepthPlanes, RowOrder};
use viewsynth::io::{self, DepthDecode, DepthMap, Mask, PngCompression, RgbImage};

fn config() -> ProptestConfig {
    // Each case writes and reads a small file: 64 cases per property keep the whole file
    // around a second while covering sizes 1..=33 per side.
    ProptestConfig {
        cases: 64,
        ..ProptestConfig::default()
    }
}

fn scratch() -> tempfile::TempDir {
    tempfile::Builder::new().prefix("viewsynth-prop-").tempdir().unwrap()
}

/// A size and `per_pixel` bytes per pixel of it.
fn image_bytes(per_pixel: usize) -> impl Strategy<Value = (u32, u32, Vec<u8>)> {
    (1u32..=33, 1u32..=33).prop_flat_map(move |(w, h)| {
        proptest::collection::vec(any::<u8>(), (w * h) as usize * per_pixel).prop_map(move |v| (w, h, v))
    })
}

/// Depth values: mostly metric 1 mm .. 60 m, some holes (0, negative, NaN, inf).
fn depth_value() -> impl Strategy<Value = f32> {
    prop_oneof![
        8 => 0.001f32..60.0,
        1 => Just(0.0f32),
        1 => prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(-1.0f32), Just(f32::NEG_INFINITY)],
    ]
}

fn depth_map() -> impl Strategy<Value = DepthMap> {
    (1u32..=33, 1u32..=33).prop_flat_map(|(w, h)| {
        proptest::collection::vec(depth_value(), (w * h) as usize).prop_map(move |d| DepthMap::new(w, h, d).unwrap())
    })
}

fn same_f32(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

proptest! {
    #![proptest_config(config())]

    /// Bottom-up memory rows are the image rows reversed (row y of the image is memory row
    /// h - 1 - y), top-down is the identity, and either conversion undone by itself.
    #[test]
    fn row_order_is_a_flip_or_nothing_and_its_own_inverse((w, h, data) in image_bytes(3)) {
        let row = w as usize * 3;
        let flipped = RowOrder::BottomUp.convert_rows(data.clone(), row);
        for y in 0..h as usize {
            let m = h as usize - 1 - y;
            prop_assert_eq!(&flipped[m * row..(m + 1) * row], &data[y * row..(y + 1) * row]);
        }
        prop_assert_eq!(RowOrder::BottomUp.convert_rows(flipped, row), data.clone());
        prop_assert_eq!(RowOrder::TopDown.convert_rows(data.clone(), row), data);
    }

    /// NDC z of a view distance and back, under each of the 8 conventions. z_ndc = a + b / Z
    /// and Z = b / (z_ndc - a): the forward rounding is ~eps x (|a| + |b| / Z) and dividing by
    /// |z_ndc - a| = |b| / Z amplifies it by 1 + |a| Z / |b| <= 1 + far / near (|a| / |b| <=
    /// 1 / near in every convention's coefficients), so |Z' - Z| / Z <= 8 eps (1 + far /
    /// near) with room for the 3 or 4 roundings on each side. Near maps to the convention's
    /// near NDC value, far to its far value, and the map is strictly monotone.
    #[test]
    fn ndc_depth_round_trips_under_every_convention(
        near in 1e-3f64..10.0,
        ratio in 1.01f64..1e5,
        t in 0.0f64..=1.0,
        t2 in 0.0f64..=1.0,
    ) {
        let far = near * ratio;
        let planes = DepthPlanes { near, far };
        let z = near + t * (far - near);
        let z2 = near + t2 * (far - near);
        for conv in Conventions::all() {
            let (zn, zf) = conv.ndc_z_near_far();
            let ndc = planes.ndc_z_of_view_z(&conv, z);
            let back = planes.view_z_of_ndc_z(&conv, ndc);
            let bound = 8.0 * f64::EPSILON * (1.0 + ratio);
            prop_assert!(((back - z) / z).abs() <= bound, "{}: {z} -> {ndc} -> {back}", conv.label());
            // a + b / Z rounds to within a few ulps of its larger term.
            let (a, b) = planes.clip_z_coefficients(&conv);
            for (plane, want) in [(near, zn), (far, zf)] {
                let err = (planes.ndc_z_of_view_z(&conv, plane) - want).abs();
                prop_assert!(err <= 4.0 * f64::EPSILON * (a.abs() + (b / plane).abs()), "{}: {plane} -> {want}", conv.label());
            }
            if z2 != z {
                let (a, b) = (planes.ndc_z_of_view_z(&conv, z), planes.ndc_z_of_view_z(&conv, z2));
                // Nearer is towards zn: the order of Z and of (ndc - zf) / (zn - zf) disagree.
                let s = (zn - zf).signum();
                prop_assert!(((a - b) * s) * (z - z2) <= 0.0, "{}: not monotone", conv.label());
            }
        }
    }

    /// The colour PNG writer and loader: the same pixels and size, byte for byte.
    #[test]
    fn rgb_png_loads_what_was_saved((w, h, data) in image_bytes(3)) {
        let d = scratch();
        let p = d.path().join("c.png");
        io::save_rgb(&p, &RgbImage::new(w, h, data.clone()).unwrap()).unwrap();
        let back = io::load_rgb(&p).unwrap();
        prop_assert_eq!((back.width, back.height), (w, h));
        prop_assert_eq!(back.data, data);
    }

    /// The mask PNG writer and loader, at every compression: 0 stays 0, any other byte is
    /// valid (1 in memory; 255 on disk, or 128 for MASK_FILLED, the filled pixels of
    /// cyclopean --fill).
    #[test]
    fn mask_png_loads_what_was_saved((w, h, data) in image_bytes(1), best in any::<bool>()) {
        let d = scratch();
        let p = d.path().join("m.png");
        let c = if best { PngCompression::Best } else { PngCompression::Fast };
        io::save_mask_png_with(&p, &Mask { width: w, height: h, data: data.clone() }, c).unwrap();
        let back = io::load_mask_png(&p).unwrap();
        prop_assert_eq!((back.width, back.height), (w, h));
        let want: Vec<u8> = data.iter().map(|v| u8::from(*v != 0)).collect();
        prop_assert_eq!(back.data, want);
        let disk = image::open(&p).unwrap().into_luma8();
        let on_disk: Vec<u8> = data
            .iter()
            .map(|v| match *v {
                0 => 0,
                io::MASK_FILLED => io::MASK_FILLED,
                _ => 255,
            })
            .collect();
        prop_assert_eq!(disk.as_raw(), &on_disk);
    }

    /// NPY (float32) and EXR (float32 channel, lossless compression) give every value back bit
    /// for bit, holes included (NaN as NaN).
    #[test]
    fn float_depth_files_load_bit_for_bit(depth in depth_map()) {
        let d = scratch();
        for name in ["z.npy", "z.exr"] {
            let p = d.path().join(name);
            if name.ends_with("npy") {
                io::save_depth_npy(&p, &depth).unwrap();
            } else {
                io::save_depth_exr(&p, &depth).unwrap();
            }
            let back = io::load_depth(&p, &DepthDecode::default()).unwrap();
            prop_assert_eq!((back.width, back.height), (depth.width, depth.height), "{}", name);
            for (i, (a, b)) in depth.data.iter().zip(&back.data).enumerate() {
                prop_assert!(same_f32(*a, *b), "{}: pixel {} {} -> {}", name, i, a, b);
            }
        }
        // The generic NPY writer and reader: shape and values (widened to f64 exactly).
        let p = d.path().join("a.npy");
        io::save_npy_f32(&p, &[depth.height as usize, depth.width as usize], &depth.data).unwrap();
        let arr = io::load_npy(&p).unwrap();
        prop_assert_eq!(arr.shape, vec![depth.height as usize, depth.width as usize]);
        for (a, b) in depth.data.iter().zip(&arr.data) {
            prop_assert!(same_f32(*a, *b as f32) && (a.is_nan() || f64::from(*a) == *b));
        }
    }

    /// 16-bit PNG in millimetres read back with scale 1000: a valid Z becomes round(1000 Z)
    /// mm, so within half a millimetre (plus f32 rounding of the metres, <= 2^-24 x 65.5 m =
    /// 4e-6 m), or 0 (invalid) where it rounds to 0 mm or above 65535 mm, which the writer
    /// counts; every hole is 0.
    #[test]
    fn png16_depth_is_millimetres_rounded(depth in depth_map(), far in any::<bool>()) {
        let mut depth = depth;
        if far {
            // Some values beyond the format's 65.535 m.
            for z in depth.data.iter_mut().step_by(3) {
                if z.is_finite() && *z > 0.0 {
                    *z += 70.0;
                }
            }
        }
        let d = scratch();
        let p = d.path().join("z.png");
        let clipped = io::save_depth_png16(&p, &depth, io::Png16Units::default(), PngCompression::Fast).unwrap();
        let back = io::load_depth(&p, &DepthDecode { scale: Some(io::PNG16_UNITS_PER_METRE), ..Default::default() }).unwrap();
        prop_assert_eq!((back.width, back.height), (depth.width, depth.height));
        let mut over = 0u64;
        for (z, b) in depth.data.iter().zip(&back.data) {
            let valid = z.is_finite() && *z > 0.0;
            let mm = (f64::from(*z) * 1000.0).round();
            if !valid || mm < 1.0 {
                prop_assert_eq!(*b, 0.0, "hole or below 0.5 mm: {}", z);
            } else if mm > 65535.0 {
                over += 1;
                prop_assert_eq!(*b, 0.0, "beyond 65.535 m: {}", z);
            } else {
                prop_assert!((f64::from(*b) - f64::from(*z)).abs() <= 0.0005 + 4e-6, "{} -> {}", z, b);
                prop_assert_eq!((f64::from(*b) * 1000.0).round(), mm);
            }
        }
        prop_assert_eq!(clipped, over);
    }
}
