//! `manifest`: a `refocus --batch` manifest from a TUM-style sequence (`rgb.txt` and
//! `depth.txt`, each colour frame paired with the depth frame nearest in time), with the
//! dataset's intrinsics and depth scale on every row. The file is written whole or not at all.

use super::{ArgError, SourceIntrinsics};
use crate::refocus::batch::{associate_tum, write_manifest_csv};
use std::path::PathBuf;

/// A checked `manifest` job.
#[derive(Debug, Clone)]
pub struct TumManifestJob {
    /// The sequence folder: the listings' paths are relative to it.
    pub sequence: PathBuf,
    /// The colour listing (`SEQUENCE/rgb.txt` by default).
    pub rgb_list: PathBuf,
    /// The depth listing (`SEQUENCE/depth.txt` by default).
    pub depth_list: PathBuf,
    /// The dataset's intrinsics, written on every row.
    pub intrinsics: SourceIntrinsics,
    /// Stored depth units per metre (TUM: 5000).
    pub depth_scale: f64,
    /// Largest time between a paired colour and depth frame, seconds (TUM: 0.02).
    pub max_difference: f64,
    /// The CSV manifest to write.
    pub out: PathBuf,
}

/// What a `manifest` run made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TumManifestReport {
    /// Frames written (pairs).
    pub frames: usize,
    /// Frames the colour and the depth listing name.
    pub listed: (usize, usize),
}

impl TumManifestJob {
    /// Checks the numbers (a usage error names the option); the listings are read by [`run`].
    ///
    /// [`run`]: TumManifestJob::run
    pub fn new(
        sequence: PathBuf,
        lists: (Option<PathBuf>, Option<PathBuf>),
        intrinsics: SourceIntrinsics,
        depth_scale: f64,
        max_difference: f64,
        out: PathBuf,
    ) -> Result<Self, ArgError> {
        let positive = |name: crate::Field, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(ArgError::Invalid(crate::Error::param(
                    name,
                    format!("{v}: must be above 0"),
                )))
            }
        };
        positive(crate::Field::DepthScale, depth_scale)?;
        positive(crate::Field::MaxDifference, max_difference)?;
        let (rgb_list, depth_list) = lists;
        let rgb_list = rgb_list.unwrap_or_else(|| sequence.join("rgb.txt"));
        let depth_list = depth_list.unwrap_or_else(|| sequence.join("depth.txt"));
        // The one output rule of every command: --out never replaces a listing it reads.
        crate::output::check_outputs(
            &[
                (crate::Field::RgbList.into(), rgb_list.as_path()),
                (crate::Field::DepthList.into(), depth_list.as_path()),
            ],
            &[(crate::Field::Out.into(), out.as_path())],
        )
        .map_err(ArgError::Invalid)?;
        Ok(TumManifestJob {
            rgb_list,
            depth_list,
            sequence,
            intrinsics,
            depth_scale,
            max_difference,
            out,
        })
    }

    /// Pairs the listings and writes the manifest.
    pub fn run(&self) -> crate::Result<TumManifestReport> {
        let a = associate_tum(
            &self.sequence,
            &self.rgb_list,
            &self.depth_list,
            self.intrinsics.k,
            self.depth_scale,
            self.max_difference,
        )?;
        // Nor a frame the listings name (known only once they are read: a run error).
        let frames: Vec<crate::output::NamedPath<'_>> = a
            .frames
            .iter()
            .flat_map(|f| {
                [
                    ("rgb.txt".into(), f.rgb.as_path()),
                    ("depth.txt".into(), f.depth.as_path()),
                ]
            })
            .collect();
        crate::output::check_outputs(&frames, &[(crate::Field::Out.into(), self.out.as_path())])?;
        write_manifest_csv(&self.out, &a.frames)?;
        Ok(TumManifestReport {
            frames: a.frames.len(),
            listed: a.listed,
        })
    }
}
