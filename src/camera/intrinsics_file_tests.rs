//! One test per format on a written file, plus the Middlebury 2014 Motorcycle calibration
//! against the downsampled pair in ../shared/data.

use super::*;
use std::path::PathBuf;

fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("viewsynth-intrinsics-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn k(fx: f64, fy: f64, cx: f64, cy: f64) -> Intrinsics {
    Intrinsics { fx, fy, cx, cy }
}

#[test]
fn k_json_nested_flat_and_keyed() {
    let nested =
        IntrinsicsFile::load(&write("k_nested.json", "[[525, 0, 319.5], [0, 520, 239.5], [0, 0, 1]]")).unwrap();
    assert_eq!(nested.k, k(525.0, 520.0, 319.5, 239.5));
    assert_eq!((nested.format, nested.size), (IntrinsicsFormat::KMatrixJson, None));
    let flat = IntrinsicsFile::load(&write("k_flat.json", "[525,0,319.5,0,520,239.5,0,0,1]")).unwrap();
    assert_eq!(flat.k, nested.k);
    let keyed = IntrinsicsFile::load(&write(
        "k_keyed.json",
        r#"{"K": [[600, 0, 300], [0, 601, 200], [0, 0, 1]], "width": 640, "height": 400}"#,
    ))
    .unwrap();
    assert_eq!(keyed.k, k(600.0, 601.0, 300.0, 200.0));
    assert_eq!(keyed.size, Some((640, 400)));
}

#[test]
fn k_text_with_comments_and_brackets() {
    let f = IntrinsicsFile::load(&write(
        "K.txt",
        "# camera matrix\n[[517.3 0 318.6]\n [0 516.5 255.3]\n [0 0 1]]\n",
    ))
    .unwrap();
    assert_eq!(f.k, k(517.3, 516.5, 318.6, 255.3));
    assert_eq!(f.format, IntrinsicsFormat::KMatrixText);
}

#[test]
fn open3d_intrinsic_matrix_is_column_major() {
    // As Open3D's io.write_pinhole_camera_intrinsic writes it (PrimeSenseDefault, fx != fy to
    // tell the order apart).
    let text = r#"{
	"height" : 480,
	"intrinsic_matrix" : [ 525.0, 0.0, 0.0, 0.0, 521.0, 0.0, 319.5, 239.5, 1.0 ],
	"width" : 640
}"#;
    let f = IntrinsicsFile::load(&write("open3d.json", text)).unwrap();
    assert_eq!(f.k, k(525.0, 521.0, 319.5, 239.5));
    assert_eq!((f.format, f.size), (IntrinsicsFormat::Open3d, Some((640, 480))));
}

#[test]
fn middlebury_motorcycle_calib_matches_the_downsampled_pair() {
    // The published calib.txt of Middlebury 2014 Motorcycle (full resolution). ../shared/data
    // holds the pair downsampled 4x (scikit-image) without its calib.txt; its README gives the
    // downsampled values f = 994.978, cx = 311.193, cy = 254.877, doffs = 31.086,
    // baseline = 193.001 mm.
    let text = "cam0=[3979.911 0 1244.772; 0 3979.911 1019.507; 0 0 1]\n\
                cam1=[3979.911 0 1369.115; 0 3979.911 1019.507; 0 0 1]\n\
                doffs=124.343\nbaseline=193.001\nwidth=2964\nheight=2000\nndisp=270\n\
                isint=0\nvmin=23\nvmax=245\ndyavg=0\ndymax=0\n";
    let f = IntrinsicsFile::load(&write("calib.txt", text)).unwrap();
    assert_eq!(f.format, IntrinsicsFormat::MiddleburyCalib);
    assert_eq!(f.k, k(3979.911, 3979.911, 1244.772, 1019.507));
    let stereo = f.stereo.unwrap();
    assert_eq!((stereo.doffs, stereo.baseline_mm), (124.343, 193.001));
    let (w, h) = f.size.unwrap();
    let close = |a: f64, b: f64| (a - b).abs() < 1e-3;
    assert!(close(f.k.fx / 4.0, 994.978) && close(f.k.cx / 4.0, 311.193) && close(f.k.cy / 4.0, 254.877));
    assert!(close(stereo.doffs / 4.0, 31.086));
    let data = crate::test_data::dir().join("middlebury2014_motorcycle_skimage");
    let left = crate::io::load_rgb(&data.join("motorcycle_left.png")).unwrap();
    assert_eq!((w / 4, h / 4), (left.width, left.height));
    // The full-resolution file does not fit the downsampled image: refused, naming both sizes.
    let e = f
        .check_size(Path::new("calib.txt"), left.width, left.height)
        .unwrap_err()
        .to_string();
    assert!(e.contains("2964x2000") && e.contains("741x500"), "{e}");
}

#[test]
fn colmap_pinhole_and_simple_pinhole_shift_half_a_pixel() {
    let header = "# Camera list with one line of data per camera:\n\
                  #   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n# Number of cameras: 1\n";
    let f = IntrinsicsFile::load(&write(
        "cameras.txt",
        &format!("{header}1 PINHOLE 640 480 525 521 320 240\n"),
    ))
    .unwrap();
    assert_eq!(f.k, k(525.0, 521.0, 319.5, 239.5));
    assert_eq!((f.format, f.size), (IntrinsicsFormat::Colmap, Some((640, 480))));
    let s = IntrinsicsFile::load(&write(
        "cameras_simple.txt",
        &format!("{header}3 SIMPLE_PINHOLE 741 500 994.978 311.693 255.377\n"),
    ))
    .unwrap();
    assert_eq!(s.k.fx, s.k.fy);
    assert!((s.k.cx - 311.193).abs() < 1e-9 && (s.k.cy - 254.877).abs() < 1e-9);
}

#[test]
fn colmap_distortion_models_are_refused_by_name() {
    for (model, params) in [
        ("OPENCV", "500 500 320 240 0.1 0.01 0 0"),
        ("SIMPLE_RADIAL", "500 320 240 0.05"),
    ] {
        let p = write(
            &format!("cameras_{model}.txt"),
            &format!("1 {model} 640 480 {params}\n"),
        );
        let e = IntrinsicsFile::load(&p).unwrap_err().to_string();
        assert!(
            e.contains(model) && e.contains("undistort") && e.contains("cameras_"),
            "{e}"
        );
    }
    let two = write(
        "cameras_two.txt",
        "1 PINHOLE 640 480 1 1 1 1\n2 PINHOLE 640 480 2 2 2 2\n",
    );
    assert!(IntrinsicsFile::load(&two)
        .unwrap_err()
        .to_string()
        .contains("2 cameras"));
}

#[test]
fn malformed_files_name_the_problem() {
    let cases = [
        ("skew.json", "[[500, 3, 320], [0, 500, 240], [0, 0, 1]]", "skew"),
        ("last_row.txt", "500 0 320 0 500 240 0 0 2", "pinhole matrix"),
        ("eight.txt", "500 0 320 0 500 240 0 0", "found 8"),
        ("words.txt", "hello world", "not a recognised intrinsics file"),
        ("obj.json", r#"{"fx": 500}"#, "intrinsic_matrix"),
        ("bad.json", "{", "invalid JSON"),
        ("neg.txt", "-500 0 320 0 500 240 0 0 1", "must be in [1e-3, 1e6]"),
        // The flags' bounds hold for files too: huge and subnormal focal lengths, huge centres.
        (
            "huge_f.txt",
            "1e300 0 320 0 500 240 0 0 1",
            "fx: 1e300 must be in [1e-3, 1e6]",
        ),
        (
            "tiny_f.txt",
            "500 0 320 0 5e-324 240 0 0 1",
            "fy: 5e-324 must be in [1e-3, 1e6]",
        ),
        (
            "huge_c.txt",
            "500 0 1e7 0 500 240 0 0 1",
            "cx: 1e7: magnitude must be <= 1e6",
        ),
        (
            "half.json",
            r#"{"K": [1,0,0,0,1,0,0,0,1], "width": 640}"#,
            "both width and height",
        ),
        ("calib_bad.txt", "cam0=[1 0 2; 0 1]\n", "cam0"),
    ];
    for (name, text, want) in cases {
        let e = IntrinsicsFile::load(&write(name, text)).unwrap_err().to_string();
        assert!(e.contains(want) && e.contains(name), "{name}: {e}");
    }
    let missing = IntrinsicsFile::load(Path::new("/nonexistent/K.json"))
        .unwrap_err()
        .to_string();
    assert!(missing.contains("/nonexistent/K.json"), "{missing}");
}
