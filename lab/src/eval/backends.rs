//! Device against device (GL against Vulkan): how far two runs of the same pass description
//! differ, counted as the issue of record states the agreement (masks on at most 0.5 % of
//! pixels, colour within one level on at least 99.5 %, depth within 1e-4 relative on at least
//! 99.5 % of the pixels valid in both). The one agreement type ([`BackendDiff`]) and rule
//! ([`BackendDiff::agrees`]), shared by the tests (viewsynth_tests/tests/library/vulkan/passes.rs) and the
//! report's table ([`device_rows`], `gl_vs_vulkan.md`): every pass of [`crate::passes`] run on
//! two devices under every convention.

use crate::passes::{PassCase, PassInputs};
use std::fmt::Write as _;
use viewsynth::convention::Conventions;
use viewsynth::error::Result;
use viewsynth::pass::Device;
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

    /// The worst of `self` and `other`, count by count (pixels: the larger).
    pub fn worst(self, other: BackendDiff) -> BackendDiff {
        BackendDiff {
            pixels: self.pixels.max(other.pixels),
            mask_mismatches: self.mask_mismatches.max(other.mask_mismatches),
            colour_beyond_one: self.colour_beyond_one.max(other.colour_beyond_one),
            colour_worst: self.colour_worst.max(other.colour_worst),
            depth_compared: self.depth_compared.max(other.depth_compared),
            depth_beyond: self.depth_beyond.max(other.depth_beyond),
            depth_worst_rel: self.depth_worst_rel.max(other.depth_worst_rel),
        }
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

/// One pass on two devices, over every convention.
#[derive(Debug, Clone)]
pub struct DeviceRow {
    /// The pass ([`PassCase::name`]).
    pub pass: String,
    /// The worst count of each kind over the conventions and the views of a frame.
    pub worst: BackendDiff,
    /// Every view of every convention within the rule ([`BackendDiff::agrees`]).
    pub agrees: bool,
    /// Summed wall milliseconds of one frame per convention, on each device.
    pub ms: [f64; 2],
}

/// Every pass of [`PassCase::all`] at `width` x `height` on both `devices` under each of
/// `conventions`, compared view by view under the one rule.
pub fn device_rows(
    devices: &[Device; 2],
    width: u32,
    height: u32,
    conventions: &[Conventions],
) -> Result<Vec<DeviceRow>> {
    let inputs = conventions
        .iter()
        .map(|&conv| PassInputs::new(width, height, conv))
        .collect::<Result<Vec<_>>>()?;
    let mut rows = Vec::new();
    for case in PassCase::all() {
        let mut row = DeviceRow {
            pass: case.name(),
            worst: BackendDiff::default(),
            agrees: true,
            ms: [0.0; 2],
        };
        for inputs in &inputs {
            let mut views = Vec::new();
            for (device, ms) in devices.iter().zip(row.ms.iter_mut()) {
                let t0 = std::time::Instant::now();
                views.push(case.frame(device, inputs)?()?);
                *ms += t0.elapsed().as_secs_f64() * 1e3;
            }
            if views[0].len() != views[1].len() {
                row.agrees = false;
            }
            for (a, b) in views[0].iter().zip(&views[1]) {
                let d = backend_diff(a, b);
                row.agrees &= d.agrees();
                row.worst = row.worst.worst(d);
            }
        }
        rows.push(row);
    }
    Ok(rows)
}

/// `rows` as a Markdown table, the devices named in the header.
pub fn device_table(rows: &[DeviceRow], names: [&str; 2]) -> String {
    let mut s = format!(
        "| pass | mask mismatches | pixels > 1 level | worst colour | depth beyond {DEPTH_REL:.0e} | worst depth rel | \
         agrees | {} ms | {} ms |\n|---|---|---|---|---|---|---|---|---|\n",
        names[0], names[1]
    );
    for r in rows {
        writeln!(
            s,
            "| {} | {} | {} | {} | {} | {:.1e} | {} | {:.1} | {:.1} |",
            r.pass,
            r.worst.mask_mismatches,
            r.worst.colour_beyond_one,
            r.worst.colour_worst,
            r.worst.depth_beyond,
            r.worst.depth_worst_rel,
            if r.agrees { "yes" } else { "NO" },
            r.ms[0],
            r.ms[1]
        )
        .expect("write to String");
    }
    s
}

/// `gl_vs_vulkan.md` in `out_dir`: [`device_rows`] of `first` against the automatically chosen
/// Vulkan device at 96 x 72 under the 8 conventions (when no Vulkan device opens, a line saying
/// why: the report goes on); its path.
pub fn write_section(first: &Device, out_dir: &std::path::Path) -> Result<std::path::PathBuf> {
    let second = viewsynth::vulkan::VulkanContext::open(
        viewsynth::vulkan::VulkanDeviceChoice::Auto,
        viewsynth::pass::GpuPolicy::default(),
    )
    .and_then(|vk| viewsynth::vulkan::VkExecutor::device(&vk));
    let mut text = format!(
        "# viewsynth: every pass, GL against Vulkan\n\nGL renderer: {}\n\n",
        first.renderer()
    );
    match second.and_then(|second| {
        let names = [first.renderer(), second.renderer()];
        let rows = device_rows(&[first.clone(), second], 96, 72, &Conventions::all())?;
        Ok((names, rows))
    }) {
        Ok((names, rows)) => {
            writeln!(
                text,
                "Every pass described once (src/pass/) and run by both devices, built-in scene 96x72 \
                 (refocus: 5 focal scales; stitch: 192x96 per eye from 24 px faces), worst over the 8 \
                 conventions. Rule (viewsynth_tests/tests/library/vulkan/passes.rs): masks differ on at most 0.5 % of \
                 pixels, colour within 1 level on 99.5 %, depth within 1e-4 relative on 99.5 % of pixels \
                 valid in both. Devices: {} against {}.\n",
                names[0], names[1]
            )
            .expect("write to String");
            text.push_str(&device_table(&rows, ["GL", "Vulkan"]));
        }
        Err(e) => writeln!(text, "Vulkan not run: {e}").expect("write to String"),
    }
    let path = out_dir.join("gl_vs_vulkan.md");
    viewsynth::io::atomic_write(&path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| viewsynth::Error::io(&path, e))
    })?;
    Ok(path)
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
