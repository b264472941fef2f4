//! Refocus report rows: both GPU paths on the built-in scene against the scene ray-traced from
//! each target camera.

use super::{score, timed};
use crate::report::ReportRow;
use viewsynth::convention::Conventions;
use viewsynth::error::Result;
use viewsynth::pass::Device;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::{BreakRule, Method as RefocusMethod, OutputSet, RefocusSource, Refocuser};
use viewsynth::world;

/// Refocus of the built-in scene against the scene ray-traced from each target camera.
pub fn refocus_rows(device: &Device, repeats: usize) -> Result<Vec<ReportRow>> {
    let cam = world::demo_camera(640, 480);
    let (rgb, depth) = world::render(&cam);
    let src = RefocusSource::new(rgb, depth, cam.k)?;
    let scales = [0.5, 1.0, 2.0];
    let targets = TargetSpec {
        scales: scales.to_vec(),
        size: None,
        principal: None,
    }
    .targets(&cam)?;
    let mut rows = Vec::new();
    for method in [RefocusMethod::Fullscreen, RefocusMethod::Mesh] {
        let mut r = Refocuser::new(
            device,
            &src,
            &BreakRule::default(),
            method,
            OutputSet::default(),
            Conventions::default(),
        )?;
        for (s, target) in scales.iter().zip(&targets) {
            let (out, t) = timed(repeats, || {
                let o = r.render(target)?;
                let t = o.render;
                Ok((o, t))
            })?;
            let (truth, truth_depth) = world::render(target);
            let mask: Vec<bool> = out
                .mask
                .as_ref()
                .expect("mask requested")
                .data
                .iter()
                .zip(&truth_depth.data)
                .map(|(m, z)| *m != 0 && *z > 0.0)
                .collect();
            let name = match method {
                RefocusMethod::Fullscreen => "fullscreen",
                RefocusMethod::Mesh => "mesh",
            };
            let mut row = ReportRow::new("refocus", "builtin:demo 640x480", name, format!("s={s}"), t.wall_ms);
            row.gpu_ms = t.gpu_ms;
            score(
                out.rgb.as_ref().expect("rgb"),
                out.depth.as_ref(),
                &mask,
                &truth,
                Some(&truth_depth),
                &mut row,
            );
            rows.push(row);
        }
    }
    Ok(rows)
}
