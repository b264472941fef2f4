//! `viewsynth stress --quick`: every case of every capability passes its derived bound (or is
//! marked lost by design) and no output holds NaN/Inf. The bounds are derived in src/stress/*.rs
//! beside each case.

use viewsynth_lab::stress::{first_failure, run_stress, table, StressOptions, CAPABILITIES};
use viewsynth_tests::gpu;

#[test]
fn quick_sweep_of_every_capability_passes_with_no_nan_or_inf() {
    let g = gpu();
    let rows = run_stress(
        &viewsynth::pass::Device::gl(&g).unwrap(),
        &CAPABILITIES,
        StressOptions { quick: true },
    )
    .unwrap();
    println!("{}", table(&rows));
    for cap in CAPABILITIES {
        assert!(rows.iter().any(|r| r.capability == cap), "no rows for {cap}");
    }
    assert!(rows.iter().all(|r| r.non_finite == 0), "NaN/Inf in an output");
    assert!(first_failure(&rows).is_none(), "{}", table(&rows));
    // The sweep must actually compare pixels, and say where precision is lost by design: the
    // standard-Z rows at near/far 1e-7 and the lossy depth round trips.
    assert!(rows.iter().filter(|r| r.pixels > 0).count() >= 30);
    let lossy: Vec<_> = rows.iter().filter(|r| r.tolerance.by_design).collect();
    assert!(lossy.len() >= 5 && lossy.iter().all(|r| r.note.contains("by design")));
    assert!(lossy
        .iter()
        .all(|r| !r.case.contains("reversed-Z") && !r.case.contains("vk-rev")));
    // The value sweeps (issue 23): every GPU capability over the whole f32/f64 range, GPU and
    // twin compared, refusals alike, and no valid pixel with a non-finite output.
    for cap in ["refocus", "cyclopean", "reproject", "stitch"] {
        let sweeps: Vec<_> = rows
            .iter()
            .filter(|r| r.capability == cap && r.case.starts_with("value sweep"))
            .collect();
        assert!(!sweeps.is_empty(), "no value sweep for {cap}");
        for r in sweeps {
            assert!(r.pass && r.non_finite == 0 && r.pixels > 0, "{r:?}");
            assert!(
                r.note.contains("refused on both sides") && !r.note.contains("first problem"),
                "{r:?}"
            );
        }
    }
    // One past the context's largest image side is refused, naming the size and the limit, by
    // every GPU capability (refocus: its source and its output).
    let limit = g.max_image_side();
    let refused: Vec<_> = rows
        .iter()
        .filter(|r| r.case.contains("one past the largest"))
        .collect();
    assert_eq!(refused.len(), 5);
    assert!(
        refused.iter().all(|r| r.note.contains(&limit.to_string())),
        "{refused:?}"
    );
    assert!(
        refused.iter().all(|r| r.pass && r.note.starts_with("refused:")),
        "{refused:?}"
    );
}
