//! Loads the real RGB-D frames in `../shared/data` (see its README, section 4).

use super::{load_depth, load_rgb, DepthDecode, DepthMap};

fn data(rel: &str) -> std::path::PathBuf {
    crate::test_data::dir().join(rel)
}

/// (fraction of pixels equal to `invalid`, min and max of the others).
fn stats(d: &DepthMap, invalid: f32) -> (f64, f32, f32) {
    let valid: Vec<f32> = d.data.iter().copied().filter(|&v| v != invalid).collect();
    let min = valid.iter().copied().fold(f32::INFINITY, f32::min);
    let max = valid.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    (1.0 - valid.len() as f64 / d.data.len() as f64, min, max)
}

fn near(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn tum_depth_png_scale_5000() {
    let decode = DepthDecode {
        scale: Some(5000.0),
        ..Default::default()
    };
    let d = load_depth(&data("rgbd_open3d_testdata/TUM_depth.png"), &decode).unwrap();
    assert_eq!((d.width, d.height), (640, 480));
    let (zeros, min, max) = stats(&d, 0.0);
    assert!(near(zeros, 0.19, 0.01), "zeros {zeros}");
    assert!(
        near(min.into(), 1.46, 0.01) && near(max.into(), 9.33, 0.01),
        "{min}..{max}"
    );
}

#[test]
fn sun_depth_png_bit_rotate_1000() {
    let decode = DepthDecode {
        scale: Some(1000.0),
        sun_rgbd_bit_rotate: true,
        ..Default::default()
    };
    let d = load_depth(&data("rgbd_open3d_testdata/SUN_depth.png"), &decode).unwrap();
    assert_eq!((d.width, d.height), (640, 480));
    let (zeros, min, max) = stats(&d, 0.0);
    assert!(near(zeros, 0.18, 0.01), "zeros {zeros}");
    assert!(
        near(min.into(), 1.06, 0.01) && near(max.into(), 9.87, 0.01),
        "{min}..{max}"
    );
}

/// NYU's raw PGM holds little-endian samples despite the Netpbm big-endian rule, and they
/// are Kinect disparity units, not a linear depth: metres = 351.3 / (1092.5 - raw),
/// 2047 = invalid. Loading with scale 1 yields the raw units.
#[test]
fn nyu_raw_pgm_needs_byte_swap() {
    let path = data("rgbd_open3d_testdata/NYU_depth.pgm");
    let raw = DepthDecode {
        scale: Some(1.0),
        swap_bytes: true,
        ..Default::default()
    };
    let d = load_depth(&path, &raw).unwrap();
    assert_eq!((d.width, d.height), (640, 480));
    let (invalid, min, max) = stats(&d, 2047.0);
    assert!(near(invalid, 0.07, 0.01), "invalid {invalid}");
    assert_eq!((min, max), (839.0, 1040.0));
    let metres = |r: f32| 351.3 / (1092.5 - f64::from(r));
    assert!(near(metres(min), 1.39, 0.01) && near(metres(max), 6.69, 0.01));

    // Decoded per the spec (no swap), the same file is nonsense: 2047 reads as 0xFF07.
    let spec = load_depth(
        &path,
        &DepthDecode {
            scale: Some(1.0),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(spec.get(0, 0), Some(f32::from(2047u16.swap_bytes())));
}

#[test]
fn middlebury_8_bit_disparity_pgm_with_scale() {
    let decode = DepthDecode {
        scale: Some(4.0),
        ..Default::default()
    };
    let d = load_depth(&data("middlebury2003_cones/disp2.pgm"), &decode).unwrap();
    assert_eq!((d.width, d.height), (450, 375));
    let (_, _, max) = stats(&d, 0.0);
    assert_eq!(max, 55.0);
}

#[test]
fn colour_frames_load() {
    for name in ["TUM_color.png", "SUN_color.jpg", "NYU_color.ppm"] {
        let img = load_rgb(&data(&format!("rgbd_open3d_testdata/{name}"))).unwrap();
        assert_eq!(
            (img.width, img.height, img.data.len()),
            (640, 480, 640 * 480 * 3),
            "{name}"
        );
    }
}
