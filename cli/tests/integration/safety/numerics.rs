//! Depth and focal values over the whole f32/f64 range through the commands: never valid and
//! non-finite; a refusal names the value.

use crate::common::assert_no_failures;
use viewsynth::io::{self, DepthMap};

use crate::cli::{bin, scratch};
use crate::safety::support::{inputs, H, W};

#[test]
fn depth_and_focal_values_over_the_whole_range_are_never_valid_and_non_finite() {
    let root = scratch("r3-numerics");
    let (rgb, _) = inputs(&root);
    let values: [f32; 14] = [
        1e-45,
        1e-40,
        f32::MIN_POSITIVE,
        1e-30,
        1e-7,
        1e-6,
        1.0,
        1e6,
        1.1e6,
        1e20,
        1e38,
        f32::MAX,
        -1e-40,
        -1e38,
    ];
    let mut failures = Vec::new();
    let mut cases = 0;
    for (i, v) in values.iter().enumerate() {
        let depth = root.join(format!("d{i}.npy"));
        io::save_depth_npy(&depth, &DepthMap::new(W, H, vec![*v; (W * H) as usize]).unwrap()).unwrap();
        for method in ["fullscreen", "mesh"] {
            for fx in ["40", "1e-3", "1e6"] {
                cases += 1;
                let out = root.join(format!("o{i}-{method}-{fx}"));
                let res = bin()
                    .args([
                        "refocus",
                        "--fy",
                        "40",
                        "--cx",
                        "15.5",
                        "--cy",
                        "11.5",
                        "--zoom-range",
                        "0.5,2",
                    ])
                    .args(["--fx", fx, "--method", method, "--depth-format", "exr"])
                    .arg("--rgb")
                    .arg(&rgb)
                    .arg("--depth")
                    .arg(&depth)
                    .arg("--out-dir")
                    .arg(&out)
                    .output()
                    .unwrap();
                let err = String::from_utf8_lossy(&res.stderr);
                if !res.status.success() {
                    // A refusal must be a clear run or usage error naming the value.
                    if !matches!(res.status.code(), Some(1 | 2)) || err.contains("panicked") {
                        failures.push(format!("depth {v:e} {method} fx {fx}: {err}"));
                    }
                    continue;
                }
                let usable = v.abs() >= 1e-6 && v.abs() <= 1e6;
                for tag in ["s0.5", "s2"] {
                    let d = io::load_depth(&out.join(format!("{tag}_depth.exr")), &Default::default()).unwrap();
                    let m = io::load_mask_png(&out.join(format!("{tag}_mask.png"))).unwrap();
                    let bad = d
                        .data
                        .iter()
                        .zip(&m.data)
                        .filter(|(z, m)| **m != 0 && !z.is_finite())
                        .count();
                    let valid = m.data.iter().filter(|m| **m != 0).count();
                    if bad > 0 {
                        failures.push(format!(
                            "depth {v:e} {method} fx {fx} {tag}: {bad} valid pixels not finite"
                        ));
                    }
                    if !usable && valid > 0 {
                        failures.push(format!("depth {v:e} {method} fx {fx} {tag}: {valid} valid pixels"));
                    }
                }
            }
        }
    }
    assert_no_failures(failures, cases);
}
