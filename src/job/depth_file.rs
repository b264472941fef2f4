//! One depth file read back as view Z in metres under the rules the commands apply to their
//! inputs (Python's `read_depth`): integer samples need their scale (`--depth-scale`), device
//! depth needs the planes it was written with and is decoded through them. Nothing is assumed:
//! a 16-bit PNG read as millimetres by default turned a TUM frame (5000 units per metre) into
//! one five times too far.

use super::reproject::{device_depth, SourceDepth};
use super::ArgError;
use crate::convention::Conventions;
use crate::depth::DepthEncoding;
use crate::io::{self, DepthDecode, DepthMap};
use std::path::Path;

/// How a depth file is to be read, as given.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DepthFileRequest {
    /// Raw units per metre of integer samples (required for them); divides float samples.
    pub depth_scale: Option<f64>,
    /// What the file holds: view Z (metres once scaled) or device depth.
    pub depth_kind: SourceDepth,
    /// Near plane the device depth was written with.
    pub near: Option<f64>,
    /// Far plane the device depth was written with (may be infinite).
    pub far: Option<f64>,
}

/// A checked [`DepthFileRequest`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthFileReading {
    decode: DepthDecode,
    encoding: DepthEncoding,
}

impl DepthFileRequest {
    /// Checks the options against each other: planes with device depth only (and always with
    /// it), a scale finite and > 0, no disparity (it needs a camera to become metres).
    pub fn check(&self) -> Result<DepthFileReading, ArgError> {
        super::cyclopean::check_scale(crate::Field::DepthScale, self.depth_scale)?;
        let encoding = match self.depth_kind {
            SourceDepth::ViewZ => {
                if self.near.is_some() || self.far.is_some() {
                    return Err(ArgError::PlanesWithoutDevice);
                }
                DepthEncoding::ViewZ
            }
            SourceDepth::Device => device_depth(self.near, self.far, "the file")?,
            SourceDepth::Disparity => {
                return Err(ArgError::Invalid(crate::Error::param(
                    crate::Field::DepthKind,
                    "disparity becomes metres only with a focal length and baseline: read it as \
                     stored (view-z with no depth-scale) or reproject it with them",
                )))
            }
        };
        Ok(DepthFileReading {
            decode: DepthDecode {
                scale: self.depth_scale,
                ..Default::default()
            },
            encoding,
        })
    }
}

impl DepthFileReading {
    /// Reads `path` as view Z in metres (0 where invalid or background). Device depth is
    /// decoded under the default conventions (GL NDC, standard Z), as Python's `reproject`.
    pub fn read(&self, path: &Path) -> crate::Result<DepthMap> {
        let stored = io::load_depth(path, &self.decode)?;
        Ok(match self.encoding {
            DepthEncoding::ViewZ => stored,
            encoding => encoding.view_z_map(&Conventions::default(), &stored),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convention::DepthPlanes;

    fn png16(dir: &Path, raw: &[u16]) -> std::path::PathBuf {
        let path = dir.join("d.png");
        image::ImageBuffer::<image::Luma<u16>, _>::from_raw(raw.len() as u32, 1, raw.to_vec())
            .unwrap()
            .save(&path)
            .unwrap();
        path
    }

    #[test]
    fn integer_depth_without_its_scale_is_refused_naming_the_option() {
        let dir = crate::io::test_util::scratch_dir("depth-file-scale");
        let path = png16(&dir, &[12_075, 0]);
        let reading = DepthFileRequest::default().check().unwrap();
        let e = reading.read(&path).unwrap_err().to_string();
        assert!(e.contains("--depth-scale") && e.contains("5000 for TUM"), "{e}");
        let tum = DepthFileRequest {
            depth_scale: Some(5000.0),
            ..Default::default()
        };
        assert_eq!(tum.check().unwrap().read(&path).unwrap().data, [2.415, 0.0]);
        for bad in [0.0, -5000.0, f64::NAN, f64::INFINITY] {
            let r = DepthFileRequest {
                depth_scale: Some(bad),
                ..Default::default()
            };
            assert!(matches!(
                r.check(),
                Err(ArgError::Scale {
                    option: crate::Field::DepthScale,
                    ..
                })
            ));
        }
    }

    #[test]
    fn device_depth_is_decoded_with_its_planes_or_refused() {
        let planes = DepthPlanes { near: 0.1, far: 100.0 };
        let device = DepthEncoding::Device { planes };
        let conv = Conventions::default();
        let stored = [device.encode(&conv, 2.0, 1.0) as f32, 1.0];
        let dir = crate::io::test_util::scratch_dir("depth-file-device");
        let path = dir.join("d.npy");
        io::save_depth_npy(&path, &DepthMap::new(2, 1, stored.to_vec()).unwrap()).unwrap();
        let r = DepthFileRequest {
            depth_kind: SourceDepth::Device,
            near: Some(0.1),
            far: Some(100.0),
            ..Default::default()
        };
        let z = r.check().unwrap().read(&path).unwrap().data;
        // Window depth in f32 near 1 holds ~6e-8; at 2 m of a 0.1-100 m range that is ~2.4e-6 m.
        assert!((z[0] - 2.0).abs() < 1e-4 && z[1] == 0.0, "{z:?}");
        let no_planes = DepthFileRequest {
            depth_kind: SourceDepth::Device,
            ..Default::default()
        };
        assert!(matches!(no_planes.check(), Err(ArgError::DevicePlanesMissing(_))));
        let stray = DepthFileRequest {
            near: Some(0.1),
            far: Some(100.0),
            ..Default::default()
        };
        assert!(matches!(stray.check(), Err(ArgError::PlanesWithoutDevice)));
        let disparity = DepthFileRequest {
            depth_kind: SourceDepth::Disparity,
            ..Default::default()
        };
        assert!(disparity.check().is_err());
    }
}
