//! A colour-mapped picture of a depth map, for looking at rather than measuring: Google's
//! turbo map (via `colorous`), near = red, far = blue, invalid = black. The colour range runs
//! over the 2nd to 98th percentile of the valid depth so that a few stray pixels do not flatten
//! the rest; depth outside it takes the end colours.

use std::path::Path;

use serde::Serialize;

use crate::error::Result;
use crate::io::image::types::{DepthMap, RgbImage};
use crate::io::Encoding;

/// The depth (metres) at the near (red) and far (blue) ends of the preview's colour map.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PreviewRange {
    /// Depth at the red (near) end, metres.
    pub min_m: f64,
    /// Depth at the blue (far) end, metres.
    pub max_m: f64,
}

/// Fractions of the valid pixels below the range's ends.
pub const PREVIEW_PERCENTILES: (f64, f64) = (0.02, 0.98);

/// The 2nd and 98th percentile of the valid (finite, > 0) depth; None when no pixel is valid.
pub fn depth_preview_range(depth: &DepthMap) -> Option<PreviewRange> {
    let mut valid: Vec<f32> = depth
        .data
        .iter()
        .copied()
        .filter(|z| z.is_finite() && *z > 0.0)
        .collect();
    if valid.is_empty() {
        return None;
    }
    valid.sort_unstable_by(f32::total_cmp);
    let at = |p: f64| f64::from(valid[(p * (valid.len() - 1) as f64).round() as usize]);
    Some(PreviewRange {
        min_m: at(PREVIEW_PERCENTILES.0),
        max_m: at(PREVIEW_PERCENTILES.1),
    })
}

/// The preview of `depth` over `range` (see the module's description).
pub fn depth_preview(depth: &DepthMap, range: Option<PreviewRange>) -> RgbImage {
    let mut data = Vec::with_capacity(depth.data.len() * 3);
    for &z in &depth.data {
        let rgb = match range {
            Some(r) if z.is_finite() && z > 0.0 => {
                let span = r.max_m - r.min_m;
                // A flat map (one depth) takes the middle colour.
                let t = if span > 0.0 {
                    (f64::from(z) - r.min_m) / span
                } else {
                    0.5
                };
                // Turbo's ends are near-black; 0.1-0.9 keeps valid depth apart from holes.
                let c = colorous::TURBO.eval_continuous(0.9 - 0.8 * t.clamp(0.0, 1.0));
                [c.r, c.g, c.b]
            }
            _ => [0, 0, 0],
        };
        data.extend_from_slice(&rgb);
    }
    RgbImage {
        width: depth.width,
        height: depth.height,
        data,
    }
}

/// Writes the preview of `depth` as PNG (with `encoding`'s PNG compression) and returns the
/// range it used (None when no pixel is valid: the picture is black).
pub fn save_depth_preview(path: &Path, depth: &DepthMap, encoding: &Encoding) -> Result<Option<PreviewRange>> {
    let range = depth_preview_range(depth);
    crate::io::save_rgb_with(path, &depth_preview(depth, range), encoding)?;
    Ok(range)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::scratch_dir;

    #[test]
    fn invalid_is_black_and_near_differs_from_far() {
        // 100 valid pixels from 1.00 to 1.99 m, then 0, NaN, -1 and +inf.
        let mut z: Vec<f32> = (0..100).map(|i| 1.0 + 0.01 * i as f32).collect();
        z.extend([0.0, f32::NAN, -1.0, f32::INFINITY]);
        let depth = DepthMap::new(z.len() as u32, 1, z).unwrap();
        let r = depth_preview_range(&depth).unwrap();
        assert!((r.min_m - 1.02).abs() < 1e-6 && (r.max_m - 1.97).abs() < 1e-6, "{r:?}");
        let dir = scratch_dir("preview");
        let path = dir.join("p.png");
        assert_eq!(
            save_depth_preview(&path, &depth, &Encoding::default()).unwrap(),
            Some(r)
        );
        let img = crate::io::load_rgb(&path).unwrap();
        let px = |i: usize| [img.data[3 * i], img.data[3 * i + 1], img.data[3 * i + 2]];
        for i in 100..104 {
            assert_eq!(px(i), [0, 0, 0], "invalid pixel {i}");
        }
        let (near, mid, far) = (px(0), px(50), px(99));
        assert!(near != far && near != mid && mid != far, "{near:?} {mid:?} {far:?}");
        // Near is the warm end of turbo, far the cool end.
        assert!(near[0] > near[2] && far[2] > far[0], "{near:?} {far:?}");
        // Every valid pixel is clearly brighter than a hole.
        assert!(
            (0..100).all(|i| px(i).iter().max().unwrap() >= &100),
            "{near:?} {far:?}"
        );
        // Beyond the percentiles the end colours hold.
        assert_eq!(px(0), px(1));
    }

    #[test]
    fn nothing_valid_gives_no_range_and_a_black_picture() {
        let depth = DepthMap::new(2, 1, vec![0.0, f32::NAN]).unwrap();
        assert_eq!(depth_preview_range(&depth), None);
        assert_eq!(depth_preview(&depth, None).data, vec![0; 6]);
        let flat = DepthMap::new(2, 1, vec![2.0, 2.0]).unwrap();
        let img = depth_preview(&flat, depth_preview_range(&flat));
        assert_eq!(img.data[..3], img.data[3..]);
        assert_ne!(img.data[..3], [0, 0, 0]);
    }
}
