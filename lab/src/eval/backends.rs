//! GL against Vulkan: how far two runs of the same pass description on the two APIs differ,
//! counted as the issue of record states the agreement (masks on at most 0.5 % of pixels,
//! colour within one level on at least 99.5 %, depth within 1e-4 relative on at least 99.5 % of
//! the pixels valid in both). Shared by the tests and the report's GL-vs-Vulkan table.

use viewsynth::view::ViewOutput;

/// Relative depth difference counted as agreeing.
pub const DEPTH_REL: f64 = 1e-4;

/// Differences between a GL view and a Vulkan view of one pass.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BackendDiff {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels whose mask (valid or not) differs.
    pub mask_mismatches: usize,
    /// Pixels with a channel more than one level apart.
    pub colour_beyond_one: usize,
    /// Largest channel difference, levels.
    pub colour_worst: i32,
    /// Pixels valid in both (or every pixel with depth, when the views have no mask).
    pub depth_compared: usize,
    /// Of those, pixels more than [`DEPTH_REL`] apart, relative.
    pub depth_beyond: usize,
    /// Largest relative depth difference.
    pub depth_worst_rel: f64,
}

impl BackendDiff {
    /// The agreement rule above.
    pub fn agrees(&self) -> bool {
        let frac = |n: usize, of: usize| if of == 0 { 0.0 } else { n as f64 / of as f64 };
        frac(self.mask_mismatches, self.pixels) <= 0.005
            && frac(self.colour_beyond_one, self.pixels) <= 0.005
            && frac(self.depth_beyond, self.depth_compared) <= 0.005
    }
}

/// Compares `gl` with `vk` plane by plane (planes only one view has are mismatches of every
/// pixel: the same files must be written by both).
pub fn backend_diff(gl: &ViewOutput, vk: &ViewOutput) -> BackendDiff {
    let n = gl.width as usize * gl.height as usize;
    let mut d = BackendDiff {
        pixels: n,
        ..Default::default()
    };
    if (gl.width, gl.height) != (vk.width, vk.height) {
        d.mask_mismatches = n;
        return d;
    }
    let (va, vb) = (gl.valid(), vk.valid());
    match (&va, &vb) {
        (Some(a), Some(b)) => d.mask_mismatches = a.iter().zip(b).filter(|(x, y)| x != y).count(),
        (None, None) => {}
        _ => d.mask_mismatches = n,
    }
    match (&gl.color, &vk.color) {
        (Some(a), Some(b)) => {
            for (pa, pb) in a.data.chunks_exact(3).zip(b.data.chunks_exact(3)) {
                let worst = pa
                    .iter()
                    .zip(pb)
                    .map(|(x, y)| (*x as i32 - *y as i32).abs())
                    .max()
                    .unwrap_or(0);
                d.colour_worst = d.colour_worst.max(worst);
                d.colour_beyond_one += (worst > 1) as usize;
            }
        }
        (None, None) => {}
        _ => d.colour_beyond_one = n,
    }
    match (&gl.depth, &vk.depth) {
        (Some(a), Some(b)) => {
            for i in 0..n {
                let both = match (&va, &vb) {
                    (Some(x), Some(y)) => x[i] && y[i],
                    _ => a.data[i] > 0.0 && b.data[i] > 0.0,
                };
                if !both {
                    continue;
                }
                let (za, zb) = (a.data[i] as f64, b.data[i] as f64);
                let rel = if za == zb {
                    0.0
                } else {
                    (za - zb).abs() / za.abs().max(zb.abs())
                };
                d.depth_compared += 1;
                d.depth_beyond += (rel.is_nan() || rel > DEPTH_REL) as usize;
                d.depth_worst_rel = d.depth_worst_rel.max(if rel.is_nan() { f64::INFINITY } else { rel });
            }
        }
        (None, None) => {}
        _ => {
            d.depth_compared = n;
            d.depth_beyond = n;
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use viewsynth::io::{DepthMap, Mask, RgbImage};

    fn view(color: Vec<u8>, depth: Vec<f32>, mask: Vec<u8>) -> ViewOutput {
        let n = depth.len() as u32;
        ViewOutput {
            width: n,
            height: 1,
            color: Some(RgbImage::new(n, 1, color).unwrap()),
            depth: Some(DepthMap::new(n, 1, depth).unwrap()),
            mask: Some(Mask::new(n, 1, mask).unwrap()),
            timing: None,
            exact: None,
        }
    }

    #[test]
    fn counts_each_kind_of_difference_and_applies_the_half_percent_rule() {
        let a = view(vec![10; 6], vec![1.0, 2.0], vec![255, 255]);
        assert_eq!(
            backend_diff(&a, &a),
            BackendDiff {
                pixels: 2,
                depth_compared: 2,
                ..Default::default()
            }
        );
        assert!(backend_diff(&a, &a).agrees());
        let b = view(vec![11, 10, 10, 13, 10, 10], vec![1.0, 2.001], vec![255, 0]);
        let d = backend_diff(&a, &b);
        assert_eq!((d.mask_mismatches, d.colour_beyond_one, d.colour_worst), (1, 1, 3));
        // Pixel 1 is valid in one view only: its depth is not compared.
        assert_eq!((d.depth_compared, d.depth_beyond), (1, 0));
        assert!(!d.agrees());
        let c = view(vec![10; 6], vec![1.0002, 2.0], vec![255, 255]);
        assert_eq!(backend_diff(&a, &c).depth_beyond, 1);
        let mut no_depth = a.clone();
        no_depth.depth = None;
        assert!(!backend_diff(&a, &no_depth).agrees(), "a plane missing on one side");
    }
}
