//! The result must not depend on the convention beyond float rounding: every NDC range x
//! reversed-Z x row order gives the same mask and depth within 1e-6 relative (f32 rounding of
//! differently ordered arithmetic), for both paths.

use viewsynth::convention::Conventions;
use viewsynth::refocus::manifest::TargetSpec;
use viewsynth::refocus::{BreakRule, Method, OutputSet, Refocuser};
use viewsynth_tests::*;

#[test]
fn all_conventions_give_the_same_output() {
    let g = gpu();
    for (name, src) in [("TUM", real_frame("TUM")), ("synthetic", synthetic(320, 240))] {
        let targets = TargetSpec {
            scales: vec![0.5, 1.0, 1.5, 3.0],
            size: None,
            principal: None,
        }
        .targets(&src.camera())
        .unwrap();
        for method in [Method::Fullscreen, Method::Mesh] {
            let mut base = Vec::new();
            for (ci, conv) in Conventions::all().into_iter().enumerate() {
                let mut r =
                    Refocuser::new(&g, &src, &BreakRule::default(), method, OutputSet::default(), conv).unwrap();
                for (ti, t) in targets.iter().enumerate() {
                    let out = r.render(t).unwrap();
                    if ci == 0 {
                        base.push(out);
                        continue;
                    }
                    let b = &base[ti];
                    let tag = format!("{name} {method:?} {} scale#{ti}", conv.label());
                    assert_eq!(
                        out.mask.as_ref().unwrap().data,
                        b.mask.as_ref().unwrap().data,
                        "{tag}: mask"
                    );
                    let (z, zb) = (&out.depth.as_ref().unwrap().data, &b.depth.as_ref().unwrap().data);
                    for i in 0..z.len() {
                        let tol = 1e-6 * zb[i].abs();
                        assert!((z[i] - zb[i]).abs() <= tol, "{tag}: depth {i}: {} vs {}", z[i], zb[i]);
                    }
                    let (c, cb) = (&out.rgb.as_ref().unwrap().data, &b.rgb.as_ref().unwrap().data);
                    let worst = c
                        .iter()
                        .zip(cb)
                        .map(|(x, y)| (*x as i32 - *y as i32).abs())
                        .max()
                        .unwrap_or(0);
                    assert!(worst <= 1, "{tag}: colour differs by {worst} levels");
                }
            }
        }
    }
}
