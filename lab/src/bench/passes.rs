//! `viewsynth bench --with-vulkan`: every pass of [`crate::passes`] timed on each device from one
//! run, same inputs (the rows the report's agreement table compares), for the GL-vs-Vulkan
//! comparison. Nothing here knows which API a device runs.

use super::BenchCase;
use crate::passes::{Frame, PassCase, PassInputs};
use crate::stats::median;
use std::fmt::Write as _;
use std::time::Instant;
use viewsynth::convention::Conventions;
use viewsynth::error::Result;
use viewsynth::pass::Device;

/// Median ms of `repeats` frames after a warm-up (pipelines compile on first use, targets are
/// allocated).
fn time(repeats: usize, mut frame: Frame) -> Result<f64> {
    frame()?;
    let mut runs = Vec::new();
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        frame()?;
        runs.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(&runs))
}

/// Every pass on each of `devices` (named `names`, e.g. "gl" and "vulkan"), render + readback,
/// medians of `repeats` after a warm-up, at `width` x `height` (refocus: 5 focal scales a frame;
/// stitch: one stereo equirect `2 width` x `width` per eye from `width / 4` px faces). One
/// Markdown table, the last column the second device's time over the first's; every case also
/// goes to `cases` (`<name>-<pass>`).
pub fn passes_bench(
    devices: &[(&str, Device)],
    width: u32,
    height: u32,
    repeats: usize,
    cases: &mut Vec<BenchCase>,
) -> Result<String> {
    let inputs = PassInputs::new(width, height, Conventions::default())?;
    let mut t = format!(
        "every pass on each device: {width}x{height} (refocus: 5 focal scales a frame; stitch: \
         {0}x{1} per eye from {2} px faces), render + readback, {repeats} repeats, medians; devices: {3}\n\n| pass |",
        2 * width,
        width,
        (width / 4).max(16),
        devices
            .iter()
            .map(|(name, d)| format!("{name} '{}'", d.renderer()))
            .collect::<Vec<_>>()
            .join(", ")
    );
    for (name, _) in devices {
        write!(t, " {name} ms |").expect("write to String");
    }
    let ratio = devices.len() == 2;
    if ratio {
        write!(t, " {} / {} |", devices[1].0, devices[0].0).expect("write to String");
    }
    t.push_str(&format!(
        "\n|---|{}{}\n",
        "---|".repeat(devices.len()),
        if ratio { "---|" } else { "" }
    ));
    for case in PassCase::all() {
        let name = case.name();
        write!(t, "| {name} |").expect("write to String");
        let mut ms = Vec::new();
        for (api, device) in devices {
            let m = time(repeats, case.frame(device, &inputs)?)?;
            cases.push(BenchCase::new(
                "passes",
                &format!("{api}-{name}"),
                format!("{width}x{height}"),
                None,
                m,
            ));
            write!(t, " {m:.2} |").expect("write to String");
            ms.push(m);
        }
        if ratio {
            write!(t, " {:.2} |", ms[1] / ms[0]).expect("write to String");
        }
        t.push('\n');
    }
    Ok(t)
}
