//! The GPU-vs-reference check the tests share: when a GPU output disagrees with its f64 twin
//! (by the test's own rule), both images and their difference are written as PNG into
//! `target/gpu-vs-reference/<case>/` and the panic message names that folder, so a person can
//! look at where they differ instead of reading counts.
//!
//! Files per compared plane `<label>`: `<label>_gpu.png`, `<label>_reference.png` and
//! `<label>_diff.png`. Colour is written as is; depth as grey over the valid range of both
//! images (black = invalid); masks scaled to 0/255. The difference is grey, scaled so the
//! largest difference is white, and red where exactly one side is valid (depth) or set (mask).

use std::fmt::Display;
use std::path::PathBuf;

use viewsynth::io::{save_rgb, RgbImage};
use viewsynth::view::ViewOutput;

/// One image plane of a comparison, rows top-down, `width * height` pixels.
#[derive(Debug, Clone, Copy)]
pub enum Plane<'a> {
    /// Interleaved 8-bit RGB.
    Rgb(&'a [u8]),
    /// One value per pixel; <= 0 or not finite is invalid (the crate's depth rule).
    Depth(&'a [f32]),
    /// One flag or small count per pixel (validity mask, source eye).
    Mask(&'a [u8]),
}

/// Where the images of case `name` go: `$CARGO_TARGET_DIR` (else `target`) /
/// `gpu-vs-reference` / `name` with anything but letters, digits, `-` and `_` made `_`.
pub fn failure_dir(name: &str) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| PathBuf::from("target"), PathBuf::from);
    let safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    target.join("gpu-vs-reference").join(safe)
}

/// Panics with `message` and the folder holding the images unless `ok`; writes the images of
/// every `(label, gpu, reference)` plane (each `width` x `height`) before panicking.
///
/// # Panics
/// When `ok` is false (that is its purpose), or when a plane does not have `width * height`
/// pixels.
pub fn ensure(ok: bool, name: &str, width: u32, height: u32, planes: &[(&str, Plane, Plane)], message: impl Display) {
    if ok {
        return;
    }
    let dir = failure_dir(name);
    match write_planes(&dir, width, height, planes) {
        Ok(()) => panic!("{message}\n  GPU, reference and difference images: {}", dir.display()),
        Err(e) => panic!("{message}\n  (could not write the images to {}: {e})", dir.display()),
    }
}

/// [`ensure`] over every plane present in both views (colour, depth, mask): the GPU output and
/// its f64 twin in their common shape.
///
/// # Panics
/// When `ok` is false, or when the views differ in size.
pub fn ensure_views(ok: bool, name: &str, gpu: &ViewOutput, reference: &ViewOutput, message: impl Display) {
    if ok {
        return;
    }
    assert_eq!(
        (gpu.width, gpu.height),
        (reference.width, reference.height),
        "{name}: GPU and reference views differ in size"
    );
    let mut planes = Vec::new();
    if let (Some(a), Some(b)) = (&gpu.color, &reference.color) {
        planes.push(("colour", Plane::Rgb(&a.data), Plane::Rgb(&b.data)));
    }
    if let (Some(a), Some(b)) = (&gpu.depth, &reference.depth) {
        planes.push(("depth", Plane::Depth(&a.data), Plane::Depth(&b.data)));
    }
    if let (Some(a), Some(b)) = (&gpu.mask, &reference.mask) {
        planes.push(("mask", Plane::Mask(&a.data), Plane::Mask(&b.data)));
    }
    ensure(ok, name, gpu.width, gpu.height, &planes, message);
}

fn write_planes(
    dir: &std::path::Path,
    width: u32,
    height: u32,
    planes: &[(&str, Plane, Plane)],
) -> viewsynth::Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| viewsynth::Error::io(dir, e))?;
    for (label, gpu, reference) in planes {
        let [g, r, d] = render(width, height, gpu, reference);
        for (suffix, img) in [("gpu", g), ("reference", r), ("diff", d)] {
            save_rgb(&dir.join(format!("{label}_{suffix}.png")), &img)?;
        }
    }
    Ok(())
}

fn valid_depth(v: f32) -> bool {
    v.is_finite() && v > 0.0
}

/// The GPU image, the reference image and their difference as 8-bit RGB.
fn render(width: u32, height: u32, gpu: &Plane, reference: &Plane) -> [RgbImage; 3] {
    let n = width as usize * height as usize;
    let rgb = |data: Vec<u8>| RgbImage::new(width, height, data).expect("plane of width x height pixels");
    let grey = |v: f64| [v.round().clamp(0.0, 255.0) as u8; 3];
    match (gpu, reference) {
        (Plane::Rgb(a), Plane::Rgb(b)) => {
            assert!(
                a.len() == n * 3 && b.len() == n * 3,
                "RGB plane is not {width}x{height}"
            );
            let diff: Vec<u8> = a.iter().zip(b.iter()).map(|(x, y)| x.abs_diff(*y)).collect();
            let max = diff.iter().copied().max().unwrap_or(0).max(1) as f64;
            let diff = diff
                .chunks_exact(3)
                .flat_map(|p| grey(f64::from(p[0].max(p[1]).max(p[2])) * 255.0 / max))
                .collect();
            [rgb(a.to_vec()), rgb(b.to_vec()), rgb(diff)]
        }
        (Plane::Depth(a), Plane::Depth(b)) => {
            assert!(a.len() == n && b.len() == n, "depth plane is not {width}x{height}");
            let (lo, hi) = a
                .iter()
                .chain(b.iter())
                .filter(|v| valid_depth(**v))
                .fold((f32::INFINITY, 0f32), |(lo, hi), &v| (lo.min(v), hi.max(v)));
            let span = f64::from(hi - lo).max(f64::MIN_POSITIVE);
            let show = |v: f32| {
                if valid_depth(v) {
                    grey(32.0 + 223.0 * f64::from(v - lo) / span)
                } else {
                    [0; 3]
                }
            };
            let diffs: Vec<Option<f64>> = a
                .iter()
                .zip(b.iter())
                .map(|(&x, &y)| match (valid_depth(x), valid_depth(y)) {
                    (true, true) => Some(f64::from((x - y).abs())),
                    (false, false) => Some(0.0),
                    _ => None,
                })
                .collect();
            let max = diffs
                .iter()
                .flatten()
                .fold(0f64, |m, &d| m.max(d))
                .max(f64::MIN_POSITIVE);
            let diff = diffs
                .iter()
                .flat_map(|d| d.map_or([255, 0, 0], |d| grey(d * 255.0 / max)))
                .collect();
            [
                rgb(a.iter().flat_map(|&v| show(v)).collect()),
                rgb(b.iter().flat_map(|&v| show(v)).collect()),
                rgb(diff),
            ]
        }
        (Plane::Mask(a), Plane::Mask(b)) => {
            assert!(a.len() == n && b.len() == n, "mask plane is not {width}x{height}");
            let max = a.iter().chain(b.iter()).copied().max().unwrap_or(0).max(1) as f64;
            let show = |m: &[u8]| m.iter().flat_map(|&v| grey(f64::from(v) * 255.0 / max)).collect();
            let diff = a
                .iter()
                .zip(b.iter())
                .flat_map(|(x, y)| match (*x != 0, *y != 0) {
                    (true, false) | (false, true) => [255, 0, 0],
                    _ if x != y => grey(128.0),
                    _ => [0; 3],
                })
                .collect();
            [rgb(show(a)), rgb(show(b)), rgb(diff)]
        }
        _ => panic!("image_check: the GPU and reference planes are of different kinds"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_check_writes_both_images_and_the_difference_and_names_the_folder() {
        let (a, b) = (
            vec![10u8; 2 * 2 * 3],
            vec![10u8, 10, 10, 40, 10, 10, 10, 10, 10, 10, 10, 10],
        );
        let (za, zb) = ([1.0f32, 2.0, 0.0, 3.0], [1.0f32, 2.5, 1.0, 3.0]);
        let (ma, mb) = ([1u8, 1, 0, 1], [1u8, 0, 0, 1]);
        let planes = [
            ("colour", Plane::Rgb(&a), Plane::Rgb(&b)),
            ("depth", Plane::Depth(&za), Plane::Depth(&zb)),
            ("mask", Plane::Mask(&ma), Plane::Mask(&mb)),
        ];
        let name = "image_check self-test";
        let dir = failure_dir(name);
        let _ = std::fs::remove_dir_all(&dir);
        let err = std::panic::catch_unwind(|| ensure(false, name, 2, 2, &planes, "they differ")).unwrap_err();
        let msg = err.downcast_ref::<String>().expect("formatted panic message");
        assert!(
            msg.contains("they differ") && msg.contains(&dir.display().to_string()),
            "{msg}"
        );
        for label in ["colour", "depth", "mask"] {
            for suffix in ["gpu", "reference", "diff"] {
                assert!(dir.join(format!("{label}_{suffix}.png")).is_file(), "{label}_{suffix}");
            }
        }
        // The colour difference is white where it is largest, black elsewhere.
        let diff = viewsynth::io::load_rgb(&dir.join("colour_diff.png")).unwrap();
        assert_eq!(&diff.data[..6], &[0, 0, 0, 255, 255, 255]);
        // Depth valid on one side only is red; equal depths are black.
        let diff = viewsynth::io::load_rgb(&dir.join("depth_diff.png")).unwrap();
        assert_eq!(&diff.data[6..9], &[255, 0, 0]);
        assert_eq!(&diff.data[..3], &[0, 0, 0]);
        // A passing check writes nothing.
        let _ = std::fs::remove_dir_all(&dir);
        ensure(true, name, 2, 2, &planes, "unused");
        assert!(!dir.exists());
    }
}
