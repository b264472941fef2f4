//! `cyclopean --sequence FILE`: the middle views of a sequence of stereo frames, in order, for a
//! spectator stream. With `--fill`, each frame's holes take first what the earlier frames saw
//! there (the temporal accumulation: the last accumulated view moved into this frame's camera,
//! [`crate::cyclopean::temporal::Accumulator`]), and the fill fills what no frame saw; without
//! `--fill` every frame is rendered on its own, holes left. The renderers are made at the first
//! frame and reused ([`Reused`]), so a frame of the same size creates no GPU object.
//!
//! The file is JSON, `{"frames": [{...}, ...]}`, each frame naming its files with the keys of the
//! one-frame flags (`left_rgb`, `right_rgb`, and `left_disparity`/`right_disparity` or
//! `left_depth`/`right_depth`/`cameras`, or neither: two images alone), paths relative to the
//! file. Every other option applies to every frame. Frame k writes `middle_{k:05}_rgb.png`,
//! `_depth.exr`, `_mask.png`; all frames are one file set, so a failed or killed run leaves the
//! folder as it was (the sequence is one result: a later frame depends on the earlier ones).
//!
//! Memory: the file is read whole under the JSON cap ([`io::MAX_JSON_BYTES`]) and holds at
//! most [`MAX_SEQUENCE_FRAMES`] frames; each frame's images are decoded when it is rendered,
//! written to the set's staging folder and dropped.

use super::{CyclopeanJob, CyclopeanOptions, CyclopeanReport};
use crate::cyclopean::pipeline::Reused;
use crate::error::{Error, Result};
use crate::io;
use crate::job::{ArgError, Event, Host, JobError};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Most frames one sequence file lists.
pub const MAX_SEQUENCE_FRAMES: usize = 100_000;

/// One frame of a sequence file: the files of `viewsynth cyclopean`'s one-frame flags.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SequenceFrame {
    /// Left eye colour.
    pub left_rgb: PathBuf,
    /// Right eye colour.
    pub right_rgb: PathBuf,
    /// Left disparity (a rectified pair).
    #[serde(default)]
    pub left_disparity: Option<PathBuf>,
    /// Right disparity.
    #[serde(default)]
    pub right_disparity: Option<PathBuf>,
    /// Left depth (with a camera file).
    #[serde(default)]
    pub left_depth: Option<PathBuf>,
    /// Right depth.
    #[serde(default)]
    pub right_depth: Option<PathBuf>,
    /// The frame's camera file.
    #[serde(default)]
    pub cameras: Option<PathBuf>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SequenceFile {
    frames: Vec<SequenceFrame>,
}

/// Reads a sequence file: at least one frame, at most [`MAX_SEQUENCE_FRAMES`], paths made
/// relative to the file's folder. Errors name the file (and the frame).
pub fn load_sequence(path: &Path) -> Result<Vec<SequenceFrame>> {
    let text = io::read_text(path, io::MAX_JSON_BYTES)?;
    let file: SequenceFile = serde_json::from_str(&text).map_err(|e| Error::decode(path, e.to_string()))?;
    let mut frames = file.frames;
    if frames.is_empty() {
        return Err(Error::decode(path, "the sequence lists no frame"));
    }
    if frames.len() > MAX_SEQUENCE_FRAMES {
        return Err(Error::decode(
            path,
            format!("{} frames: at most {MAX_SEQUENCE_FRAMES} per sequence", frames.len()),
        ));
    }
    let base = path.parent().unwrap_or(Path::new("."));
    for (k, f) in frames.iter_mut().enumerate() {
        let paths = [Some(&mut f.left_rgb), Some(&mut f.right_rgb)]
            .into_iter()
            .chain([
                f.left_disparity.as_mut(),
                f.right_disparity.as_mut(),
                f.left_depth.as_mut(),
                f.right_depth.as_mut(),
                f.cameras.as_mut(),
            ])
            .flatten();
        for p in paths {
            if p.as_os_str().is_empty() {
                return Err(Error::decode(path, format!("frame {k}: an empty path")));
            }
            if p.is_relative() {
                *p = base.join(&*p);
            }
        }
    }
    Ok(frames)
}

/// A checked `cyclopean --sequence` run.
#[derive(Debug, Clone)]
pub struct CyclopeanSequenceJob {
    file: PathBuf,
    /// Every option but the frame's files.
    template: CyclopeanOptions,
}

impl CyclopeanSequenceJob {
    /// `template` holds every option but the frames' files, which come from `file`. Options
    /// that read one pair's files are refused here; the rest are checked against each frame's
    /// set-up when the file is read.
    pub fn new(file: PathBuf, template: CyclopeanOptions) -> std::result::Result<Self, ArgError> {
        let t = &template;
        t.gpu.check_backend(t.backend)?;
        for (flag, given) in [
            (crate::Field::LeftRgb, !t.left_rgb.as_os_str().is_empty()),
            (crate::Field::RightRgb, !t.right_rgb.as_os_str().is_empty()),
            (crate::Field::LeftDisparity, t.left_disparity.is_some()),
            (crate::Field::RightDisparity, t.right_disparity.is_some()),
            (crate::Field::LeftDepth, t.left_depth.is_some()),
            (crate::Field::RightDepth, t.right_depth.is_some()),
            (crate::Field::Cameras, t.cameras.is_some()),
        ] {
            if given {
                return Err(ArgError::Invalid(Error::param(
                    flag,
                    crate::msg![
                        "names one frame's file: with ",
                        crate::Field::Sequence,
                        " each frame names its own"
                    ],
                )));
            }
        }
        if t.request.confidence {
            return Err(ArgError::Invalid(Error::param(
                crate::Field::Confidence,
                crate::msg!["writes one pair's confidence files: not with ", crate::Field::Sequence],
            )));
        }
        Ok(CyclopeanSequenceJob { file, template })
    }

    /// `--out-dir`.
    pub fn out_dir(&self) -> &Path {
        &self.template.out_dir
    }

    /// Frame `k`'s job: its files with the shared options, checked as one pair's.
    fn frame_job(&self, k: usize, f: SequenceFrame) -> Result<CyclopeanJob> {
        let o = CyclopeanOptions {
            left_rgb: f.left_rgb,
            right_rgb: f.right_rgb,
            left_disparity: f.left_disparity,
            right_disparity: f.right_disparity,
            left_depth: f.left_depth,
            right_depth: f.right_depth,
            cameras: f.cameras,
            ..self.template.clone()
        };
        CyclopeanJob::new(o).map_err(|e| Error::decode(&self.file, format!("frame {k}: {e}")))
    }

    /// Renders every frame in order and writes them all-or-none.
    pub fn run(&self, host: &dyn Host) -> std::result::Result<CyclopeanReport, JobError> {
        let frames = load_sequence(&self.file)?;
        // Every frame's options are checked before anything is decoded or rendered.
        let jobs = frames
            .into_iter()
            .enumerate()
            .map(|(k, f)| self.frame_job(k, f))
            .collect::<Result<Vec<_>>>()?;
        let device = host.open_device(&self.template.gpu, self.template.backend)?;
        let mut reused = Reused::default();
        let mut set = None;
        let (mut size, mut coverage, mut render_ms) = ((0, 0), 0.0, 0.0);
        host.event(Event::Started {
            what: "cyclopean frames",
            total: jobs.len() as u64,
        });
        for (k, job) in jobs.iter().enumerate() {
            let view = job.render(&device, host, Some(&mut reused))?;
            // The folder once the first frame rendered: a refused first input leaves none.
            let set = match &mut set {
                Some(set) => set,
                None => set.insert(
                    io::OutDir::prepare(self.out_dir())?
                        .file_set()?
                        .replacing(super::replaced()),
                ),
            };
            let names = crate::output::ViewNames::tagged(&format!("middle_{k:05}"));
            crate::output::write_view(set, &names, &view.done.view, &job.formats())?;
            size = view.size;
            coverage += view.done.coverage;
            render_ms += view.done.view.timing.map_or(0.0, |t| t.wall_ms);
            host.event(Event::Advanced);
        }
        // load_sequence refuses a file without frames, so the loop opened the set.
        let set = set.ok_or_else(|| Error::decode(&self.file, "the sequence lists no frame"))?;
        let written = set.commit()?;
        host.event(Event::Finished);
        Ok(CyclopeanReport {
            width: size.0,
            height: size.1,
            frames: jobs.len(),
            valid_fraction: coverage / jobs.len() as f64,
            render_ms,
            written,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, text: &str) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let p = dir.join("seq.json");
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn frames_are_read_relative_to_the_file_and_refused_by_name() {
        let dir = std::env::temp_dir().join(format!("viewsynth-seq-{}", std::process::id()));
        let p = write(
            &dir,
            r#"{"frames": [{"left_rgb": "a/l.png", "right_rgb": "/abs/r.png", "cameras": "c.json"}]}"#,
        );
        let f = load_sequence(&p).unwrap();
        assert_eq!(f[0].left_rgb, dir.join("a/l.png"));
        assert_eq!(f[0].right_rgb, PathBuf::from("/abs/r.png"));
        assert_eq!(f[0].cameras, Some(dir.join("c.json")));
        for (text, says) in [
            (r#"{"frames": []}"#, "no frame"),
            (
                r#"{"frames": [{"left_rgb": "", "right_rgb": "r"}]}"#,
                "frame 0: an empty path",
            ),
            (
                r#"{"frames": [{"left_rgb": "l", "right_rgb": "r", "depth": "d"}]}"#,
                "unknown field",
            ),
            (r#"[{"left_rgb": "l", "right_rgb": "r"}]"#, "invalid type"),
        ] {
            let err = load_sequence(&write(&dir, text)).unwrap_err().to_string();
            assert!(err.contains("seq.json") && err.contains(says), "{text}: {err}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn one_pair_options_are_refused_with_a_sequence() {
        let t = CyclopeanOptions {
            left_rgb: "l.png".into(),
            ..Default::default()
        };
        let e = CyclopeanSequenceJob::new("s.json".into(), t).unwrap_err().to_string();
        assert!(e.contains("--left-rgb"), "{e}");
        let mut t = CyclopeanOptions::default();
        t.request.confidence = true;
        let e = CyclopeanSequenceJob::new("s.json".into(), t).unwrap_err().to_string();
        assert!(e.contains("--confidence"), "{e}");
        assert!(CyclopeanSequenceJob::new("s.json".into(), CyclopeanOptions::default()).is_ok());
    }
}
