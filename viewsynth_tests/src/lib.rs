//! What the library's tests share (and the command line's tests, through a dev-dependency):
//! the GL and Vulkan contexts (a missing EGL or Vulkan driver fails, never skips), the test data
//! folder, the real RGB-D frames and a synthetic one, GPU-against-twin agreement, the cyclopean
//! methods every backend test runs, and the files `viewsynth cyclopean` reads.

pub mod real_pairs;

use std::path::PathBuf;
use viewsynth::camera::{Intrinsics, PinholeCamera};
use viewsynth::gpu::{DeviceChoice, Gpu};
use viewsynth::io::{self, DepthDecode};
use viewsynth::metrics::{self, Agreement};
use viewsynth::refocus::reference::{refocus_reference, ReferenceImage};
use viewsynth::refocus::{BreakRule, RefocusOutput, RefocusSource};
use viewsynth::stereo::gather::Blend;
use viewsynth::stereo::gather::CyclopeanParams;
use viewsynth::stereo::gather::Method;
use viewsynth::stereo::Eye;
use viewsynth::view::ViewOutput;

pub fn gpu() -> Gpu {
    Gpu::new(DeviceChoice::Auto).unwrap_or_else(|e| {
        panic!("GPU tests need EGL + OpenGL 4.5 core (run ci/install-deps.sh for Mesa llvmpipe): {e}")
    })
}

/// `../shared/data` next to the repository, or $VIEWSYNTH_DATA_DIR.
pub fn data_dir() -> PathBuf {
    let dir = std::env::var_os("VIEWSYNTH_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data")));
    assert!(
        dir.is_dir(),
        "test data missing: {} (fetch it with `python3 ci/fetch-data.py`, or set VIEWSYNTH_DATA_DIR)",
        dir.display()
    );
    dir
}

/// The real RGB-D frames of ../shared/data with the intrinsics its README gives.
pub fn real_frame(name: &str) -> RefocusSource {
    let d = data_dir().join("rgbd_open3d_testdata");
    let (color, depth, decode, k) = match name {
        "TUM" => (
            "TUM_color.png",
            "TUM_depth.png",
            DepthDecode {
                scale: Some(5000.0),
                ..Default::default()
            },
            Intrinsics {
                fx: 525.0,
                fy: 525.0,
                cx: 319.5,
                cy: 239.5,
            },
        ),
        "SUN" => (
            "SUN_color.jpg",
            "SUN_depth.png",
            DepthDecode {
                scale: Some(1000.0),
                sun_rgbd_bit_rotate: true,
                ..Default::default()
            },
            Intrinsics {
                fx: 570.0,
                fy: 570.0,
                cx: 320.0,
                cy: 240.0,
            },
        ),
        "NYU" => (
            "NYU_color.ppm",
            "NYU_depth.pgm",
            // Raw Kinect values, little-endian despite the PGM header; converted below.
            DepthDecode {
                scale: Some(1.0),
                swap_bytes: true,
                ..Default::default()
            },
            Intrinsics {
                fx: 518.9,
                fy: 519.5,
                cx: 325.6,
                cy: 253.7,
            },
        ),
        _ => panic!("unknown frame {name}"),
    };
    let rgb = io::load_rgb(&d.join(color)).expect("colour loads");
    let mut depth = io::load_depth(&d.join(depth), &decode).expect("depth loads");
    if name == "NYU" {
        // The data README: raw 2047 = invalid, metres = 351.3 / (1092.5 - raw).
        for z in depth.data.iter_mut() {
            *z = if *z >= 2047.0 || *z <= 0.0 {
                0.0
            } else {
                (351.3 / (1092.5 - *z as f64)) as f32
            };
        }
    }
    RefocusSource::new(rgb, depth, k).expect("valid frame")
}

pub fn synthetic(width: u32, height: u32) -> RefocusSource {
    let cam = viewsynth::world::demo_camera(width, height);
    let (rgb, depth) = viewsynth::world::render(&cam);
    RefocusSource::new(rgb, depth, cam.k).unwrap()
}

pub fn mask_bools(out: &RefocusOutput) -> Vec<bool> {
    out.mask
        .as_ref()
        .expect("mask requested")
        .data
        .iter()
        .map(|v| *v != 0)
        .collect()
}

pub fn compare(out: &RefocusOutput, reference: &ReferenceImage) -> Agreement {
    metrics::agreement(
        out.rgb.as_ref().map(|i| i.data.as_slice()),
        out.depth.as_ref().map(|d| d.data.as_slice()),
        &mask_bools(out),
        &reference.rgb,
        &reference.depth,
        &reference.mask,
    )
}

/// A GPU view against its f64 twin's view: the twin's unrounded values, so a rounding tie may
/// go either way ([`metrics::agreement`]).
pub fn compare_views(out: &ViewOutput, reference: &ViewOutput) -> Agreement {
    let exact = reference.exact.as_ref().expect("an f64 twin's view");
    metrics::agreement(
        out.color.as_ref().map(|i| i.data.as_slice()),
        out.depth.as_ref().map(|d| d.data.as_slice()),
        &out.valid().expect("mask requested"),
        &exact.color,
        exact.depth.as_deref().expect("twin depth"),
        &reference.valid().expect("twin mask"),
    )
}

pub fn reference(src: &RefocusSource, target: &PinholeCamera) -> ReferenceImage {
    refocus_reference(src, &BreakRule::default(), target)
}

/// Writes `frame` for `viewsynth cyclopean` into `dir`: each eye's colour (`left.png`,
/// `right.png`) and depth (`left.exr`, `right.exr`), and `cams.json` with the eyes' matrices,
/// conventions and depth kind, the middle camera `mid` and a 3 m fixation. Returns that JSON
/// (tests write variants of it).
pub fn write_cyclopean_files(
    dir: &std::path::Path,
    frame: &viewsynth::stereo::StereoFrame,
    mid: &viewsynth::stereo::MiddleCamera,
) -> serde_json::Value {
    for (name, eye) in [("left", &frame.left), ("right", &frame.right)] {
        io::save_rgb(&dir.join(format!("{name}.png")), &eye.color).unwrap();
        io::save_depth_exr(&dir.join(format!("{name}.exr")), &eye.depth).unwrap();
    }
    let cams = serde_json::json!({
        "conventions": frame.conv,
        "depth_kind": frame.depth_kind,
        "left": { "view": frame.left.view, "proj": frame.left.proj },
        "right": { "view": frame.right.view, "proj": frame.right.proj },
        "middle": { "proj": mid.proj, "width": mid.width, "height": mid.height, "view": mid.view },
        "fixation_distance": 3.0
    });
    std::fs::write(dir.join("cams.json"), serde_json::to_string(&cams).unwrap()).unwrap();
    cams
}

/// Largest |a - b| over two maps of one length (0 for none).
pub fn max_abs_difference(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max)
}

/// The gather methods every GL and Vulkan cyclopean comparison sweeps.
pub fn methods() -> Vec<(&'static str, CyclopeanParams)> {
    let seed = CyclopeanParams::seed(3.0);
    vec![
        ("seed", seed),
        (
            "refine3",
            CyclopeanParams {
                method: Method::Refine { steps: 3 },
                ..seed
            },
        ),
        (
            "refine4-soft-dominant",
            CyclopeanParams {
                method: Method::Refine { steps: 4 },
                blend: Blend::Soft,
                dominant: Some((Eye::Right, 0.7)),
                ..seed
            },
        ),
    ]
}

/// The Vulkan executor's context (Mesa lavapipe in CI).
#[cfg(feature = "vulkan")]
pub fn vulkan() -> viewsynth::vulkan::Vk {
    viewsynth::vulkan::VulkanContext::open(
        viewsynth::vulkan::VulkanDeviceChoice::Auto,
        viewsynth::pass::GpuPolicy::default(),
    )
    .unwrap_or_else(|e| {
        panic!("Vulkan tests need the loader and a driver (ci/install-deps.sh installs Mesa lavapipe): {e}")
    })
}

/// Bound on |confidence_gpu - confidence_twin|, from the numerics: the GPU's decisions (which
/// pixel is read, whether the eyes agree within 1 px) are f32 operations the twin repeats in f32,
/// so the same pixels are 0. The value `(1 - |d - e|) / (1 + variance)` over at most 9 known
/// disparities below 2^7 px: the f32 mean is off by at most ~9 x 2^7 x 2^-24 < 7e-5 px (plus
/// GLSL's 2.5 ulp division), so each squared deviation by 2 |v - m| 7e-5 and the variance by
/// about 1.4e-4 sqrt(variance) plus its own rounding (a few 2^-24 relative); divided by
/// (1 + variance)^2 that moves the confidence by at most 1.4e-4 x max sqrt(v) / (1 + v)^2
/// (0.33 at v = 1/3) < 5e-5, and the agreement's f32 difference by 2^-24. So 1e-4.
pub const CONFIDENCE_BOUND: f32 = 1e-4;

/// Runs `command` under VK_LAYER_KHRONOS_validation (Debian package `vulkan-validationlayers`)
/// and returns its stdout and stderr. It must succeed with no validation message, and the
/// loader's own log must show the layer inserted, so a missing layer cannot pass silently.
pub fn run_clean_under_validation_layer(what: &str, command: &mut std::process::Command) -> String {
    let o = command
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_KHRONOS_validation")
        .env("VK_LOADER_DEBUG", "layer")
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "{what}: {text}");
    assert!(
        text.contains("Insert instance layer \"VK_LAYER_KHRONOS_validation\""),
        "{what}: the validation layer was not loaded (install vulkan-validationlayers):\n{text}"
    );
    for bad in ["Validation Error", "VUID-", "Validation Warning"] {
        assert!(!text.contains(bad), "{what}: {bad}:\n{text}");
    }
    text
}

/// Fails naming every failed case of a table of `cases`.
pub fn assert_no_failures(failures: Vec<String>, cases: usize) {
    assert!(
        failures.is_empty(),
        "{} of {cases} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
