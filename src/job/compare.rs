//! `compare`: two renderings (e.g. ours and a Vulkan renderer's) compared after converting row
//! order, NDC range, reversed-Z and device vs linear depth, with CI thresholds. The options
//! become a [`CompareJob`]; running it writes the diff image and the JSON summary when asked.

use super::error::InContext;
use super::{ArgError, Event, Host, JobError};
use crate::compare::{compare_with, ColourReading, Comparison, Measures, Side, Thresholds};
use crate::convention::{Conventions, DepthPlanes, NdcDepthRange, RowOrder};
use crate::depth::DepthEncoding;
use crate::field::{Field, Message};
use crate::io::{self, DepthDecode};
use crate::msg;
use std::path::{Path, PathBuf};

/// What a side's depth file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SideDepth {
    /// Window depth in [0, 1] from a depth buffer, written with the side's planes (the same
    /// function of Z under either NDC range).
    Device,
    /// NDC z after the perspective divide (clip z / w) in the side's NDC range, written with
    /// the side's planes.
    Ndc,
    /// View distance in metres.
    #[default]
    ViewZ,
}

impl SideDepth {
    fn name(self) -> &'static str {
        match self {
            SideDepth::Device => "device",
            SideDepth::Ndc => "ndc",
            SideDepth::ViewZ => "view-z",
        }
    }
}

/// One side's files as given.
#[derive(Debug, Clone, Default)]
pub struct SideOptions {
    /// Colour.
    pub rgb: PathBuf,
    /// How the colour is stored.
    pub colour: ColourReading,
    /// Depth, if compared.
    pub depth: Option<PathBuf>,
    /// What the depth holds.
    pub depth_kind: SideDepth,
    /// Planes its device or NDC depth was written with (else [`CompareOptions::planes`]).
    pub planes: Option<DepthPlanes>,
    /// NDC range of stored NDC z ([`SideDepth::Ndc`] only: window depth is the same under both).
    pub ndc: Option<NdcDepthRange>,
    /// Its device or NDC depth was written with reversed-Z.
    pub reversed_z: bool,
    /// Row order of its files.
    pub row_order: RowOrder,
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
    /// Planes of both sides' device or NDC depth (a side's own planes take precedence).
    pub planes: Option<DepthPlanes>,
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
    /// Each side's encoding, decided from its options.
    storage: [DepthEncoding; 2],
    diff: Option<PathBuf>,
    flip_map: Option<PathBuf>,
    mask: Option<PathBuf>,
    thresholds: Thresholds,
    json: Option<JsonOutput>,
}

/// How one side was read, as the JSON records it: the figures hold under these conventions.
#[derive(serde::Serialize)]
struct SideReading {
    /// Channel order, transfer and alpha of its colour.
    colour: ColourReading,
    /// What its depth holds ("view-z", "device", "ndc"); None without a depth file.
    depth_kind: Option<&'static str>,
    /// Near plane of its device or NDC depth.
    near: Option<f64>,
    /// Far plane of its device or NDC depth ("inf" when infinite).
    #[serde(serialize_with = "crate::compare::optional_infinite_as_string")]
    far: Option<f64>,
    /// NDC range of stored NDC z, as `--X-ndc` names it (the only depth it changes).
    ndc: Option<&'static str>,
    /// Reversed-Z device or NDC depth.
    reversed_z: bool,
    /// Row order of its files.
    rows: RowOrder,
}

impl SideReading {
    fn of(o: &SideOptions, storage: DepthEncoding) -> Self {
        let planes = match storage {
            DepthEncoding::Device { planes } => Some(planes),
            _ => None,
        };
        SideReading {
            colour: o.colour,
            depth_kind: o.depth.as_ref().map(|_| o.depth_kind.name()),
            near: planes.map(|p| p.near),
            far: planes.map(|p| p.far),
            ndc: (o.depth_kind == SideDepth::Ndc).then(|| match o.ndc.unwrap_or_default() {
                NdcDepthRange::MinusOneToOne => "gl",
                NdcDepthRange::ZeroToOne => "vulkan",
            }),
            reversed_z: o.reversed_z,
            rows: o.row_order,
        }
    }
}

/// What `--json` writes.
#[derive(serde::Serialize)]
struct Summary<'a> {
    #[serde(flatten)]
    comparison: &'a Comparison,
    /// How A was read.
    a: SideReading,
    /// How B was read.
    b: SideReading,
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
        let storage = [side_storage('A', &o.a, o.planes)?, side_storage('B', &o.b, o.planes)?];
        if o.planes.is_some() && storage.iter().all(|s| !matches!(s, DepthEncoding::Device { .. })) {
            return Err(ArgError::CompareNotApplicable {
                option: msg![Field::Near, "/", Field::Far],
                why: "neither side's depth is device or ndc depth (view-z is metres: no planes)".into(),
            });
        }
        let inputs: Vec<crate::output::NamedPath<'_>> = [
            (crate::Field::ARgb.into(), Some(&o.a.rgb)),
            (crate::Field::ADepth.into(), o.a.depth.as_ref()),
            (crate::Field::BRgb.into(), Some(&o.b.rgb)),
            (crate::Field::BDepth.into(), o.b.depth.as_ref()),
            (crate::Field::Mask.into(), o.mask.as_ref()),
        ]
        .into_iter()
        .filter_map(|(option, p)| p.map(|p| (option, p.as_path())))
        .collect();
        let mut outputs: Vec<crate::output::NamedPath<'_>> = o
            .diff
            .iter()
            .map(|p| (crate::Field::Diff.into(), p.as_path()))
            .collect();
        outputs.extend(o.flip_map.iter().map(|p| (crate::Field::FlipMap.into(), p.as_path())));
        if let Some(JsonOutput::File(p)) = &o.json {
            outputs.push((crate::Field::Json.into(), p));
        }
        crate::output::check_outputs(&inputs, &outputs).map_err(ArgError::Invalid)?;
        Ok(CompareJob {
            a: o.a,
            b: o.b,
            npz_key: o.npz_key,
            storage,
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

    fn side(&self, s: &SideOptions, storage: DepthEncoding) -> crate::Result<Side> {
        Ok(Side {
            color: io::load_colour(&s.rgb)?,
            colour: s.colour,
            depth: s
                .depth
                .as_deref()
                .map(|d| io::load_depth_with_key(d, self.npz_key.as_deref(), &DepthDecode::default()))
                .transpose()?,
            storage,
            ndc_z: s.depth_kind == SideDepth::Ndc,
            conv: Conventions {
                ndc_depth: s.ndc.unwrap_or_default(),
                reversed_z: s.reversed_z,
                row_order: s.row_order,
            },
        })
    }

    /// Reads both sides, compares them and writes the diff and JSON files asked for (each
    /// atomically: they name files anywhere, not an output folder). Each depth input is
    /// summarised to `host` in metres (device depth converted with the planes).
    pub fn run(&self, host: &dyn Host) -> Result<CompareReport, JobError> {
        let sa = self.side(&self.a, self.storage[0])?;
        let sb = self.side(&self.b, self.storage[1])?;
        for (opts, side, name) in [(&self.a, &sa, 'A'), (&self.b, &sb, 'B')] {
            if let (Some(path), Some(depth)) = (&opts.depth, &side.depth) {
                let f = SideFields::of(name);
                let window = msg![f.depth_kind, " device ", f.near, " N ", f.far, " F"];
                let hint = msg![
                    format!("check what {name}'s file holds: metres (`"),
                    f.depth_kind,
                    " view-z`), window depth (`",
                    &window,
                    "`, far may be inf; reversed: `",
                    &window,
                    " ",
                    f.reversed_z,
                    "`), and that it is depth, not disparity"
                ];
                host.event(Event::InputDepth {
                    path,
                    summary: &side.storage.summary(&side.conv, &side_window_depth(side, depth)),
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
            a: SideReading::of(&self.a, self.storage[0]),
            b: SideReading::of(&self.b, self.storage[1]),
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

/// The side's depth as window depth (NDC z converted), for its summary.
fn side_window_depth(side: &Side, depth: &io::DepthMap) -> io::DepthMap {
    if !side.ndc_z {
        return depth.clone();
    }
    io::DepthMap {
        width: depth.width,
        height: depth.height,
        data: depth
            .data
            .iter()
            .map(|v| crate::depth::window_depth_of_ndc_z(f64::from(*v), &side.conv) as f32)
            .collect(),
    }
}

/// A side's depth encoding from its options, refusing every convention option that cannot
/// change its reading: planes, `ndc` and reversed-Z on metric depth (or none), the NDC range on
/// window depth (the same function of Z under either range), premultiplied alpha nowhere to
/// apply is checked on reading (the file decides).
fn side_storage(name: char, o: &SideOptions, both: Option<DepthPlanes>) -> Result<DepthEncoding, ArgError> {
    let f = SideFields::of(name);
    let not_applicable = |option: Message, why: Message| Err(ArgError::CompareNotApplicable { option, why });
    let kind = o.depth_kind;
    if o.depth.is_none() {
        if o.planes.is_some() || o.reversed_z || o.ndc.is_some() || kind != SideDepth::ViewZ {
            return not_applicable(
                msg![f.depth_kind, "/", f.near, "/", f.far, "/", f.reversed_z, "/", f.ndc],
                msg![format!("{name} has no depth file ("), f.depth, ")"],
            );
        }
        return Ok(DepthEncoding::ViewZ);
    }
    match kind {
        SideDepth::ViewZ => {
            let metric = msg![
                format!("{name}'s depth is view-z, metres ("),
                f.depth_kind,
                " device or ndc for device depth)"
            ];
            if o.planes.is_some() {
                return not_applicable(msg![f.near, "/", f.far], metric);
            }
            if o.reversed_z {
                return not_applicable(f.reversed_z.into(), metric);
            }
            if o.ndc.is_some() {
                return not_applicable(f.ndc.into(), metric);
            }
            Ok(DepthEncoding::ViewZ)
        }
        SideDepth::Device | SideDepth::Ndc => {
            if kind == SideDepth::Device && o.ndc.is_some() {
                return not_applicable(
                    f.ndc.into(),
                    msg![
                        format!(
                            "window depth in [0, 1] is the same function of Z under gl and vulkan NDC for the \
                             same planes, so it cannot change {name}'s reading; it applies to NDC z stored ("
                        ),
                        f.depth_kind,
                        " ndc)"
                    ],
                );
            }
            if kind == SideDepth::Ndc && o.ndc.is_none() {
                return not_applicable(
                    msg![f.depth_kind, " ndc"],
                    msg![
                        "needs the NDC range the z was written in: ",
                        f.ndc,
                        " gl or ",
                        f.ndc,
                        " vulkan"
                    ],
                );
            }
            let planes = o.planes.or(both).ok_or(ArgError::ComparePlanesMissing {
                side: name,
                kind: kind.name(),
            })?;
            if !(planes.near.is_finite() && planes.near > 0.0 && planes.far > planes.near) {
                let options = match o.planes.is_some() {
                    true => msg![f.near, "/", f.far],
                    false => msg![Field::Near, "/", Field::Far],
                };
                return Err(ArgError::ComparePlanes {
                    options,
                    near: planes.near,
                    far: planes.far,
                });
            }
            Ok(DepthEncoding::Device { planes })
        }
    }
}

/// The convention options of one compare side (`A` or `B`).
struct SideFields {
    depth: Field,
    depth_kind: Field,
    near: Field,
    far: Field,
    reversed_z: Field,
    ndc: Field,
}

impl SideFields {
    fn of(side: char) -> Self {
        match side {
            'A' => SideFields {
                depth: Field::ADepth,
                depth_kind: Field::ADepthKind,
                near: Field::ANear,
                far: Field::AFar,
                reversed_z: Field::AReversedZ,
                ndc: Field::ANdc,
            },
            _ => SideFields {
                depth: Field::BDepth,
                depth_kind: Field::BDepthKind,
                near: Field::BNear,
                far: Field::BFar,
                reversed_z: Field::BReversedZ,
                ndc: Field::BNdc,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{ArgError, CompareJob, CompareOptions, SideDepth, SideOptions};
    use crate::convention::{DepthPlanes, NdcDepthRange};

    fn device(planes: Option<DepthPlanes>) -> SideOptions {
        SideOptions {
            depth: Some("d.exr".into()),
            depth_kind: SideDepth::Device,
            planes,
            ..Default::default()
        }
    }

    fn job(a: SideOptions, b: SideOptions, planes: Option<DepthPlanes>) -> Result<CompareJob, ArgError> {
        CompareJob::new(CompareOptions {
            a: SideOptions {
                rgb: "a.png".into(),
                ..a
            },
            b: SideOptions {
                rgb: "b.png".into(),
                ..b
            },
            planes,
            ..Default::default()
        })
    }

    #[test]
    fn planes_must_be_ordered_and_positive_and_far_may_be_infinite() {
        let p = |near, far| Some(DepthPlanes { near, far });
        assert!(job(device(p(0.1, 1000.0)), device(p(0.05, f64::INFINITY)), None).is_ok());
        assert!(job(device(None), device(None), p(0.1, f64::INFINITY)).is_ok());
        for (near, far) in [(0.0, 10.0), (10.0, 1.0), (f64::NAN, 1.0)] {
            assert!(matches!(
                job(device(p(near, far)), device(p(0.1, 1.0)), None),
                Err(ArgError::ComparePlanes { .. })
            ));
        }
    }

    #[test]
    fn device_depth_needs_planes_and_each_option_must_apply() {
        let p = Some(DepthPlanes { near: 0.1, far: 10.0 });
        // No silent default planes.
        let e = job(device(p), device(None), None).unwrap_err();
        assert!(matches!(e, ArgError::ComparePlanesMissing { side: 'B', .. }), "{e}");
        assert!(e.to_string().contains("--b-near N --b-far F"), "{e}");
        let metric = SideOptions {
            depth: Some("d.exr".into()),
            ..Default::default()
        };
        // Planes, reversed-Z and the NDC range on metric depth; the NDC range on window depth.
        for (b, option) in [
            (
                SideOptions {
                    planes: p,
                    ..metric.clone()
                },
                "--b-near/--b-far",
            ),
            (
                SideOptions {
                    reversed_z: true,
                    ..metric.clone()
                },
                "--b-reversed-z",
            ),
            (
                SideOptions {
                    ndc: Some(NdcDepthRange::ZeroToOne),
                    ..device(p)
                },
                "--b-ndc",
            ),
        ] {
            let e = job(metric.clone(), b, None).unwrap_err();
            assert!(
                matches!(&e, ArgError::CompareNotApplicable { option: o, .. } if o.to_string() == option)
                    && e.is_usage(),
                "{option}: {e}"
            );
        }
        assert!(
            job(metric.clone(), metric.clone(), p).is_err(),
            "--near/--far with no device side"
        );
        // Stored NDC z needs its range, and takes it.
        let ndc = SideOptions {
            depth_kind: SideDepth::Ndc,
            ..device(p)
        };
        assert!(job(metric.clone(), ndc.clone(), None).is_err());
        let gl = SideOptions {
            ndc: Some(NdcDepthRange::MinusOneToOne),
            ..ndc
        };
        assert!(job(metric, gl, None).is_ok());
    }
}
