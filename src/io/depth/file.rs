//! Depth maps: format dispatch, integer-to-metre conversion, EXR/NPY output.

use std::path::Path;

use image::ImageFormat;

use crate::error::{Error, Result};
use crate::io::files::atomic::atomic_write;
use crate::io::files::input::max_pixels;
use crate::io::formats::decode::{decode_image, image_dimensions, Samples};
use crate::io::formats::exr::{exr_dimensions, read_depth_channel, write_f32_planes};
use crate::io::formats::grey_png::grey_of;
use crate::io::formats::netpbm::netpbm_dimensions;
use crate::io::formats::npy::{open_npy, read_npy, save_npy_f32, NpyArray};
use crate::io::formats::npz::load_npz_array_within;
use crate::io::formats::raw_depth::{RawDepth, RawSamples};
use crate::io::formats::{pfm, pgm};
use crate::io::image::rgb::lowercase_extension;
use crate::io::image::types::{decode_dims, encode_dims, DepthMap};
use crate::io::NpyDtype;

/// How stored depth samples map to metres.
///
/// Integer inputs (8/16-bit PNG, PGM, `u2` NPY, u32 EXR): `metres = raw / scale`, and
/// `scale` is required (5000 for TUM, 1000 for SUN RGB-D). Raw 0 becomes 0.0 (invalid).
/// Float inputs (EXR, f4/f8 NPY, PFM): values are used as stored, or divided by `scale`
/// when it is given (e.g. 1000 for millimetres). NaN, infinities and negatives pass
/// through unchanged; callers treat them as invalid.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DepthDecode {
    /// Integer samples: divisor to metres (required); float samples: optional divisor (e.g. 1000 for millimetres).
    pub scale: Option<f64>,
    /// SUN RGB-D's PNG storage: `d = ((d >> 3) | (d << 13)) & 0xFFFF` before scaling.
    /// 16-bit inputs only.
    pub sun_rgbd_bit_rotate: bool,
    /// Swap the two bytes of each 16-bit sample before anything else. For files written
    /// little-endian despite the format (NYU Depth v2 raw PGM dumps). 16-bit inputs only.
    pub swap_bytes: bool,
}

/// Loads a depth (or disparity) map by extension, case-insensitive: `.exr` (one channel,
/// see below), `.npy` (shape (H, W) or (H, W, 1); `<f4 >f4 <f8 >f8 <u2 >u2`, either
/// order), `.npz` (the only array, else the first floating-point one, as `.npy`), `.png`
/// (16-bit, or 8-bit when `scale` is given; gray, or palette/RGB/RGBA with equal colour
/// channels and opaque alpha), `.pgm` (P5/P2, big-endian per Netpbm unless `swap_bytes`),
/// `.pfm` (grayscale `Pf`).
///
/// The EXR channel is "Z", else "depth" (any case), else "Y", else "R", else the only one.
pub fn load_depth(path: &Path, decode: &DepthDecode) -> Result<DepthMap> {
    load_depth_with_key(path, None, decode)
}

/// [`load_depth`], reading array `npz_key` of an `.npz` (`None`: the only array, else the
/// first floating-point one). A key given for another format is refused.
pub fn load_depth_with_key(path: &Path, npz_key: Option<&str>, decode: &DepthDecode) -> Result<DepthMap> {
    let ext = lowercase_extension(path);
    if npz_key.is_some() && ext != "npz" {
        return Err(Error::param(
            "npz-key",
            format!("{}: applies to .npz files only", path.display()),
        ));
    }
    let raw = match ext.as_str() {
        "exr" => read_depth_channel(path)?,
        "npy" => {
            let file = open_npy(path, max_pixels())?;
            npy_dims(path, file.shape())?;
            from_npy(path, read_npy(path, file)?)?
        }
        "npz" => {
            // The member's declared shape is checked (one value per budget pixel, (H, W) or
            // (H, W, 1)) before anything of it is inflated.
            let check = |shape: &[usize]| npy_dims(path, shape).map(|_| ());
            let (key, array) = load_npz_array_within(path, npz_key, max_pixels(), &check)?;
            from_npy(path, array).map_err(|e| match e {
                Error::Decode { path, message } => Error::decode(path, format!("array '{key}': {message}")),
                other => other,
            })?
        }
        "png" => read_png(path)?,
        "pgm" => pgm::read_pgm(path)?,
        "pfm" => pfm::read_pfm(path)?,
        _ => {
            return Err(Error::decode(
                path,
                "unknown depth format: expected .exr .npy .npz .png .pgm .pfm",
            ))
        }
    };
    to_metres(path, raw, decode)
}

/// Width and height of a depth file from its header alone (limits and pixel budget checked);
/// nothing of the body is read.
pub fn depth_dimensions(path: &Path) -> Result<(u32, u32)> {
    match lowercase_extension(path).as_str() {
        "exr" => exr_dimensions(path),
        "npy" => npy_dims(path, open_npy(path, max_pixels())?.shape()),
        "png" => image_dimensions(path, Some(ImageFormat::Png)),
        "pgm" | "pfm" => netpbm_dimensions(path),
        _ => Err(Error::decode(
            path,
            "unknown depth format: expected .exr .npy .png .pgm .pfm",
        )),
    }
}

/// Width and height of a colour file (PNG, JPEG, PPM, EXR) from its header alone.
pub fn rgb_dimensions(path: &Path) -> Result<(u32, u32)> {
    image_dimensions(path, None)
}

/// Checks from the headers alone (before either file is decoded) that a colour image and its
/// depth map have the same size; returns it. The error names both files and sizes.
pub fn check_rgbd_sizes(rgb: &Path, depth: &Path) -> Result<(u32, u32)> {
    let (cw, ch) = rgb_dimensions(rgb)?;
    if lowercase_extension(depth) == "npz" {
        // An archive's array is only known once inflated (and its key chosen): the sizes are
        // compared after decoding, still within the pixel budget.
        return Ok((cw, ch));
    }
    let (dw, dh) = depth_dimensions(depth)?;
    if (cw, ch) != (dw, dh) {
        return Err(Error::SizeMismatch {
            message: format!(
                "colour {} is {cw}x{ch} but depth {} is {dw}x{dh} (from their headers; nothing decoded)",
                rgb.display(),
                depth.display()
            ),
        });
    }
    Ok((cw, ch))
}

/// Writes one f32 channel named "Z", ZIP compressed, rows top-down.
pub fn save_depth_exr(path: &Path, depth: &DepthMap) -> Result<()> {
    save_depth_exr_with(path, depth, crate::io::ExrCompression::default())
}

/// [`save_depth_exr`] with a chosen compression.
pub fn save_depth_exr_with(path: &Path, depth: &DepthMap, compression: crate::io::ExrCompression) -> Result<()> {
    encode_dims(path, depth.width, depth.height, 1, depth.data.len())?;
    atomic_write(path, |out| encode_depth_exr(path, out, depth, compression))
}

/// Encodes [`save_depth_exr_with`]'s file into `out`; errors name `path`.
pub fn encode_depth_exr(
    path: &Path,
    out: &mut std::io::BufWriter<std::fs::File>,
    depth: &DepthMap,
    compression: crate::io::ExrCompression,
) -> Result<()> {
    encode_map_exr(path, out, depth, "Z", compression)
}

/// One f32 channel named `channel` holding `map`, rows top-down, into `out`; errors name `path`.
pub(crate) fn encode_map_exr(
    path: &Path,
    out: &mut std::io::BufWriter<std::fs::File>,
    map: &DepthMap,
    channel: &str,
    compression: crate::io::ExrCompression,
) -> Result<()> {
    encode_dims(path, map.width, map.height, 1, map.data.len())?;
    write_f32_planes(path, out, map.width, map.height, &[(channel, &map.data)], compression)
}

/// Writes `<f4`, shape (height, width), C order, NPY 1.0.
pub fn save_depth_npy(path: &Path, depth: &DepthMap) -> Result<()> {
    encode_dims(path, depth.width, depth.height, 1, depth.data.len())?;
    save_npy_f32(path, &[depth.height as usize, depth.width as usize], &depth.data)
}

/// Encodes [`save_depth_npy`]'s file into `out`; errors name `path`.
pub fn encode_depth_npy(path: &Path, out: &mut std::io::BufWriter<std::fs::File>, depth: &DepthMap) -> Result<()> {
    encode_dims(path, depth.width, depth.height, 1, depth.data.len())?;
    crate::io::formats::npy::encode_npy_f32(path, out, &[depth.height as usize, depth.width as usize], &depth.data)
}

/// A single-channel PNG, or a palette, RGB or RGBA one holding a grey map
/// ([`grey_of`]: equal colour channels, opaque alpha).
fn read_png(path: &Path) -> Result<RawDepth> {
    let img = decode_image(path, Some(ImageFormat::Png))?;
    let (channels, width) = (img.channels, img.width);
    let samples = match img.samples {
        Samples::U8(v) => RawSamples::U8(grey_of(path, v, channels, width, u8::MAX)?),
        Samples::U16(v) => RawSamples::U16(grey_of(path, v, channels, width, u16::MAX)?),
        Samples::F32(v) => RawSamples::F32(grey_of(path, v, channels, width, 1.0)?),
    };
    Ok(RawDepth {
        width: img.width,
        height: img.height,
        samples,
    })
}

/// Width and height of a depth NPY's shape, checked against the limits and the budget.
fn npy_dims(path: &Path, shape: &[usize]) -> Result<(u32, u32)> {
    let (h, w) = match shape {
        &[h, w] | &[h, w, 1] => (h, w),
        shape => {
            return Err(Error::decode(
                path,
                format!("depth NPY must have shape (H, W) or (H, W, 1), found {shape:?}"),
            ))
        }
    };
    decode_dims(path, w as u64, h as u64)
}

fn from_npy(path: &Path, arr: NpyArray) -> Result<RawDepth> {
    let (width, height) = npy_dims(path, &arr.shape)?;
    // Values were widened from the stored dtype, so narrowing back is exact.
    let samples = match arr.dtype {
        NpyDtype::U16 => RawSamples::U16(arr.data.iter().map(|&v| v as u16).collect()),
        NpyDtype::F32 => RawSamples::F32(arr.data.iter().map(|&v| v as f32).collect()),
        NpyDtype::F64 => RawSamples::F64(arr.data),
        NpyDtype::U8 => {
            return Err(Error::decode(
                path,
                "uint8 NPY is not accepted as depth: store metres as float32, \
                 or integers as uint16 with --depth-scale",
            ))
        }
    };
    Ok(RawDepth { width, height, samples })
}

fn to_metres(path: &Path, raw: RawDepth, decode: &DepthDecode) -> Result<DepthMap> {
    let scale = match decode.scale {
        Some(s) if !(s.is_finite() && s > 0.0) => {
            return Err(Error::param("depth-scale", format!("must be finite and > 0, got {s}")))
        }
        s => s,
    };
    let is_16_bit = matches!(raw.samples, RawSamples::U16(_));
    for (on, name) in [
        (decode.sun_rgbd_bit_rotate, "sun-rgbd-bit-rotate"),
        (decode.swap_bytes, "depth-swap-bytes"),
    ] {
        if on && !is_16_bit {
            return Err(Error::param(
                name,
                format!("{}: applies to 16-bit integer depth only", path.display()),
            ));
        }
    }
    let need_scale = |bits: &str, hint: &str| {
        scale.ok_or_else(|| {
            Error::param(
                "depth-scale",
                format!("{}: {bits} depth needs --depth-scale ({hint})", path.display()),
            )
        })
    };
    let data: Vec<f32> = match raw.samples {
        RawSamples::U8(v) => {
            let s = need_scale("8-bit", "unusual for depth; e.g. 4 for Middlebury 2003 disparity")?;
            v.into_iter().map(|d| int_to_metres(d.into(), s)).collect()
        }
        RawSamples::U16(v) => {
            let s = need_scale(
                "16-bit",
                "5000 for TUM, 1000 for SUN RGB-D, NYU, ScanNet or millimetres; \
                 viewsynth's png16 output records its scale in manifest.json",
            )?;
            if !(decode.swap_bytes || decode.sun_rgbd_bit_rotate) {
                // The common case as its own loop, so it vectorises.
                v.into_iter().map(|d| int_to_metres(d.into(), s)).collect()
            } else {
                v.into_iter()
                    .map(|d| {
                        let d = if decode.swap_bytes { d.swap_bytes() } else { d };
                        // Same as ((d >> 3) | (d << 13)) & 0xFFFF.
                        let d = if decode.sun_rgbd_bit_rotate {
                            d.rotate_right(3)
                        } else {
                            d
                        };
                        int_to_metres(d.into(), s)
                    })
                    .collect()
            }
        }
        RawSamples::U32(v) => {
            let s = need_scale("integer", "the number of raw units per metre")?;
            v.into_iter().map(|d| int_to_metres(d, s)).collect()
        }
        RawSamples::F32(v) => match scale {
            Some(s) => v.into_iter().map(|x| (f64::from(x) / s) as f32).collect(),
            None => v,
        },
        RawSamples::F64(v) => v.into_iter().map(|x| (x / scale.unwrap_or(1.0)) as f32).collect(),
    };
    let mut data = data;
    crate::io::clear_unusable_depth(&mut data);
    DepthMap::new(raw.width, raw.height, data).map_err(|e| Error::decode(path, e.to_string()))
}

/// `raw / scale` in f64, rounded once to f32; 0 (no reading) stays 0 because `scale` is finite
/// and > 0. No branch, so the conversion loops vectorise (a branch per pixel cost ~2 ms a VGA
/// frame).
fn int_to_metres(raw: u32, scale: f64) -> f32 {
    (f64::from(raw) / scale) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::formats::exr::write_f32_channels;
    use crate::io::formats::npy::build_npy;
    use crate::io::formats::pfm::build_pfm;
    use crate::io::test_util::{list_dir, scratch_dir};

    fn scaled(scale: f64) -> DepthDecode {
        DepthDecode {
            scale: Some(scale),
            ..Default::default()
        }
    }

    fn sample_map() -> DepthMap {
        // Non-symmetric, with an invalid NaN, an infinity and a negative value.
        let data = vec![0.5, 1.25, f32::NAN, 3.0, -1.0, f32::INFINITY];
        DepthMap::new(3, 2, data).unwrap()
    }

    fn same(a: &DepthMap, b: &DepthMap) -> bool {
        (a.width, a.height) == (b.width, b.height)
            && a.data.iter().zip(&b.data).all(|(x, y)| x.to_bits() == y.to_bits())
    }

    fn save_png16(path: &Path, w: u32, h: u32, data: Vec<u16>) {
        image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, data)
            .unwrap()
            .save(path)
            .unwrap();
    }

    #[test]
    fn exr_round_trip_is_bit_exact() {
        let dir = scratch_dir("depth-exr");
        let path = dir.join("d.EXR");
        save_depth_exr(&path, &sample_map()).unwrap();
        let back = load_depth(&path, &DepthDecode::default()).unwrap();
        assert!(same(&back, &sample_map()), "{back:?}");
        // Optional scale divides float depth.
        let mm = load_depth(&path, &scaled(2.0)).unwrap();
        assert_eq!(mm.get(1, 0), Some(0.625));
    }

    #[test]
    fn exr_ambiguous_channels_are_listed() {
        let dir = scratch_dir("depth-exr-ambiguous");
        let path = dir.join("d.exr");
        atomic_write(&path, |out| {
            write_f32_channels(
                &path,
                out,
                1,
                1,
                vec![("alpha", vec![1.0]), ("beta", vec![2.0])],
                crate::io::ExrCompression::default(),
            )
        })
        .unwrap();
        let err = load_depth(&path, &DepthDecode::default()).unwrap_err().to_string();
        assert!(
            err.contains("alpha") && err.contains("beta") && err.contains("d.exr"),
            "{err}"
        );
    }

    #[test]
    fn npy_round_trip_is_bit_exact() {
        let dir = scratch_dir("depth-npy");
        let path = dir.join("d.npy");
        save_depth_npy(&path, &sample_map()).unwrap();
        assert_eq!(crate::io::load_npy(&path).unwrap().shape, vec![2, 3]);
        let back = load_depth(&path, &DepthDecode::default()).unwrap();
        assert!(same(&back, &sample_map()), "{back:?}");
    }

    #[test]
    fn npy_hand_built_variants() {
        let dir = scratch_dir("depth-npy-variants");
        // f8 big-endian, Fortran order, shape (2, 3, 1); C-order values 0..6.
        let col_major = [0f64, 3.0, 1.0, 4.0, 2.0, 5.0];
        let payload: Vec<u8> = col_major.iter().flat_map(|v| v.to_be_bytes()).collect();
        let dict = "{'descr': '>f8', 'fortran_order': True, 'shape': (2, 3, 1), }";
        let path = dir.join("f8.npy");
        std::fs::write(&path, build_npy(dict, &payload)).unwrap();
        let d = load_depth(&path, &DepthDecode::default()).unwrap();
        assert_eq!((d.width, d.height), (3, 2));
        assert_eq!(d.data, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);

        // u2 big-endian needs a scale; 0 stays 0.
        let payload: Vec<u8> = [5000u16, 0, 10000, 2500].iter().flat_map(|v| v.to_be_bytes()).collect();
        let dict = "{'descr': '>u2', 'fortran_order': False, 'shape': (2, 2), }";
        let path = dir.join("u2.npy");
        std::fs::write(&path, build_npy(dict, &payload)).unwrap();
        let err = load_depth(&path, &DepthDecode::default()).unwrap_err();
        assert!(matches!(err, Error::InvalidParameter { ref name, .. } if name.to_string() == "depth-scale"));
        assert_eq!(
            load_depth(&path, &scaled(5000.0)).unwrap().data,
            vec![1.0, 0.0, 2.0, 0.5]
        );
    }

    #[test]
    fn npy_wrong_dtype_and_shape_are_refused() {
        let dir = scratch_dir("depth-npy-bad");
        let path = dir.join("rgb.npy");
        save_npy_f32(&path, &[2, 2, 3], &[0.0; 12]).unwrap();
        let err = load_depth(&path, &DepthDecode::default()).unwrap_err().to_string();
        assert!(err.contains("(H, W)") && err.contains("[2, 2, 3]"), "{err}");

        let path = dir.join("u1.npy");
        let dict = "{'descr': '|u1', 'fortran_order': False, 'shape': (1, 2), }";
        std::fs::write(&path, build_npy(dict, &[1, 2])).unwrap();
        let err = load_depth(&path, &scaled(1.0)).unwrap_err().to_string();
        assert!(err.contains("uint8"), "{err}");

        let path = dir.join("i4.npy");
        let dict = "{'descr': '<i4', 'fortran_order': False, 'shape': (1, 1), }";
        std::fs::write(&path, build_npy(dict, &[0; 4])).unwrap();
        let err = load_depth(&path, &scaled(1.0)).unwrap_err().to_string();
        assert!(err.contains("'<i4'"), "{err}");
    }

    #[test]
    fn png16_with_scale_and_sun_rotation() {
        let dir = scratch_dir("depth-png");
        let path = dir.join("d.png");
        save_png16(&path, 2, 1, vec![5000, 0]);
        let err = load_depth(&path, &DepthDecode::default()).unwrap_err().to_string();
        assert!(err.contains("--depth-scale") && err.contains("5000 for TUM"), "{err}");
        assert_eq!(load_depth(&path, &scaled(5000.0)).unwrap().data, vec![1.0, 0.0]);

        // SUN stores d rotated left by 3 bits; 2500 mm -> 2.5 m.
        let stored = 2500u16.rotate_left(3);
        save_png16(&path, 1, 1, vec![stored]);
        let sun = DepthDecode {
            scale: Some(1000.0),
            sun_rgbd_bit_rotate: true,
            swap_bytes: false,
        };
        assert_eq!(load_depth(&path, &sun).unwrap().data, vec![2.5]);
        let swapped = DepthDecode {
            swap_bytes: true,
            ..scaled(1.0)
        };
        save_png16(&path, 1, 1, vec![0x0102]);
        assert_eq!(load_depth(&path, &swapped).unwrap().data, vec![f32::from(0x0201u16)]);
    }

    #[test]
    fn png8_needs_scale_and_flags_need_16_bit() {
        let dir = scratch_dir("depth-png8");
        let path = dir.join("disp.png");
        image::GrayImage::from_raw(2, 1, vec![8, 0])
            .unwrap()
            .save(&path)
            .unwrap();
        let err = load_depth(&path, &DepthDecode::default()).unwrap_err().to_string();
        assert!(err.contains("8-bit"), "{err}");
        assert_eq!(load_depth(&path, &scaled(4.0)).unwrap().data, vec![2.0, 0.0]);
        let rot = DepthDecode {
            sun_rgbd_bit_rotate: true,
            ..scaled(4.0)
        };
        assert!(matches!(load_depth(&path, &rot), Err(Error::InvalidParameter { .. })));
        assert!(matches!(
            load_depth(&path, &scaled(0.0)),
            Err(Error::InvalidParameter { .. })
        ));
        assert!(matches!(
            load_depth(&path, &scaled(f64::NAN)),
            Err(Error::InvalidParameter { .. })
        ));

        let rgb = dir.join("rgb.png");
        image::RgbImage::from_raw(1, 1, vec![1, 2, 3])
            .unwrap()
            .save(&rgb)
            .unwrap();
        assert!(matches!(load_depth(&rgb, &scaled(1.0)), Err(Error::Decode { .. })));
    }

    #[test]
    fn pfm_and_pgm_dispatch() {
        let dir = scratch_dir("depth-pfm");
        let path = dir.join("d.PFM");
        let rows = [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0];
        std::fs::write(&path, build_pfm(2, &rows, false)).unwrap();
        let d = load_depth(&path, &DepthDecode::default()).unwrap();
        assert_eq!(
            (d.width, d.height, d.get(1, 0), d.get(0, 2)),
            (2, 3, Some(2.0), Some(5.0))
        );

        let path = dir.join("d.pgm");
        std::fs::write(&path, b"P5 2 1 65535\n\x13\x88\x00\x00").unwrap();
        assert_eq!(load_depth(&path, &scaled(5000.0)).unwrap().data, vec![1.0, 0.0]);
    }

    #[test]
    fn missing_corrupt_and_unknown_files() {
        let dir = scratch_dir("depth-errors");
        let missing = dir.join("none.exr");
        let err = load_depth(&missing, &DepthDecode::default()).unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert!(err.to_string().contains(&missing.display().to_string()));

        for name in ["bad.png", "bad.exr", "bad.npy", "bad.pfm", "bad.pgm"] {
            let path = dir.join(name);
            std::fs::write(&path, b"\x89PNG\r\n\x1a\ngarbage garbage garbage").unwrap();
            let err = load_depth(&path, &scaled(1.0)).unwrap_err();
            assert!(matches!(err, Error::Decode { .. }), "{name}: {err}");
            assert!(err.to_string().contains(name), "{err}");
        }

        let err = load_depth(&dir.join("d.tiff"), &DepthDecode::default()).unwrap_err();
        assert!(
            err.to_string().contains("expected .exr .npy .npz .png .pgm .pfm"),
            "{err}"
        );
    }

    #[test]
    fn saves_refuse_bad_maps_without_files() {
        let dir = scratch_dir("depth-save-bad");
        let bad = DepthMap {
            width: 3,
            height: 3,
            data: vec![0.0; 2],
        };
        assert!(save_depth_exr(&dir.join("d.exr"), &bad).is_err());
        assert!(save_depth_npy(&dir.join("d.npy"), &bad).is_err());
        let empty = DepthMap {
            width: 0,
            height: 1,
            data: vec![],
        };
        assert!(save_depth_exr(&dir.join("d.exr"), &empty).is_err());
        assert!(list_dir(&dir).is_empty());
    }
}
