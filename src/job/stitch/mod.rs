//! `stitch`: an omni-directional stereo (ODS) 360 equirect, top-bottom, from six over-wide cube
//! faces per eye (the built-in scene's, or a face folder). The options become a [`StitchJob`];
//! running it writes the image(s) all-or-none and, with the built-in scene, scores them
//! against the ray-traced ODS truth.

mod request;

pub use request::{Ndc, StitchPlan, StitchRequest};

use super::error::InContext;
use super::{ArgError, Backend, Event, GpuRequest, Host, JobError};
use crate::convention::Conventions;
use crate::depth::DepthEncoding;
use crate::io::{self, DepthDecode, DepthMap, DepthSummary, RgbImage};
use crate::pass::Timing;
use crate::stitch::faces::{load_face_dir, scene_faces, FaceDepthFiles, FACE_TAGS};
use crate::stitch::render::StitchRenderer;
use crate::stitch::score::{score_eyes, split_top_bottom, StitchScore};
use crate::stitch::truth::ods_truth;
use crate::stitch::{seam_band_mask, FaceSet, OdsRig, Side, StitchParams};
use crate::view::ViewOutput;
use std::path::PathBuf;
use std::time::Instant;

/// What to check when the face depth looks wrongly decoded.
fn face_depth_hint() -> crate::Message {
    crate::msg![
        "check ",
        crate::Field::DepthScale,
        " (raw units per metre of integer files) and ",
        crate::Field::DepthKind,
        " (view-z, or device with the ",
        crate::Field::Near,
        "/",
        crate::Field::Far,
        " and conventions the faces were written with)"
    ]
}

/// An eye's six face depths (view Z, metres) stacked top to bottom: one summary per eye, since
/// every face is decoded with the same options, and a face that sees only sky (no valid depth)
/// is normal, not a sign of a wrong decoding (nor is a mostly-sky eye: the summary is marked
/// background-expected).
fn stacked_depth(set: &FaceSet) -> DepthMap {
    DepthMap {
        width: set.size(),
        height: set.size() * set.faces.len() as u32,
        data: set.faces.iter().flat_map(|f| f.depth.data.iter().copied()).collect(),
    }
}

/// The stitched images: `{name}.png`, and with depth asked for `{name}_depth.exr`.
const OUTPUT_NAMES: [&str; 3] = ["ods_top_bottom", "ods_left", "ods_right"];

/// The files of the stitched image `stem` (one of [`OUTPUT_NAMES`]).
fn view_names(stem: &str) -> crate::output::ViewNames {
    crate::output::ViewNames::named(stem, &format!("{stem}_depth"))
}

/// Refuses a face folder whose files an output would replace: a face file under an output's
/// name in the out-dir, or one an output's name already is (a hard link, a symlink). Every
/// regular file of the folder whose name is a face's counts (the files are chosen by
/// extension when the run reads them).
fn check_faces_against_outputs(faces: &std::path::Path, out_dir: &std::path::Path) -> Result<(), ArgError> {
    let is_face = |name: &str| {
        ["left_", "right_"].iter().any(|eye| {
            name.strip_prefix(eye).is_some_and(|rest| {
                FACE_TAGS
                    .iter()
                    .any(|t| rest.strip_prefix(t).is_some_and(|r| r.starts_with(['.', '_'])))
            })
        })
    };
    // An unreadable folder is reported where the run reads its faces.
    let Ok(entries) = std::fs::read_dir(faces) else {
        return Ok(());
    };
    let files: Vec<PathBuf> = entries
        .flatten()
        .filter(|e| e.file_name().to_str().is_some_and(is_face))
        .map(|e| e.path())
        .collect();
    let inputs: Vec<crate::output::NamedPath<'_>> = files
        .iter()
        .map(|p| (crate::Field::Faces.into(), p.as_path()))
        .collect();
    let writes = |name: &str| OUTPUT_NAMES.iter().any(|n| view_names(n).may_write(name));
    crate::output::check_out_dir(out_dir, writes, &replaced(), &inputs).map_err(ArgError::Invalid)
}

/// What face depth files hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FaceDepth {
    /// View-space Z in metres.
    #[default]
    ViewZ,
    /// Window depth written with `--near/--far`.
    Device,
}

/// The stitch options as given: where the faces come from, how to decode them, the request.
#[derive(Debug, Clone)]
pub struct StitchOptions {
    /// A built-in scene to ray-trace the faces of (only `demo`).
    pub scene: Option<String>,
    /// A folder with the 12 faces.
    pub faces: Option<PathBuf>,
    /// Face side with the scene.
    pub face_size: u32,
    /// Raw units per metre for integer face depth.
    pub depth_scale: Option<f64>,
    /// The array of `.npz` face depth files to read (default: the only, else the first float one).
    pub npz_key: Option<String>,
    /// Every setting the Python binding gives too.
    pub request: StitchRequest,
    /// Memory row order of the pass.
    pub rows: crate::convention::RowOrder,
    /// Also write each eye's equirect.
    pub per_eye: bool,
    /// Score against the ray-traced ODS truth.
    pub truth: bool,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The GPU to render on.
    pub gpu: GpuRequest,
    /// `--backend`: the API the passes run on.
    pub backend: Backend,
}

/// A checked stitch.
#[derive(Debug, Clone)]
pub struct StitchJob {
    faces: Option<PathBuf>,
    face_size: u32,
    fov: f64,
    rig: OdsRig,
    params: StitchParams,
    decode: DepthDecode,
    npz_key: Option<String>,
    depth_kind: DepthEncoding,
    conventions: Conventions,
    outputs: crate::output::OutputSet,
    per_eye: bool,
    truth: bool,
    out_dir: PathBuf,
    gpu: GpuRequest,
    backend: Backend,
}

/// The stitched image against the ODS truth.
#[derive(Debug, Clone, Copy)]
pub struct TruthScore {
    /// Time to ray-trace the truth.
    pub truth_ms: f64,
    /// Errors on the seam band and the whole image.
    pub score: StitchScore,
}

/// What a stitch did and wrote.
#[derive(Debug)]
pub struct StitchReport {
    /// Where the faces came from, e.g. "loaded 12 faces of 512x512 from DIR".
    pub source: String,
    /// Face field of view, degrees.
    pub fov: f64,
    /// Time to make or load the faces.
    pub faces_ms: f64,
    /// Upload and shader compile.
    pub setup_ms: f64,
    /// The rig.
    pub rig: OdsRig,
    /// Method, overlap and size per eye.
    pub params: StitchParams,
    /// Top-bottom image size.
    pub image_size: (u32, u32),
    /// Render time.
    pub timing: Timing,
    /// With `--truth`.
    pub truth: Option<TruthScore>,
    /// The files written.
    pub written: Vec<PathBuf>,
}

impl StitchJob {
    /// Checks the options against each other and the library's rules.
    pub fn new(o: StitchOptions) -> Result<Self, ArgError> {
        o.gpu.check_backend(o.backend)?;
        // Face files are named by the folder, found while running; an empty key, or a key with
        // the built-in scene (no depth files at all), is wrong on the command line.
        super::check_npz_key(o.npz_key.as_deref(), &[])?;
        if o.npz_key.is_some() && o.faces.is_none() {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::NpzKey,
                crate::msg![
                    "applies to ",
                    crate::Field::Faces,
                    " depth files only (the built-in scene has none)"
                ],
            )));
        }
        let base = match &o.scene {
            Some(name) if name == "demo" => OdsRig::demo(),
            Some(name) => return Err(ArgError::StitchScene(name.clone())),
            // The circle centre only translates the face eyes and the ODS rays together.
            None => OdsRig {
                centre: [0.0; 3],
                ..OdsRig::demo()
            },
        };
        let StitchPlan {
            fov,
            rig,
            params,
            depth_kind,
            conventions,
            outputs,
        } = o.request.plan(base, o.rows)?;
        if o.truth && o.scene.is_none() {
            return Err(ArgError::TruthWithoutScene);
        }
        if o.truth && !outputs.rgb {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::Truth,
                crate::msg!["scores the colour image: add rgb to ", crate::Field::Outputs],
            )));
        }
        if o.faces.is_none() && o.request.depth_kind != FaceDepth::ViewZ {
            return Err(ArgError::FaceDepthKindWithoutFaces);
        }
        super::cyclopean::check_scale(crate::Field::DepthScale, o.depth_scale)?;
        if let Some(dir) = &o.faces {
            check_faces_against_outputs(dir, &o.out_dir)?;
        }
        Ok(StitchJob {
            faces: o.faces,
            face_size: o.face_size,
            fov,
            rig,
            params,
            decode: DepthDecode {
                scale: o.depth_scale,
                ..Default::default()
            },
            npz_key: o.npz_key,
            depth_kind,
            conventions,
            outputs,
            per_eye: o.per_eye,
            truth: o.truth,
            out_dir: o.out_dir,
            gpu: o.gpu,
            backend: o.backend,
        })
    }

    /// Makes or loads the faces, stitches, writes the image(s) all-or-none, and scores them
    /// against the truth when asked.
    pub fn run(&self, host: &dyn Host) -> Result<StitchReport, JobError> {
        let (fov, rig, conv) = (self.fov, self.rig, self.conventions);
        let t0 = Instant::now();
        let (left, right, source) = if let Some(dir) = &self.faces {
            if !dir.is_dir() {
                return Err(ArgError::FacesNotADirectory(dir.clone()).into());
            }
            let load = |side: Side| {
                load_face_dir(
                    dir,
                    &rig,
                    side,
                    fov,
                    FaceDepthFiles {
                        decode: &self.decode,
                        npz_key: self.npz_key.as_deref(),
                    },
                    &self.depth_kind,
                    &conv,
                )
                .within(|| crate::msg![crate::Field::Faces, format!(" {}", dir.display())])
            };
            let (l, r) = (load(Side::Left)?, load(Side::Right)?);
            if l.size() != r.size() {
                return Err(JobError::FaceSizes {
                    dir: dir.clone(),
                    left: l.size(),
                    right: r.size(),
                });
            }
            for (set, eye) in [(&l, "left"), (&r, "right")] {
                host.event(Event::InputDepth {
                    path: &dir.join(format!("{eye}_{{{}}}_depth", FACE_TAGS.join(","))),
                    summary: &DepthSummary::of(&stacked_depth(set)).with_background_expected(),
                    hint: &face_depth_hint(),
                });
            }
            let what = format!("loaded 12 faces of {n}x{n} from {}", dir.display(), n = l.size());
            (l, r, what)
        } else {
            let n = self.face_size;
            let l = scene_faces(&rig, Side::Left, n, fov).within(|| crate::Field::FaceSize)?;
            let r = scene_faces(&rig, Side::Right, n, fov).within(|| crate::Field::FaceSize)?;
            (l, r, format!("ray-traced 12 faces of {n}x{n} (CPU)"))
        };
        let faces_ms = t0.elapsed().as_secs_f64() * 1e3;
        let out_dir = io::OutDir::prepare(&self.out_dir)?;

        let gpu = host.open_device(&self.gpu, self.backend)?;
        let t0 = Instant::now();
        let mut renderer = StitchRenderer::with_conventions(&gpu, &left, &right, conv)?;
        let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
        let out = renderer.render_outputs(&self.params, self.outputs)?;
        let timing = out.timing;
        let (w, h) = (self.params.width, self.params.height);
        let whole = ViewOutput::from_stitch(out.color, out.distance, None);
        let image_size = (whole.width, whole.height);
        // Through the output layer, all or none: colour PNGs, distance EXRs.
        let formats = crate::output::FileFormats::of(self.outputs);
        let mut set = out_dir.file_set()?.replacing(replaced());
        crate::output::write_view(&mut set, &view_names("ods_top_bottom"), &whole, &formats)?;
        if self.per_eye {
            for (name, eye) in [("ods_left", 0), ("ods_right", 1)] {
                let view = eye_of(&whole, eye, w, h)?;
                crate::output::write_view(&mut set, &view_names(name), &view, &formats)?;
            }
        }
        let written = set.commit()?;
        let truth = match (self.truth, &whole.color) {
            (true, Some(img)) => Some(self.score(img)?),
            _ => None,
        };
        Ok(StitchReport {
            source,
            fov,
            faces_ms,
            setup_ms,
            rig,
            params: self.params,
            image_size,
            timing,
            truth,
            written,
        })
    }

    /// The stitched top-bottom image against the ray-traced ODS truth of both eyes.
    fn score(&self, img: &RgbImage) -> Result<TruthScore, JobError> {
        let (rig, w, h) = (&self.rig, self.params.width, self.params.height);
        let t0 = Instant::now();
        let (tl, tr) = std::thread::scope(|s| {
            let l = s.spawn(|| ods_truth(rig, Side::Left, w, h));
            let r = ods_truth(rig, Side::Right, w, h);
            (l.join().expect("ODS truth does not panic"), r)
        });
        let (tl, tr) = (tl?, tr?);
        let [el, er] = split_top_bottom(img);
        let band = seam_band_mask(w, h, self.params.overlap_deg);
        Ok(TruthScore {
            truth_ms: t0.elapsed().as_secs_f64() * 1e3,
            score: score_eyes([&el, &er], [&tl, &tr], &band),
        })
    }
}

/// Eye `eye` (0 left, 1 right) of a top-bottom stitch: its `height` rows of every plane.
fn eye_of(whole: &ViewOutput, eye: usize, width: u32, height: u32) -> crate::Result<ViewOutput> {
    let n = width as usize * height as usize;
    let color = match &whole.color {
        Some(c) => Some(RgbImage::new(
            width,
            height,
            c.data[eye * 3 * n..(eye + 1) * 3 * n].to_vec(),
        )?),
        None => None,
    };
    let distance = match &whole.depth {
        Some(d) => Some(DepthMap::new(width, height, d.data[eye * n..(eye + 1) * n].to_vec())?),
        None => None,
    };
    Ok(ViewOutput::from_stitch(color, distance, None))
}

/// What a run's set replaces: the files the previous run's record lists (the one deletion rule,
/// [`io::Replaces`]).
fn replaced() -> io::Replaces {
    io::Replaces::recorded("stitch")
}

#[cfg(test)]
mod tests {
    use super::{ArgError, FaceDepth, GpuRequest, StitchJob, StitchOptions, StitchRequest};

    fn demo() -> StitchOptions {
        StitchOptions {
            scene: Some("demo".into()),
            faces: None,
            face_size: 64,
            depth_scale: None,
            npz_key: None,
            request: StitchRequest {
                width: 256,
                height: 128,
                ..Default::default()
            },
            rows: Default::default(),
            per_eye: false,
            truth: false,
            out_dir: "out".into(),
            gpu: GpuRequest::default(),
            backend: Default::default(),
        }
    }

    /// The demo options with the request changed by `change`.
    fn with(change: impl FnOnce(&mut StitchRequest)) -> StitchOptions {
        let mut o = demo();
        change(&mut o.request);
        o
    }

    #[test]
    fn fov_and_overlap_derive_each_other() {
        let job = StitchJob::new(demo()).unwrap();
        assert_eq!((job.fov, job.params.overlap_deg), (110.0, 10.0));
        let job = StitchJob::new(with(|r| r.fov = Some(120.0))).unwrap();
        assert_eq!(job.params.overlap_deg, 15.0);
        let job = StitchJob::new(with(|r| r.overlap = Some(5.0))).unwrap();
        assert_eq!(job.fov, 100.0);
        let e = StitchJob::new(with(|r| r.overlap = Some(50.0)));
        assert!(matches!(e, Err(ArgError::Overlap(_))));
        let e = StitchJob::new(with(|r| r.fov = Some(200.0)));
        assert!(matches!(e, Err(ArgError::FaceFov(_))));
    }

    #[test]
    fn truth_and_depth_kind_need_their_source() {
        let faces = StitchOptions {
            scene: None,
            faces: Some("faces".into()),
            ..demo()
        };
        let e = StitchJob::new(StitchOptions {
            truth: true,
            ..faces.clone()
        });
        assert!(matches!(e, Err(ArgError::TruthWithoutScene)));
        let e = StitchJob::new(with(|r| {
            (r.depth_kind, r.near, r.far) = (FaceDepth::Device, Some(0.1), Some(100.0));
        }));
        assert!(matches!(e, Err(ArgError::FaceDepthKindWithoutFaces)));
        let e = StitchJob::new(with(|r| (r.height, r.width) = (crate::io::MAX_DIMENSION, 16)));
        assert!(matches!(e, Err(ArgError::TopBottomTooTall { .. })));
    }
}
