//! `--intrinsics FILE` and `--fx/--fy/--cx/--cy`, shared by the commands that take a pinhole
//! source camera (the library resolves them: `viewsynth::job::SourceIntrinsics`).

use clap::Args;
use std::path::PathBuf;
use viewsynth::job::finite_value;

#[derive(Args, Clone)]
#[command(next_help_heading = super::INTRINSICS)]
pub(crate) struct IntrinsicsArgs {
    /// Source intrinsics from a file, the format told from its content: a 3x3 K (JSON, nested or 9
    /// numbers, or whitespace text), Open3D PinholeCameraIntrinsic JSON, Middlebury calib.txt
    /// (cam0) or COLMAP cameras.txt (PINHOLE, SIMPLE_PINHOLE).
    ///
    /// --fx/--fy/--cx/--cy given as well override single values.
    #[arg(long, value_name = "FILE")]
    pub intrinsics: Option<PathBuf>,
    /// Source focal length along x, in pixels.
    #[arg(long, value_parser = finite_value)]
    pub fx: Option<f64>,
    /// Source focal length along y, in pixels.
    #[arg(long, value_parser = finite_value)]
    pub fy: Option<f64>,
    /// Source principal point x, in pixels (OpenCV: the first pixel's centre is at 0).
    #[arg(long, value_parser = finite_value)]
    pub cx: Option<f64>,
    /// Source principal point y, in pixels, rows downwards (OpenCV: the first pixel's centre is at 0).
    #[arg(long, value_parser = finite_value)]
    pub cy: Option<f64>,
}

impl IntrinsicsArgs {
    /// `--fx --fy --cx --cy` in that order.
    pub(crate) fn values(&self) -> [Option<f64>; 4] {
        [self.fx, self.fy, self.cx, self.cy]
    }
}
