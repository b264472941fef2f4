//! Real stereo (Middlebury 2003 Cones with its disparities) and the splat-gather renders that
//! the library's cyclopean tests and the command line's both measure against.

use crate::{data_dir, gpu};
use std::path::PathBuf;
use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
use viewsynth::io::{self, DepthDecode, DepthMap, RgbImage};
use viewsynth::metrics;
use viewsynth::stereo::gather::{CyclopeanOutput, CyclopeanOutputs};
use viewsynth::stereo::{MiddleCamera, StereoFrame};

/// The splat-gather view of `frame` at `mid` on a GL context of its own.
pub fn splat_gpu(frame: &StereoFrame, mid: &MiddleCamera) -> CyclopeanOutput {
    splat_on(&viewsynth::pass::Device::gl(&gpu()).unwrap(), frame, mid)
}

/// The splat-gather view of `frame` at `mid` on `device`.
pub fn splat_on(device: &viewsynth::pass::Device, frame: &StereoFrame, mid: &MiddleCamera) -> CyclopeanOutput {
    SplatRenderer::new(device, frame, SplatParams::default(), CyclopeanOutputs::default())
        .unwrap()
        .render(mid)
        .unwrap()
        .0
}

/// A fresh scratch folder for `name` (this process' own).
pub fn out_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("viewsynth-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// One eye: its colour and its disparities (px).
pub type Eye = (RgbImage, DepthMap);

/// Cones' left and right eyes with their ground-truth disparities, and the true middle view (im4).
pub fn cones() -> (Eye, Eye, RgbImage) {
    let dir = data_dir().join("middlebury2003_cones");
    let dec = DepthDecode {
        scale: Some(4.0),
        ..Default::default()
    };
    let eye = |im: &str, disp: &str| {
        (
            io::load_rgb(&dir.join(im)).unwrap(),
            io::load_depth(&dir.join(disp), &dec).unwrap(),
        )
    };
    (
        eye("im2.png", "disp2.pgm"),
        eye("im6.png", "disp6.pgm"),
        io::load_rgb(&dir.join("im4.png")).unwrap(),
    )
}

/// PSNR of `a` against `b` over the pixels `mask` keeps.
pub fn psnr(a: &RgbImage, b: &RgbImage, mask: &[bool]) -> f64 {
    let (mut sq, mut n) = (0.0, 0usize);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        n += 1;
        for c in 0..3 {
            let d = a.data[i * 3 + c] as f64 - b.data[i * 3 + c] as f64;
            sq += d * d;
        }
    }
    metrics::psnr_from_mse(sq / (3 * n) as f64)
}

/// How many pixels `mask` keeps.
pub fn count(mask: &[bool]) -> usize {
    mask.iter().filter(|m| **m).count()
}
