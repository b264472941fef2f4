//! `scene`: a ground-truth stereo frame (left, right and middle colour, view distance, device
//! depth) ray-traced on the GPU from the demo rig, and the `cameras.json` that `cyclopean` and
//! `reproject --cameras` read; with `cube_faces`, also the 6 over-wide cube faces per eye that
//! `stitch --faces` reads. Every file or none: a failing rerun leaves the previous scene.

use super::{ArgError, Backend, GpuRequest, Host, JobError};
use crate::camera::gl_projection;
use crate::convention::Conventions;
use crate::io;
use crate::scene::render::{GlCamera, SceneRenderer};
use crate::stereo::scene_frame::StereoRig;
use crate::stitch::faces::{scene_faces_of, FACE_TAGS};
use crate::stitch::{OdsRig, Side};
use crate::view::ViewOutput;
use crate::world::{builtin, Scene};
use std::path::{Path, PathBuf};

/// The scene options as given.
#[derive(Debug, Clone)]
pub struct SceneOptions {
    /// `demo`, `boxes`, or a scene JSON file.
    pub scene: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Interocular distance, metres.
    pub ipd: f64,
    /// Conventions of the projections and the device depth written.
    pub conventions: Conventions,
    /// Also write each eye's six cube faces, N x N, as `stitch --faces` reads them.
    pub cube_faces: Option<u32>,
    /// The cube faces' horizontal and vertical field of view, degrees (> 90: they overlap).
    pub face_fov: f64,
    /// Frames: 1 writes one stereo frame; more write a sequence, the head moving `dolly`
    /// metres to its right per frame, each frame's files prefixed `{k:05}_`, and
    /// `sequence.json` for `cyclopean --sequence`.
    pub frames: u32,
    /// Metres the head moves to its right from one frame to the next.
    pub dolly: f64,
    /// Metres to the head's right of the middle (spectator) camera: 0 halfway between the
    /// eyes; beyond half the IPD it sees past an eye (disocclusions neither eye saw).
    pub spectator_offset: f64,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The GPU to render on.
    pub gpu: GpuRequest,
    /// `--backend`: the API the passes run on.
    pub backend: Backend,
}

/// Most frames of a scene sequence.
pub const MAX_SCENE_FRAMES: u32 = 10_000;

/// The scene to trace: built in (known now) or a file (read when the job runs).
#[derive(Debug, Clone)]
enum SceneSource {
    Builtin(Box<Scene>),
    File(PathBuf),
}

/// A checked scene rendering.
#[derive(Debug, Clone)]
pub struct SceneJob {
    scene: SceneSource,
    rig: StereoRig,
    conventions: Conventions,
    /// Cube faces to write: the ODS rig (stitch's defaults, at the same IPD), side and FOV.
    faces: Option<(OdsRig, u32, f64)>,
    frames: u32,
    dolly: f64,
    spectator_offset: f64,
    out_dir: PathBuf,
    gpu: GpuRequest,
    backend: Backend,
}

/// What a scene rendering wrote.
#[derive(Debug)]
pub struct SceneReport {
    /// The scene's name.
    pub name: String,
    /// Image size.
    pub size: (u32, u32),
    /// Each eye (left, right, middle) and its render time in milliseconds.
    pub eyes: Vec<(&'static str, f64)>,
    /// The cube faces written, if asked: side N, field of view in degrees, and the ray-tracing
    /// time in milliseconds (CPU, f64).
    pub faces: Option<(u32, f64, f64)>,
    /// Frames written (more than 1: a sequence with `sequence.json`).
    pub frames: u32,
}

impl SceneJob {
    /// Checks the scene name, the interocular distance and the image size.
    pub fn new(o: SceneOptions) -> Result<Self, ArgError> {
        o.gpu.check_backend(o.backend)?;
        let scene = if Path::new(&o.scene).extension().is_some_and(|e| e == "json") {
            SceneSource::File(PathBuf::from(&o.scene))
        } else {
            SceneSource::Builtin(Box::new(builtin(&o.scene)?))
        };
        if !(o.ipd.is_finite() && o.ipd >= 0.0) {
            return Err(ArgError::Ipd(o.ipd));
        }
        io::check_output_pixels(
            crate::msg![crate::Field::Width, "/", crate::Field::Height],
            o.width,
            o.height,
        )?;
        if !(1..=MAX_SCENE_FRAMES).contains(&o.frames) {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::Frames,
                format!("{} outside 1..={MAX_SCENE_FRAMES}", o.frames),
            )));
        }
        if !(o.dolly.is_finite() && o.dolly.abs() <= 1.0) {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::Dolly,
                format!("{} m per frame: give a finite step within 1 m", o.dolly),
            )));
        }
        if !(o.spectator_offset.is_finite() && o.spectator_offset.abs() <= 10.0) {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::SpectatorOffset,
                format!("{} m: give a finite offset within 10 m", o.spectator_offset),
            )));
        }
        if o.frames > 1 && o.cube_faces.is_some() {
            return Err(ArgError::Invalid(crate::Error::param(
                crate::Field::CubeFaces,
                crate::msg!["is for one frame: not with ", crate::Field::Frames],
            )));
        }
        if let SceneSource::File(path) = &scene {
            crate::output::check_out_dir(&o.out_dir, writes, &replaced(), &[(crate::Field::Scene.into(), path)])
                .map_err(ArgError::Invalid)?;
        }
        let mut rig = StereoRig::demo(o.width, o.height);
        rig.camera.validate("scene camera")?;
        rig.ipd = o.ipd;
        let faces = match o.cube_faces {
            None => None,
            Some(n) => {
                if !(o.face_fov > 90.0 && o.face_fov < 178.0) {
                    return Err(ArgError::CubeFaceFov(o.face_fov));
                }
                io::check_output_pixels(crate::Field::CubeFaces, n, n)?;
                // stitch's rig for a face folder, at this IPD: the faces are taken from the
                // evaluation rig's centre (inside the built-in scenes), which stitch does not
                // need to know (only the eyes' offsets from it matter).
                let ods = OdsRig {
                    ipd: o.ipd,
                    ..OdsRig::demo()
                };
                ods.validate().map_err(ArgError::from)?;
                Some((ods, n, o.face_fov))
            }
        };
        Ok(SceneJob {
            scene,
            rig,
            conventions: o.conventions,
            faces,
            frames: o.frames,
            dolly: o.dolly,
            spectator_offset: o.spectator_offset,
            out_dir: o.out_dir,
            gpu: o.gpu,
            backend: o.backend,
        })
    }

    /// `--out-dir`.
    pub fn out_dir(&self) -> &Path {
        &self.out_dir
    }

    /// Ray-traces the three eyes and writes their images and `cameras.json`, all or none.
    pub fn run(&self, host: &dyn Host) -> Result<SceneReport, JobError> {
        let loaded;
        let scene = match &self.scene {
            SceneSource::Builtin(s) => s.as_ref(),
            SceneSource::File(path) => {
                loaded = Scene::load(path)?;
                &loaded
            }
        };
        let (rig, conv) = (&self.rig, self.conventions);
        let (width, height) = (rig.camera.width, rig.camera.height);
        let out = io::OutDir::prepare(&self.out_dir)?;
        let mut set = out.file_set()?.replacing(replaced());
        let gpu = host.open_device(&self.gpu, self.backend)?;
        let mut renderer = SceneRenderer::new(&gpu, scene)?;
        let proj = gl_projection(&rig.camera, &rig.planes, &conv);
        let mut eyes = Vec::new();
        let mut sequence = Vec::new();
        for k in 0..self.frames {
            // One frame: no prefix, as before sequences; frame k of a sequence: `{k:05}_`.
            let prefix = if self.frames == 1 {
                String::new()
            } else {
                format!("{k:05}_")
            };
            let frame_rig = StereoRig {
                head: rig.right_of_head(self.dolly * f64::from(k)),
                ..*rig
            };
            // The spectator is placed in metres from the head, whatever the IPD (0 included).
            let spectator = frame_rig.right_of_head(self.spectator_offset);
            let mut cams = serde_json::Map::new();
            for (eye, pose) in [
                ("left", frame_rig.eye_pose(-1.0)),
                ("right", frame_rig.eye_pose(1.0)),
                ("middle", spectator),
            ] {
                let view = pose.gl_view();
                let (img, timing) = renderer.render(&GlCamera {
                    view,
                    proj,
                    width,
                    height,
                    conv,
                })?;
                let (rgb_depth, depth_only) = (
                    crate::output::FileFormats::of(crate::output::OutputSet::RGB_DEPTH),
                    crate::output::FileFormats::of(crate::output::OutputSet::DEPTH),
                );
                let mut planes = ViewOutput::color_only(img.color, None);
                planes.depth = Some(img.view_z);
                let names =
                    crate::output::ViewNames::named(&format!("{prefix}{eye}_rgb"), &format!("{prefix}{eye}_view_z"));
                crate::output::write_view(&mut set, &names, &planes, &rgb_depth)?;
                planes.depth = Some(img.device_depth);
                let names = crate::output::ViewNames::named("", &format!("{prefix}{eye}_device_depth"));
                crate::output::write_view(&mut set, &names, &planes, &depth_only)?;
                let entry = if eye == "middle" {
                    serde_json::json!({ "view": view, "proj": proj, "width": width, "height": height })
                } else {
                    serde_json::json!({ "view": view, "proj": proj })
                };
                cams.insert(eye.to_string(), entry);
                if k == 0 {
                    eyes.push((eye, timing.wall_ms));
                }
            }
            let name = format!("{prefix}cameras.json");
            let cameras_json = self.out_dir.join(&name);
            let conv_json =
                serde_json::to_value(conv).map_err(|e| crate::Error::encode(&cameras_json, e.to_string()))?;
            cams.insert("conventions".into(), conv_json);
            cams.insert("depth_kind".into(), "device".into());
            cams.insert("fixation_distance".into(), 3.0.into());
            write_json(&mut set, &name, &cameras_json, &serde_json::Value::Object(cams))?;
            sequence.push(serde_json::json!({
                "left_rgb": format!("{prefix}left_rgb.png"),
                "left_depth": format!("{prefix}left_device_depth.exr"),
                "right_rgb": format!("{prefix}right_rgb.png"),
                "right_depth": format!("{prefix}right_device_depth.exr"),
                "cameras": name,
            }));
        }
        if self.frames > 1 {
            let path = self.out_dir.join("sequence.json");
            write_json(
                &mut set,
                "sequence.json",
                &path,
                &serde_json::json!({ "frames": sequence }),
            )?;
        }
        let faces = match self.faces {
            None => None,
            Some((ods, n, fov)) => {
                let t0 = std::time::Instant::now();
                for (side, eye) in [(Side::Left, "left"), (Side::Right, "right")] {
                    let faces = scene_faces_of(scene, &ods, side, n, fov)?;
                    for (face, tag) in faces.faces.into_iter().zip(FACE_TAGS) {
                        let mut view = ViewOutput::color_only(face.color, None);
                        view.depth = Some(face.depth);
                        let names =
                            crate::output::ViewNames::named(&format!("{eye}_{tag}"), &format!("{eye}_{tag}_depth"));
                        crate::output::write_view(
                            &mut set,
                            &names,
                            &view,
                            &crate::output::FileFormats::of(crate::output::OutputSet::RGB_DEPTH),
                        )?;
                    }
                }
                Some((n, fov, t0.elapsed().as_secs_f64() * 1e3))
            }
        };
        set.commit()?;
        Ok(SceneReport {
            name: scene.name.clone(),
            size: (width, height),
            eyes,
            faces,
            frames: self.frames,
        })
    }
}

/// Whether `name` is one a scene run may write: a frame's files (prefixed `{k:05}_` in a
/// sequence), `sequence.json`, a cube face's files.
fn writes(name: &str) -> bool {
    let frame = name
        .split_once('_')
        .filter(|(k, _)| k.len() == 5 && k.bytes().all(|b| b.is_ascii_digit()))
        .map_or(name, |(_, rest)| rest);
    let stems = ["rgb", "view_z", "device_depth"];
    let view = ["left", "right", "middle"].iter().any(|eye| {
        stems
            .iter()
            .any(|s| crate::output::ViewNames::named(&format!("{eye}_{s}"), "").may_write(frame))
    });
    let face = ["left", "right"].iter().any(|eye| {
        FACE_TAGS.iter().any(|t| {
            crate::output::ViewNames::named(&format!("{eye}_{t}"), &format!("{eye}_{t}_depth")).may_write(name)
        })
    });
    view || face || frame == "cameras.json" || name == "sequence.json"
}

/// `value` as pretty JSON into the set as `name` (`path` names it in errors).
fn write_json(set: &mut io::FileSet, name: &str, path: &Path, value: &serde_json::Value) -> crate::Result<()> {
    let text = serde_json::to_string_pretty(value).map_err(|e| crate::Error::encode(path, e.to_string()))?;
    set.write(name, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| crate::Error::io(path, e))
    })?;
    Ok(())
}

/// What a run's set replaces: the files the previous run's record lists (the one deletion rule,
/// [`io::Replaces`]).
fn replaced() -> io::Replaces {
    io::Replaces::recorded("scene")
}

#[cfg(test)]
mod tests {
    use super::{ArgError, SceneJob, SceneOptions, SceneSource};

    fn options(scene: &str, ipd: f64) -> SceneOptions {
        SceneOptions {
            scene: scene.into(),
            width: 64,
            height: 48,
            ipd,
            conventions: Default::default(),
            cube_faces: None,
            face_fov: 110.0,
            frames: 1,
            dolly: 0.0,
            spectator_offset: 0.0,
            out_dir: "out".into(),
            gpu: Default::default(),
            backend: Default::default(),
        }
    }

    #[test]
    fn built_in_scenes_are_known_now_and_files_are_read_when_run() {
        assert!(matches!(
            SceneJob::new(options("demo", 0.064)).unwrap().scene,
            SceneSource::Builtin(_)
        ));
        assert!(matches!(
            SceneJob::new(options("my.json", 0.064)).unwrap().scene,
            SceneSource::File(_)
        ));
        assert!(SceneJob::new(options("nosuch", 0.064)).is_err());
        assert!(matches!(SceneJob::new(options("demo", -1.0)), Err(ArgError::Ipd(_))));
    }
}
