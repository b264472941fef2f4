//! The rectified-stereo command on real pairs: a pair with disparities renders what the library
//! renders and bad input is refused cleanly; two images alone render the census and semi-global
//! matchers' disparities (the splat-gather pass against its twin is `viewsynth_tests`'
//! `cyclopean::real_pairs`).

use crate::common::data_dir;
use std::path::Path;
use viewsynth::convention::Conventions;
use viewsynth::io::{self, DepthDecode};
use viewsynth::stereo::disparity_frame::{disparity_frame, DisparityRig};
use viewsynth::stereo::trust_reference::trust_reference;
use viewsynth_tests::real_pairs::{cones, count, out_dir, psnr, splat_gpu};

fn viewsynth(args: &[&str], paths: &[(&str, &Path)]) -> std::process::Output {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_viewsynth"));
    c.arg("cyclopean").args(args);
    for (flag, p) in paths {
        c.arg(flag).arg(p);
    }
    c.output().unwrap()
}

#[test]
fn cli_rectified_pair_matches_the_library_and_refuses_bad_input_cleanly() {
    let dir = data_dir().join("middlebury2003_cones");
    let out = out_dir("cyclopean-stereo-cli");
    let inputs = [
        ("--left-rgb", dir.join("im2.png")),
        ("--right-rgb", dir.join("im6.png")),
        ("--left-disparity", dir.join("disp2.pgm")),
        ("--right-disparity", dir.join("disp6.pgm")),
    ];
    let mut paths: Vec<(&str, &Path)> = inputs.iter().map(|(f, p)| (*f, p.as_path())).collect();
    let good = out.join("good");
    paths.push(("--out-dir", &good));
    let o = viewsynth(
        &["--disparity-scale", "4", "--focal", "400", "--baseline", "0.1"],
        &paths,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (l, r, _) = cones();
    let (frame, mid) = disparity_frame(l, r, &DisparityRig::middle(400.0, 0.1), Conventions::default()).unwrap();
    let lib = splat_gpu(&frame, &mid);
    assert_eq!(
        io::load_rgb(&good.join("middle_rgb.png")).unwrap(),
        *lib.color().unwrap()
    );
    let z = io::load_depth(&good.join("middle_depth.exr"), &Default::default()).unwrap();
    assert_eq!(z, *lib.depth().unwrap(), "metric depth f B / d");
    assert!(good.join("middle_mask.png").is_file());

    // No focal/baseline: colour and mask only; --position 0 is the left eye itself.
    let left = out.join("left");
    paths.pop();
    paths.push(("--out-dir", &left));
    let o = viewsynth(&["--disparity-scale", "4", "--position", "0"], &paths);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(crate::cli::files_in(&left), ["middle_mask.png", "middle_rgb.png"]);
    let im2 = io::load_rgb(&dir.join("im2.png")).unwrap();
    let mask = io::load_mask_png(&left.join("middle_mask.png")).unwrap();
    let rgb = io::load_rgb(&left.join("middle_rgb.png")).unwrap();
    // Where the left disparity is known the view is the left image itself (the right eye's
    // weight is 0 at the left eye); elsewhere the right eye fills in.
    let disp2 = io::load_depth(
        &dir.join("disp2.pgm"),
        &DepthDecode {
            scale: Some(4.0),
            ..Default::default()
        },
    )
    .unwrap();
    let known: Vec<usize> = (0..disp2.data.len())
        .filter(|&i| disp2.data[i] > 0.0 && mask.data[i] != 0)
        .collect();
    let exact = known
        .iter()
        .filter(|&&i| rgb.data[i * 3..i * 3 + 3] == im2.data[i * 3..i * 3 + 3])
        .count();
    assert!(
        exact as f64 >= 0.99 * known.len() as f64,
        "position 0 reproduces the left eye on {exact} of {} pixels",
        known.len()
    );

    // Bad input: a clear message naming the flag (usage, exit 2) or file (run error, exit 1),
    // nothing written.
    for (args, extra, needle, code) in [
        (vec!["--outputs", "rgb,depth"], None, "--focal", 2),
        (vec!["--position", "1.5"], None, "position", 2),
        (vec!["--method", "forward", "--blend", "soft"], None, "--blend", 2),
        (
            vec![],
            Some(("--right-disparity", dir.join("missing.pgm"))),
            "missing.pgm",
            1,
        ),
    ] {
        let bad = out.join("bad");
        let mut p: Vec<(&str, &Path)> = inputs
            .iter()
            .filter(|(f, _)| extra.as_ref().is_none_or(|(e, _)| e != f))
            .map(|(f, p)| (*f, p.as_path()))
            .collect();
        if let Some((f, path)) = &extra {
            p.push((f, path.as_path()));
        }
        p.push(("--out-dir", &bad));
        let mut a = vec!["--disparity-scale", "4"];
        a.extend(args);
        let o = viewsynth(&a, &p);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{a:?}: {err}");
        assert!(err.contains(needle) && !err.contains("panicked"), "{a:?}: {err}");
        assert!(!bad.exists(), "{a:?}: nothing written");
    }
}

/// Two images alone, `--matcher census`: the CLI estimates the disparities with the census
/// matcher (its GPU pass) and renders as if they had been given. Oracle: the matcher's twin's disparities (the GPU
/// pass is bit-exact with it, viewsynth_tests/tests/library/cyclopean/matcher.rs) written to files and given
/// with --left-disparity/--right-disparity must give the same files, byte for byte. Options
/// that decode disparity files, and a search range with disparities given, are usage errors.
#[test]
fn cli_two_images_alone_render_the_matchers_disparities() {
    let dir = data_dir().join("middlebury2003_cones");
    let out = out_dir("cyclopean-two-images");
    let (l, r) = (dir.join("im2.png"), dir.join("im6.png"));
    let (dl, dr) =
        viewsynth::stereo::matcher::estimate_disparities(&io::load_rgb(&l).unwrap(), &io::load_rgb(&r).unwrap(), 64)
            .unwrap();
    let (dl_file, dr_file) = (out.join("dl.npy"), out.join("dr.npy"));
    io::save_depth_npy(&dl_file, &dl).unwrap();
    io::save_depth_npy(&dr_file, &dr).unwrap();
    let (alone, given) = (out.join("alone"), out.join("given"));
    // With --confidence: the view must not change (compared with the given disparities below).
    let o = viewsynth(
        &["--max-disparity", "64", "--confidence", "--matcher", "census"],
        &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &alone)],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Each eye's confidence file holds the matcher's confidence stage: its twin on the twin's
    // disparities, within the stage's GPU-vs-twin bound (CONFIDENCE_BOUND, derived beside it in
    // viewsynth_tests/tests/library/cyclopean/matcher.rs), and exactly 0 where the disparity is unknown.
    let twin = viewsynth::stereo::matcher::confidence_reference(&dl, &dr).unwrap();
    for (name, want, d) in [
        ("left_confidence.exr", &twin.0, &dl),
        ("right_confidence.exr", &twin.1, &dr),
    ] {
        let got = io::load_depth(&alone.join(name), &io::DepthDecode::default()).unwrap();
        assert_eq!((got.width, got.height), (want.width, want.height), "{name}");
        let worst = crate::common::max_abs_difference(&got.data, &want.data);
        viewsynth_lab::eval::image_check::ensure(
            worst <= viewsynth_tests::CONFIDENCE_BOUND,
            &format!("cli confidence {name}"),
            want.width,
            want.height,
            &[(
                "confidence",
                viewsynth_lab::eval::image_check::Plane::Depth(&got.data),
                viewsynth_lab::eval::image_check::Plane::Depth(&want.data),
            )],
            format!("{name}: off the twin by up to {worst:e}"),
        );
        let unknown_nonzero = got
            .data
            .iter()
            .zip(&d.data)
            .filter(|(c, d)| **d <= 0.0 && **c != 0.0)
            .count();
        assert_eq!(unknown_nonzero, 0, "{name}: confidence where the disparity is unknown");
        assert!(
            got.data.iter().all(|c| (0.0..=1.0).contains(c)),
            "{name}: outside [0, 1]"
        );
        assert!(got.data.iter().any(|c| *c > 0.5), "{name}: no confident pixel");
    }
    let o = viewsynth(
        &[],
        &[
            ("--left-rgb", &l),
            ("--right-rgb", &r),
            ("--left-disparity", &dl_file),
            ("--right-disparity", &dr_file),
            ("--out-dir", &given),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for name in ["middle_rgb.png", "middle_mask.png"] {
        let (a, b) = (
            std::fs::read(alone.join(name)).unwrap(),
            std::fs::read(given.join(name)).unwrap(),
        );
        assert!(
            a == b,
            "{name}: two images alone differ from the matcher's disparities given as files"
        );
    }
    let usage = |args: &[&str], paths: &[(&str, &Path)]| {
        let o = viewsynth(args, paths);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let bad = out.join("bad");
    let e = usage(
        &["--max-disparity", "64"],
        &[
            ("--left-rgb", &l),
            ("--right-rgb", &r),
            ("--left-disparity", &dl_file),
            ("--right-disparity", &dr_file),
            ("--out-dir", &bad),
        ],
    );
    assert!(e.contains("--max-disparity applies to two images alone"), "{e}");
    let e = usage(
        &["--confidence"],
        &[
            ("--left-rgb", &l),
            ("--right-rgb", &r),
            ("--left-disparity", &dl_file),
            ("--right-disparity", &dr_file),
            ("--out-dir", &bad),
        ],
    );
    assert!(e.contains("--confidence applies to two images alone"), "{e}");

    // --min-confidence trades coverage for precision: fewer pixels, and those kept are the
    // ones the matcher trusts, so the view's error against im4 on them is no worse.
    let truth = io::load_rgb(&dir.join("im4.png")).unwrap();
    let mut prev: Option<(f64, f64)> = None;
    for c in ["0", "0.5", "0.9"] {
        let o_dir = out.join(format!("conf{c}"));
        let o = viewsynth(
            &["--max-disparity", "64", "--min-confidence", c, "--matcher", "census"],
            &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &o_dir)],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mask = io::load_mask_png(&o_dir.join("middle_mask.png")).unwrap();
        let seen: Vec<bool> = mask.data.iter().map(|m| *m != 0).collect();
        let rgb = io::load_rgb(&o_dir.join("middle_rgb.png")).unwrap();
        let (cover, db) = (count(&seen) as f64 / seen.len() as f64, psnr(&rgb, &truth, &seen));
        if c == "0" {
            // Confidence 0 drops only what is already unknown: the plain estimate's view.
            let plain = std::fs::read(alone.join("middle_rgb.png")).unwrap();
            assert!(
                std::fs::read(o_dir.join("middle_rgb.png")).unwrap() == plain,
                "--min-confidence 0"
            );
        }
        if let Some((c0, db0)) = prev {
            assert!(
                cover < c0,
                "--min-confidence {c}: coverage {cover:.4} not below {c0:.4}"
            );
            // The kept pixels are those seen by surfaces the matcher trusts: allow 0.1 dB of
            // the metric's own noise (fewer pixels averaged), no real loss.
            assert!(db > db0 - 0.1, "--min-confidence {c}: {db:.2} dB against {db0:.2}");
        }
        prev = Some((cover, db));
    }
    let e = usage(
        &["--min-confidence", "1.5"],
        &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &bad)],
    );
    assert!(e.contains("outside [0, 1]"), "{e}");
    let e = usage(
        &["--disparity-scale", "4"],
        &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &bad)],
    );
    assert!(e.contains("--disparity-scale decodes disparity or depth files"), "{e}");
    assert!(!bad.exists(), "a refused run writes nothing");
}

/// `--matcher sgm`: two images alone render the semi-global matcher's disparities. Oracle as
/// above: its twin's disparities given as files give the same files, byte for byte (the census
/// matcher's would not: checked, so the option is not ignored). With disparities given, or an
/// unknown name, it is a usage error.
#[test]
fn cli_two_images_alone_render_the_semi_global_matchers_disparities() {
    use viewsynth::stereo::matcher::MatcherMethod;
    let dir = data_dir().join("tsukuba_5view_no_gt");
    let out = out_dir("cyclopean-two-images-sgm");
    let (l, r) = (dir.join("tsukuba2.png"), dir.join("tsukuba4.png"));
    let (li, ri) = (io::load_rgb(&l).unwrap(), io::load_rgb(&r).unwrap());
    let mut files = Vec::new();
    let census = MatcherMethod::Census.estimate_reference(&li, &ri, 32).unwrap();
    let semi_global = MatcherMethod::Sgm.estimate_reference(&li, &ri, 32).unwrap();
    // What renders without --fill: the semi-global disparities the trust twin calls matched.
    let matched = (
        trust_reference(&semi_global.0, &census.0, &li).unwrap(),
        trust_reference(&semi_global.1, &census.1, &ri).unwrap(),
    );
    for (method, (dl, dr)) in [(MatcherMethod::Sgm, matched.clone()), (MatcherMethod::Census, census)] {
        let (dl_file, dr_file) = (
            out.join(format!("{method:?}_l.npy")),
            out.join(format!("{method:?}_r.npy")),
        );
        io::save_depth_npy(&dl_file, &dl).unwrap();
        io::save_depth_npy(&dr_file, &dr).unwrap();
        files.push((dl_file, dr_file));
    }
    let alone = out.join("alone");
    let o = viewsynth(
        &["--max-disparity", "32", "--matcher", "sgm", "--confidence"],
        &[("--left-rgb", &l), ("--right-rgb", &r), ("--out-dir", &alone)],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // An inferred disparity's confidence says so: never above INFERRED_CONFIDENCE, where the
    // confidence stage alone gives many of them more.
    let stage = viewsynth::stereo::matcher::confidence_reference(&semi_global.0, &semi_global.1).unwrap();
    let got = io::load_depth(&alone.join("left_confidence.exr"), &io::DepthDecode::default()).unwrap();
    let cap = viewsynth::cyclopean::pipeline::INFERRED_CONFIDENCE;
    let inferred: Vec<usize> = (0..got.data.len())
        .filter(|&i| semi_global.0.data[i] > 0.0 && matched.0.data[i] <= 0.0)
        .collect();
    let above = inferred.iter().filter(|&&i| stage.0.data[i] > cap + 0.01).count();
    assert!(
        above > 50,
        "{above} inferred pixels the stage alone trusts more than {cap}"
    );
    let over: Vec<&usize> = inferred.iter().filter(|&&i| got.data[i] > cap).collect();
    assert!(
        over.is_empty(),
        "{} inferred disparities above {cap}, first {:?}",
        over.len(),
        over.first()
    );
    for (k, (dl_file, dr_file)) in files.iter().enumerate() {
        let given = out.join(format!("given{k}"));
        let o = viewsynth(
            &[],
            &[
                ("--left-rgb", &l),
                ("--right-rgb", &r),
                ("--left-disparity", dl_file),
                ("--right-disparity", dr_file),
                ("--out-dir", &given),
            ],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let same = std::fs::read(alone.join("middle_rgb.png")).unwrap()
            == std::fs::read(given.join("middle_rgb.png")).unwrap();
        assert_eq!(
            same,
            k == 0,
            "the view from --matcher sgm vs the {} twin's disparities given",
            ["matched semi-global", "census"][k]
        );
    }
    let bad = out.join("bad");
    for (args, want) in [
        (&["--matcher", "sgm"][..], "--matcher applies to two images alone"),
        (&["--matcher", "bogus"][..], "bogus"),
    ] {
        let o = viewsynth(
            args,
            &[
                ("--left-rgb", &l),
                ("--right-rgb", &r),
                ("--left-disparity", &files[0].0),
                ("--right-disparity", &files[0].1),
                ("--out-dir", &bad),
            ],
        );
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(want), "{args:?}: {e}");
        assert!(!bad.exists(), "{args:?}");
    }
}
