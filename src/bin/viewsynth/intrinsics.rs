//! `--intrinsics FILE` and `--fx/--fy/--cx/--cy`, shared by the commands that take a pinhole
//! source camera: the file gives all four, a flag overrides its value.

use super::*;
use viewsynth::camera::IntrinsicsFile;

#[derive(Args, Clone)]
pub(crate) struct IntrinsicsArgs {
    /// Source intrinsics from a file, the format told from its content: a 3x3 K (JSON, nested
    /// or 9 numbers, or whitespace text), Open3D PinholeCameraIntrinsic JSON, Middlebury
    /// calib.txt (cam0) or COLMAP cameras.txt (PINHOLE, SIMPLE_PINHOLE). --fx/--fy/--cx/--cy
    /// given as well override single values.
    #[arg(long, value_name = "FILE")]
    pub intrinsics: Option<PathBuf>,
    /// Source focal length along x, in pixels.
    #[arg(long, value_parser = super::finite_value)]
    pub fx: Option<f64>,
    /// Source focal length along y, in pixels.
    #[arg(long, value_parser = super::finite_value)]
    pub fy: Option<f64>,
    /// Source principal point x, in pixels (OpenCV: the first pixel's centre is at 0).
    #[arg(long, value_parser = super::finite_value)]
    pub cx: Option<f64>,
    /// Source principal point y, in pixels, rows downwards (OpenCV: the first pixel's centre is at 0).
    #[arg(long, value_parser = super::finite_value)]
    pub cy: Option<f64>,
}

/// Intrinsics as given, with the file they came from (to check its image size).
pub(crate) struct SourceIntrinsics {
    pub k: Intrinsics,
    file: Option<(PathBuf, IntrinsicsFile)>,
}

impl IntrinsicsArgs {
    pub fn any_given(&self) -> bool {
        self.intrinsics.is_some() || self.fx.is_some() || self.fy.is_some() || self.cx.is_some() || self.cy.is_some()
    }

    /// The file's values with the flags laid over them; all four must end up known.
    pub fn resolve(&self) -> Result<SourceIntrinsics> {
        let file = match &self.intrinsics {
            Some(p) => Some((p.clone(), IntrinsicsFile::load(p).context("--intrinsics")?)),
            None => None,
        };
        let from_file = file.as_ref().map(|(_, f)| f.k);
        let pick = |flag: Option<f64>, stored: Option<f64>, name: &str| {
            flag.or(stored).with_context(|| {
                format!("give the source intrinsics: --intrinsics FILE or --fx --fy --cx --cy (--{name} is missing)")
            })
        };
        let k = Intrinsics {
            fx: pick(self.fx, from_file.map(|k| k.fx), "fx")?,
            fy: pick(self.fy, from_file.map(|k| k.fy), "fy")?,
            cx: pick(self.cx, from_file.map(|k| k.cx), "cx")?,
            cy: pick(self.cy, from_file.map(|k| k.cy), "cy")?,
        };
        k.validate("source intrinsics")?;
        Ok(SourceIntrinsics { k, file })
    }
}

impl SourceIntrinsics {
    /// Refuses a file written for another image size.
    pub fn check_size(&self, width: u32, height: u32) -> Result<()> {
        if let Some((path, file)) = &self.file {
            file.check_size(path, width, height).context("--intrinsics")?;
        }
        Ok(())
    }
}
