//! Both eyes' disparities of a rectified pair by the matchers' CPU twins, as .npy files, for the
//! lab's experiments on the disparities themselves (lab/scripts/segment_filter.py): what the
//! GPU matcher computes bit for bit, without rendering.
//!
//! Usage: cargo run --release -p viewsynth-lab --example twin_disparities -- LEFT RIGHT MAX_DISPARITY OUT_PREFIX
//! writes OUT_PREFIX_{sgm,census}_{left,right}.npy (float32, 0 = unknown; search 0..=MAX_DISPARITY).

use std::process::ExitCode;

use viewsynth::io::{load_rgb, save_depth_npy};
use viewsynth::stereo::matcher::{estimate_disparities, estimate_disparities_sgm};

fn run(args: &[String], max_disparity: u32) -> viewsynth::Result<()> {
    let (left, right) = (load_rgb(args[0].as_ref())?, load_rgb(args[1].as_ref())?);
    let prefix = &args[3];
    let (sl, sr) = estimate_disparities_sgm(&left, &right, max_disparity)?;
    let (cl, cr) = estimate_disparities(&left, &right, max_disparity)?;
    for (name, map) in [
        ("sgm_left", sl),
        ("sgm_right", sr),
        ("census_left", cl),
        ("census_right", cr),
    ] {
        save_depth_npy(format!("{prefix}_{name}.npy").as_ref(), &map)?;
    }
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(max_disparity) = args.get(2).and_then(|m| m.parse().ok()).filter(|_| args.len() == 4) else {
        eprintln!("usage: twin_disparities LEFT RIGHT MAX_DISPARITY OUT_PREFIX (MAX_DISPARITY a count)");
        return ExitCode::from(2);
    };
    match run(&args, max_disparity) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
