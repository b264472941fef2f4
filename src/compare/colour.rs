//! How a side's colour is stored (channel order, transfer function, alpha) and its conversion
//! to the form both sides are compared in: top-down, R G B, sRGB-encoded, straight alpha, as f32
//! at the file's own precision (8-bit files as v / 255, 16-bit as v / 65535, EXR as stored).

use crate::convention::RowOrder;
use crate::io::ColourImage;

/// Order of the colour channels in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ChannelOrder {
    /// Red first.
    #[default]
    Rgb,
    /// Blue first (a BGRA swapchain read back as RGBA).
    Bgr,
}

/// What the stored values are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Transfer {
    /// sRGB-encoded (what image viewers show, and our PNG outputs).
    #[default]
    Srgb,
    /// Linear light (a UNORM render target read back where an sRGB one was expected).
    Linear,
}

/// How colour relates to alpha (files with an alpha channel only).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Alpha {
    /// Colour independent of alpha.
    #[default]
    Straight,
    /// Colour multiplied by alpha.
    Premultiplied,
}

/// How one side's colour file is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct ColourReading {
    /// Channel order.
    pub channels: ChannelOrder,
    /// Transfer function of the stored values.
    pub transfer: Transfer,
    /// Alpha association (ignored without alpha: the job refuses it there).
    pub alpha: Alpha,
}

impl ChannelOrder {
    /// The name the CLI uses.
    pub fn name(self) -> &'static str {
        match self {
            ChannelOrder::Rgb => "rgb",
            ChannelOrder::Bgr => "bgr",
        }
    }
}

impl Transfer {
    /// The name the CLI uses.
    pub fn name(self) -> &'static str {
        match self {
            Transfer::Srgb => "srgb",
            Transfer::Linear => "linear",
        }
    }
}

impl Alpha {
    /// The name the CLI uses.
    pub fn name(self) -> &'static str {
        match self {
            Alpha::Straight => "straight",
            Alpha::Premultiplied => "premultiplied",
        }
    }
}

/// sRGB encoding of linear `v` (IEC 61966-2-1), in f64; negative values stay 0.
pub fn srgb_encode(v: f64) -> f64 {
    if v <= 0.003_130_8 {
        12.92 * v.max(0.0)
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear value of sRGB-encoded `v` (inverse of [`srgb_encode`]).
pub fn srgb_decode(v: f64) -> f64 {
    if v <= 0.040_45 {
        v.max(0.0) / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Top-down interleaved RGB of `img` stored in `rows`, in the compared form (see the module).
/// Premultiplied colour is divided by its alpha in the stored transfer (where alpha is 0 the
/// colour is kept: nothing to recover).
pub fn compared_form(img: &ColourImage, reading: ColourReading, rows: RowOrder) -> Vec<f32> {
    // f32 holds 16-bit and half-float colour exactly and keeps `compare` at a few bytes a
    // pixel (issue 46); the arithmetic below runs in f64.
    let (w, h) = (img.width as usize, img.height as usize);
    let mut out = img.rgb.clone();
    // Pixel i of the output (top-down) is stored pixel `src(i)`.
    let src = |i: usize| match rows {
        RowOrder::BottomUp => (h - 1 - i / w.max(1)) * w + i % w.max(1),
        RowOrder::TopDown => i,
    };
    if rows == RowOrder::BottomUp {
        let row = w * 3;
        for y in 0..h / 2 {
            let (top, bottom) = out.split_at_mut((h - 1 - y) * row);
            top[y * row..(y + 1) * row].swap_with_slice(&mut bottom[..row]);
        }
    }
    for (i, px) in out.chunks_exact_mut(3).enumerate() {
        if reading.channels == ChannelOrder::Bgr {
            px.swap(0, 2);
        }
        let mut v = [px[0], px[1], px[2]].map(f64::from);
        if let (Alpha::Premultiplied, Some(a)) = (reading.alpha, &img.alpha) {
            let a = f64::from(a[src(i)]);
            if a > 0.0 {
                v.iter_mut().for_each(|v| *v /= a);
            }
        }
        if reading.transfer == Transfer::Linear {
            v.iter_mut().for_each(|v| *v = srgb_encode(*v));
        }
        // Through f64 only when a reading changed the value: 8-bit v / 255 keeps its f32.
        if reading.transfer == Transfer::Linear || reading.alpha == Alpha::Premultiplied {
            px.copy_from_slice(&v.map(|v| v as f32));
        }
    }
    out
}

/// `data` with its rows of `row` values in the opposite order.
pub(super) fn flip_rows<T: Copy>(data: &[T], row: usize) -> Vec<T> {
    data.chunks_exact(row.max(1)).rev().flatten().copied().collect()
}

/// The compared form quantised to 8 bits (FLIP reads 8-bit sRGB).
pub(super) fn to_rgb8(values: &[f32], width: u32, height: u32) -> crate::io::RgbImage {
    crate::io::RgbImage {
        width,
        height,
        data: values
            .iter()
            .map(|v| {
                if v.is_nan() {
                    0
                } else {
                    (v.clamp(0.0, 1.0) * 255.0).round() as u8
                }
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips_and_matches_known_values() {
        assert!((srgb_encode(0.5) - 0.735_356_983).abs() < 1e-8);
        assert!((srgb_decode(0.5) - 0.214_041_140).abs() < 1e-8);
        for i in 0..=100 {
            let v = f64::from(i) / 100.0;
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-12, "{v}");
        }
    }

    #[test]
    fn the_compared_form_undoes_each_declared_storage() {
        // Two pixels, one row each, bottom-up: (0.2, 0.4, 0.6) on top, then (1, 0, 0) as BGR.
        let img = ColourImage {
            width: 1,
            height: 2,
            rgb: vec![0.0, 0.0, 0.5, 0.6, 0.4, 0.2],
            alpha: Some(vec![0.5, 1.0]),
            bits: 32,
        };
        let reading = ColourReading {
            channels: ChannelOrder::Bgr,
            transfer: Transfer::Srgb,
            alpha: Alpha::Premultiplied,
        };
        let c = compared_form(&img, reading, RowOrder::BottomUp);
        let want = [0.2, 0.4, 0.6, 1.0, 0.0, 0.0];
        assert!(c.iter().zip(want).all(|(c, w)| (c - w).abs() < 1e-6), "{c:?}");
    }
}
