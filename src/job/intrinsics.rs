//! The source camera's intrinsics from `--intrinsics FILE` and `--fx/--fy/--cx/--cy`: the file
//! gives all four, a flag overrides its value, and all four must end up known and valid.

use super::error::OptionsContext;
use super::ArgError;
use crate::camera::{Intrinsics, IntrinsicsFile};
use std::path::{Path, PathBuf};

/// Intrinsics as resolved, with the file they came from (its image size is checked against
/// the source image once that is read).
#[derive(Debug, Clone)]
pub struct SourceIntrinsics {
    /// The intrinsics, OpenCV convention.
    pub k: Intrinsics,
    file: Option<(PathBuf, IntrinsicsFile)>,
}

impl SourceIntrinsics {
    /// The file's values (when `file` is given) with the flags laid over them.
    pub fn resolve(file: Option<&Path>, flags: [Option<f64>; 4]) -> Result<Self, ArgError> {
        let file = match file {
            Some(p) => Some((
                p.to_path_buf(),
                IntrinsicsFile::load(p).for_options(crate::Field::Intrinsics)?,
            )),
            None => None,
        };
        let stored = file.as_ref().map(|(_, f)| f.k);
        let [fx, fy, cx, cy] = flags;
        let pick = |flag: Option<f64>, stored: Option<f64>, name: crate::Field| {
            flag.or(stored).ok_or(ArgError::MissingIntrinsic(name))
        };
        let k = Intrinsics {
            fx: pick(fx, stored.map(|k| k.fx), crate::Field::Fx)?,
            fy: pick(fy, stored.map(|k| k.fy), crate::Field::Fy)?,
            cx: pick(cx, stored.map(|k| k.cx), crate::Field::Cx)?,
            cy: pick(cy, stored.map(|k| k.cy), crate::Field::Cy)?,
        };
        k.validate("source intrinsics")?;
        Ok(SourceIntrinsics { k, file })
    }

    /// Refuses a file written for another image size.
    pub fn check_size(&self, width: u32, height: u32) -> Result<(), ArgError> {
        if let Some((path, file)) = &self.file {
            file.check_size(path, width, height)
                .for_options(crate::Field::Intrinsics)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::SourceIntrinsics;

    #[test]
    fn every_intrinsic_must_be_given() {
        let e = SourceIntrinsics::resolve(None, [Some(1.0), Some(1.0), None, Some(1.0)]).unwrap_err();
        assert!(e.to_string().contains("(--cx is missing)"), "{e}");
        let k = SourceIntrinsics::resolve(None, [Some(2.0), Some(3.0), Some(4.0), Some(5.0)]).unwrap();
        assert_eq!((k.k.fx, k.k.cy), (2.0, 5.0));
        assert!(SourceIntrinsics::resolve(None, [Some(0.0), Some(1.0), Some(1.0), Some(1.0)]).is_err());
    }
}
