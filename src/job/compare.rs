//! `compare`: two renderings (e.g. ours and a Vulkan renderer's) compared after converting row
//! order, NDC range, reversed-Z and device vs linear depth, with CI thresholds. The options
//! become a [`CompareJob`]; running it writes the diff image and the JSON summary when asked.

use super::error::InContext;
use super::{ArgError, Event, Host, JobError};
use crate::compare::{compare_with, Comparison, Measures, Side, Thresholds};
use crate::convention::{Conventions, DepthPlanes};
use crate::depth::DepthEncoding;
use crate::io::{self, DepthDecode};
use std::path::{Path, PathBuf};

/// What a side's depth file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SideDepth {
    /// Window depth under the side's conventions, written with the job's planes.
    Device,
    /// View distance in metres.
    #[default]
    ViewZ,
}

/// One side's files as given.
#[derive(Debug, Clone, Default)]
pub struct SideOptions {
    /// Colour.
    pub rgb: PathBuf,
    /// Depth, if compared.
    pub depth: Option<PathBuf>,
    /// What the depth holds.
    pub depth_kind: SideDepth,
    /// How the side was stored.
    pub conventions: Conventions,
}

/// Where the JSON summary goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum JsonOutput {
    /// Printed instead of the text summary.
    Stdout,
    /// Written (atomically) to this file.
    File(PathBuf),
}

/// The compare options as given.
#[derive(Debug, Clone, Default)]
pub struct CompareOptions {
    /// Side A.
    pub a: SideOptions,
    /// Side B.
    pub b: SideOptions,
    /// The `.npz` array to read (both sides).
    pub npz_key: Option<String>,
    /// Near plane of device depth.
    pub near: f64,
    /// Far plane of device depth.
    pub far: f64,
    /// Where to write the colour difference.
    pub diff: Option<PathBuf>,
    /// Where to write FLIP's magma error map.
    pub flip_map: Option<PathBuf>,
    /// Compare only where this image is nonzero.
    pub mask: Option<PathBuf>,
    /// CI limits.
    pub thresholds: Thresholds,
    /// Where the JSON summary goes.
    pub json: Option<JsonOutput>,
}

/// A checked comparison.
#[derive(Debug, Clone)]
pub struct CompareJob {
    a: SideOptions,
    b: SideOptions,
    npz_key: Option<String>,
    planes: DepthPlanes,
    diff: Option<PathBuf>,
    flip_map: Option<PathBuf>,
    mask: Option<PathBuf>,
    thresholds: Thresholds,
    json: Option<JsonOutput>,
}

/// What `--json` writes.
#[derive(serde::Serialize)]
struct Summary<'a> {
    #[serde(flatten)]
    comparison: &'a Comparison,
    thresholds: Thresholds,
    broken: &'a [String],
    passed: bool,
}

/// The comparison's result.
#[derive(Debug)]
pub struct CompareReport {
    /// Errors and the suspected convention mismatch.
    pub comparison: Comparison,
    /// The thresholds broken (empty: passed).
    pub broken: Vec<String>,
    /// The JSON summary.
    pub json: String,
}

impl CompareJob {
    /// Checks the thresholds and the depth planes.
    pub fn new(o: CompareOptions) -> Result<Self, ArgError> {
        o.thresholds.validate()?;
        let depths: Vec<&std::path::Path> = [&o.a.depth, &o.b.depth]
            .into_iter()
            .flatten()
            .map(|p| p.as_path())
            .collect();
        super::check_npz_key(o.npz_key.as_deref(), &depths)?;
        if !(o.near.is_finite() && o.near > 0.0 && o.far > o.near) {
            return Err(ArgError::ComparePlanes {
                near: o.near,
                far: o.far,
            });
        }
        let inputs: Vec<io::NamedPath<'_>> = [
            ("--a-rgb", Some(&o.a.rgb)),
            ("--a-depth", o.a.depth.as_ref()),
            ("--b-rgb", Some(&o.b.rgb)),
            ("--b-depth", o.b.depth.as_ref()),
            ("--mask", o.mask.as_ref()),
        ]
        .into_iter()
        .filter_map(|(option, p)| p.map(|p| (option, p.as_path())))
        .collect();
        let mut outputs: Vec<io::NamedPath<'_>> = o.diff.iter().map(|p| ("--diff", p.as_path())).collect();
        outputs.extend(o.flip_map.iter().map(|p| ("--flip-map", p.as_path())));
        if let Some(JsonOutput::File(p)) = &o.json {
            outputs.push(("--json", p));
        }
        io::check_outputs(&inputs, &outputs).map_err(ArgError::Invalid)?;
        Ok(CompareJob {
            a: o.a,
            b: o.b,
            npz_key: o.npz_key,
            planes: DepthPlanes {
                near: o.near,
                far: o.far,
            },
            diff: o.diff,
            flip_map: o.flip_map,
            mask: o.mask,
            thresholds: o.thresholds,
            json: o.json,
        })
    }

    /// Where the JSON summary goes.
    pub fn json(&self) -> Option<&JsonOutput> {
        self.json.as_ref()
    }

    /// Where the diff image goes.
    pub fn diff(&self) -> Option<&Path> {
        self.diff.as_deref()
    }

    /// Where FLIP's error map goes.
    pub fn flip_map(&self) -> Option<&Path> {
        self.flip_map.as_deref()
    }

    /// The limits checked.
    pub fn thresholds(&self) -> &Thresholds {
        &self.thresholds
    }

    /// Whether a mask limits the comparison.
    pub fn masked(&self) -> bool {
        self.mask.is_some()
    }

    fn side(&self, s: &SideOptions) -> crate::Result<Side> {
        Ok(Side {
            color: io::load_rgb(&s.rgb)?,
            depth: s
                .depth
                .as_deref()
                .map(|d| io::load_depth_with_key(d, self.npz_key.as_deref(), &DepthDecode::default()))
                .transpose()?,
            storage: match s.depth_kind {
                SideDepth::Device => DepthEncoding::Device { planes: self.planes },
                SideDepth::ViewZ => DepthEncoding::ViewZ,
            },
            conv: s.conventions,
        })
    }

    /// Reads both sides, compares them and writes the diff and JSON files asked for (each
    /// atomically: they name files anywhere, not an output folder). Each depth input is
    /// summarised to `host` in metres (device depth converted with the planes).
    pub fn run(&self, host: &dyn Host) -> Result<CompareReport, JobError> {
        let sa = self.side(&self.a)?;
        let sb = self.side(&self.b)?;
        for (opts, side, name) in [(&self.a, &sa, "A"), (&self.b, &sb, "B")] {
            if let (Some(path), Some(depth)) = (&opts.depth, &side.depth) {
                let hint = format!(
                    "check --{side}-depth-kind (view-z: metres; device: window depth written with \
                     --near/--far) and that {name}'s file holds depth, not disparity",
                    side = name.to_lowercase()
                );
                host.event(Event::InputDepth {
                    path,
                    summary: &side.storage.summary(&side.conv, depth),
                    hint: &hint,
                });
            }
        }
        let mask = self.mask.as_deref().map(io::load_mask_png).transpose()?;
        let measures = Measures {
            bad: self.thresholds.bad,
            flip: true,
        };
        let compared = compare_with(&sa, &sb, mask.as_ref(), measures).within(|| match &self.mask {
            Some(m) => format!("comparing A and B over {}", m.display()),
            None => "comparing A and B".to_string(),
        })?;
        let (comparison, diff) = (compared.comparison, compared.diff);
        let broken = self.thresholds.broken(&comparison);
        let summary = Summary {
            comparison: &comparison,
            thresholds: self.thresholds,
            broken: &broken,
            passed: broken.is_empty(),
        };
        let json =
            serde_json::to_string_pretty(&summary).map_err(|e| crate::Error::encode("summary", e.to_string()))?;
        // All files or none (`--diff d.png --json /nonexistent/x.json` leaves no d.png).
        let mut files: Vec<(std::path::PathBuf, io::PathWriter<'_>)> = Vec::new();
        if let Some(p) = &self.diff {
            files.push((p.clone(), Box::new(|staged: &Path| io::save_rgb(staged, &diff))));
        }
        if let (Some(p), Some(map)) = (&self.flip_map, &compared.flip_map) {
            files.push((p.clone(), Box::new(move |staged: &Path| io::save_rgb(staged, map))));
        }
        if let Some(JsonOutput::File(p)) = &self.json {
            let json = &json;
            files.push((
                p.clone(),
                Box::new(move |staged: &Path| {
                    std::fs::write(staged, json.as_bytes()).map_err(|e| crate::Error::io(staged, e))
                }),
            ));
        }
        if !files.is_empty() {
            let names: Vec<String> = files.iter().map(|(p, _)| p.display().to_string()).collect();
            io::write_paths_all_or_none(files).within(|| format!("writing {}", names.join(" and ")))?;
        }
        let json = json.clone();
        Ok(CompareReport {
            comparison,
            broken,
            json,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{ArgError, CompareJob, CompareOptions};

    #[test]
    fn planes_must_be_ordered_and_positive() {
        let options = |near, far| CompareOptions {
            near,
            far,
            ..Default::default()
        };
        assert!(CompareJob::new(options(0.1, 1000.0)).is_ok());
        assert!(CompareJob::new(options(0.1, f64::INFINITY)).is_ok());
        for (near, far) in [(0.0, 10.0), (10.0, 1.0), (f64::NAN, 1.0)] {
            assert!(matches!(
                CompareJob::new(options(near, far)),
                Err(ArgError::ComparePlanes { .. })
            ));
        }
    }
}
