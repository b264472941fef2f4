//! `Renderer.cyclopean`: the library calls of `viewsynth cyclopean`, numpy in and out, for both
//! of its set-ups: a rectified pair with disparities (`--left-disparity ...`), or any pair with
//! depth placed by a camera file (`--left-depth ... --cameras`). The cameras come as the file's
//! path or as a dict with the file's keys, read by the library's own `CameraFile` parser (K, R, t
//! converted to GL matrices exactly as for the CLI); see `camera_json` for the dict.

use crate::arrays;
use crate::backend::Backend;
use crate::errors;
use crate::errors::Kind;
use crate::shared::SameThread;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use viewsynth::convention::Conventions;
use viewsynth::cyclopean::camera_file::{CameraFile, EyeCameras};
use viewsynth::cyclopean::disparity_frame::{disparity_frame, DisparityRig};
use viewsynth::cyclopean::fill::FILLED;
use viewsynth::cyclopean::forward::ForwardWarp;
use viewsynth::cyclopean::render::CyclopeanRenderer;
use viewsynth::cyclopean::splat::{SplatParams, SplatRenderer};
use viewsynth::cyclopean::{
    CyclopeanOutput, CyclopeanOutputs, CyclopeanParams, EyeInput, Method as GatherMethod, MiddleCamera, StereoFrame,
};
use viewsynth::gpu::Timing;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::refocus::{BreakRule, OutputSet};

/// The methods of `viewsynth cyclopean --method`.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Method {
    SplatGather,
    Seed,
    Refine,
    Forward,
}

impl Method {
    fn parse(name: &str) -> PyResult<Self> {
        Ok(match name {
            "splat-gather" => Method::SplatGather,
            "seed" => Method::Seed,
            "refine" => Method::Refine,
            "forward" => Method::Forward,
            _ => {
                return Err(errors::invalid(
                    "method",
                    format!("'{name}': expected \"splat-gather\", \"seed\", \"refine\" or \"forward\""),
                ))
            }
        })
    }
}

/// The arguments of one call, as Python gave them.
pub struct CyclopeanArgs<'a, 'py> {
    pub left_rgb: &'a Bound<'py, PyAny>,
    pub right_rgb: &'a Bound<'py, PyAny>,
    pub left_disparity: Option<&'a Bound<'py, PyAny>>,
    pub right_disparity: Option<&'a Bound<'py, PyAny>>,
    pub position: Option<f64>,
    pub left_depth: Option<&'a Bound<'py, PyAny>>,
    pub right_depth: Option<&'a Bound<'py, PyAny>>,
    pub cameras: Option<&'a Bound<'py, PyAny>>,
    pub method: &'a str,
    pub focal: Option<f64>,
    pub baseline: Option<f64>,
    pub doffs: f64,
    pub outputs: Option<&'a Bound<'py, PyAny>>,
    pub fill: bool,
}

/// A call's inputs, validated while the GIL is held.
struct Job {
    frame: StereoFrame,
    mid: MiddleCamera,
    method: Method,
    /// Seed/refine start from it: the median depth the left eye saw (as the CLI).
    fixation: f64,
    wanted: CyclopeanOutputs,
    /// Holes filled from the background side after the method (the CLI's --fill).
    fill: bool,
}

/// The same renderer the CLI picks for `method`, with its defaults.
fn render(gpu: &Backend, job: &Job) -> viewsynth::Result<(f64, CyclopeanOutput, Timing)> {
    let t0 = std::time::Instant::now();
    let (frame, mid, wanted) = (&job.frame, &job.mid, job.wanted);
    let (out, timing) = match job.method {
        Method::Seed | Method::Refine => {
            let mut params = CyclopeanParams::seed(job.fixation);
            if job.method == Method::Refine {
                // The CLI's default --refine-steps.
                params.method = GatherMethod::Refine { steps: 3 };
            }
            params.validate()?;
            let mut r = CyclopeanRenderer::with_outputs(gpu, frame, params, wanted)?;
            r.render(mid)?
        }
        Method::Forward => ForwardWarp::new(gpu, frame, &BreakRule::default())?.render(mid)?,
        Method::SplatGather => SplatRenderer::new(gpu, frame, SplatParams::default(), wanted)?.render(mid)?,
    };
    let out = match job.fill {
        true => viewsynth::cyclopean::fill::Filler::new(gpu)?.fill(&out, mid.width, mid.height)?,
        false => out,
    };
    // Everything before the render itself: uploads, meshes, programs.
    let setup_ms = (t0.elapsed().as_secs_f64() * 1e3 - timing.wall_ms).max(0.0);
    Ok((setup_ms, out, timing))
}

fn eye(
    rgb: &Bound<'_, PyAny>,
    rgb_name: &str,
    map: &Bound<'_, PyAny>,
    map_name: &str,
) -> PyResult<(RgbImage, DepthMap)> {
    Ok((arrays::rgb_image(rgb, rgb_name)?, arrays::float_map(map, map_name)?))
}

/// Both eyes' images, refused (naming the argument) unless all four have left_rgb's size.
fn eyes(
    a: &CyclopeanArgs<'_, '_>,
    maps: [(&Bound<'_, PyAny>, &str); 2],
) -> PyResult<((RgbImage, DepthMap), (RgbImage, DepthMap))> {
    let left = eye(a.left_rgb, "left_rgb", maps[0].0, maps[0].1)?;
    let right = eye(a.right_rgb, "right_rgb", maps[1].0, maps[1].1)?;
    let (w, h) = (left.0.width, left.0.height);
    // Named here: the library's size message does not say which argument to fix.
    for (name, (width, height)) in [
        (maps[0].1, (left.1.width, left.1.height)),
        ("right_rgb", (right.0.width, right.0.height)),
        (maps[1].1, (right.1.width, right.1.height)),
    ] {
        if (width, height) != (w, h) {
            return Err(errors::invalid(
                name,
                format!("{width}x{height} (W x H) differs from left_rgb's {w}x{h}"),
            ));
        }
    }
    Ok((left, right))
}

/// A rectified pair with disparities (the CLI's --left-disparity mode): the frame, the view,
/// the fixation of seed/refine (the median depth the left eye saw) and whether depth is metric.
fn disparity_job(
    gpu: &Backend,
    a: &CyclopeanArgs<'_, '_>,
    left_disparity: &Bound<'_, PyAny>,
    right_disparity: &Bound<'_, PyAny>,
) -> PyResult<(StereoFrame, MiddleCamera, f64, bool)> {
    let metric = match (a.focal, a.baseline) {
        (Some(_), Some(_)) => true,
        (None, None) => false,
        (Some(_), None) => return Err(errors::invalid("baseline", "focal needs baseline (metres) too")),
        (None, Some(_)) => return Err(errors::invalid("focal", "baseline needs focal (pixels) too")),
    };
    let (left, right) = eyes(
        a,
        [(left_disparity, "left_disparity"), (right_disparity, "right_disparity")],
    )?;
    let (w, h) = (left.0.width, left.0.height);
    gpu.check_image_size("left_rgb", w, h).map_err(errors::from_library)?;
    // Without a calibration only f B matters for the view; any nominal values do (as the CLI).
    let rig = DisparityRig {
        focal_px: a.focal.unwrap_or(w as f64),
        baseline: a.baseline.unwrap_or(0.1),
        doffs: a.doffs,
        position: a.position.unwrap_or(0.5),
    };
    let (frame, mid) = disparity_frame(left, right, &rig, Conventions::default()).map_err(errors::from_library)?;
    let mut z: Vec<f32> = frame.left.depth.data.iter().copied().filter(|z| *z > 0.0).collect();
    if z.is_empty() {
        return Err(errors::invalid(
            "left_disparity",
            "no known disparity (all 0, negative or non-finite)",
        ));
    }
    let half = z.len() / 2;
    let fixation = *z.select_nth_unstable_by(half, f32::total_cmp).1 as f64;
    Ok((frame, mid, fixation, metric))
}

/// A camera-file problem as InvalidInputError naming `cameras`; the message names the field
/// ("cameras: invalid right.R: not orthonormal ...").
fn camera_error(message: impl std::fmt::Display) -> PyErr {
    errors::raise(Kind::InvalidInput, format!("cameras: {message}"), Some("cameras"))
}

/// `cameras` (a dict with cameras.json's keys; numpy arrays, tuples and numpy scalars are
/// accepted) as the JSON value the library's camera-file parser reads. Numbers must be finite
/// and within the file reader's magnitude bound, so a dict and a file accept the same cameras;
/// an offending number is named by its path, e.g. cameras["left"]["K"][0][2].
fn camera_json(obj: &Bound<'_, PyAny>, at: &str) -> PyResult<serde_json::Value> {
    use serde_json::Value;
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    let number = |x: f64| -> PyResult<Value> {
        if !(x.is_finite() && x.abs() <= viewsynth::io::MAX_JSON_MAGNITUDE) {
            return Err(camera_error(format!(
                "invalid {at}: {x}: numbers must be finite with magnitude <= {:e}",
                viewsynth::io::MAX_JSON_MAGNITUDE
            )));
        }
        Ok(serde_json::Number::from_f64(x)
            .map(Value::Number)
            .unwrap_or(Value::Null))
    };
    if obj.is_instance_of::<PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => number(i as f64).map(|_| Value::from(i)),
            Err(_) => Err(camera_error(format!("invalid {at}: too large an integer"))),
        };
    }
    if obj.is_instance_of::<PyFloat>() {
        return number(obj.extract()?);
    }
    if let Ok(dict) = obj.cast::<PyDict>() {
        let mut map = serde_json::Map::new();
        for (key, value) in dict.iter() {
            let Ok(key) = key.extract::<String>() else {
                return Err(camera_error(format!("invalid {at}: a key that is not a string: {key}")));
            };
            let inner = camera_json(&value, &format!("{at}[\"{key}\"]"))?;
            map.insert(key, inner);
        }
        return Ok(Value::Object(map));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, item) in obj.try_iter()?.enumerate() {
            items.push(camera_json(&item?, &format!("{at}[{i}]"))?);
        }
        return Ok(Value::Array(items));
    }
    // numpy arrays and scalars: as Python lists and numbers.
    if obj.hasattr("tolist")? && obj.hasattr("dtype")? {
        return camera_json(&obj.call_method0("tolist")?, at);
    }
    let ty = obj.get_type().name().map(|n| n.to_string()).unwrap_or_default();
    Err(camera_error(format!(
        "invalid {at}: a {ty}; expected dicts, lists, numbers, strings, booleans or None"
    )))
}

/// `cameras` as the library's camera file: a path (read as `viewsynth cyclopean --cameras`
/// reads it) or a dict with the same keys.
fn camera_file(obj: &Bound<'_, PyAny>) -> PyResult<CameraFile> {
    let py = obj.py();
    let is_path = obj.is_instance_of::<PyString>() || obj.is_instance(&py.import("os")?.getattr("PathLike")?)?;
    if is_path {
        let path: std::path::PathBuf = obj.extract()?;
        return CameraFile::load(&path).map_err(errors::from_library);
    }
    if !obj.is_instance_of::<PyDict>() {
        let ty = obj.get_type().name().map(|n| n.to_string()).unwrap_or_default();
        return Err(errors::invalid(
            "cameras",
            format!("expected a dict with cameras.json's keys or a path to one, got {ty}"),
        ));
    }
    let value = camera_json(obj, "cameras")?;
    // The file's parser: field errors name the field (left.R, middle.K, ...).
    serde_json::from_value(value).map_err(camera_error)
}

/// The size the camera gives its eye must be the image's (the CLI's check, argument named).
fn check_eye_size(cam: &EyeCameras, side: &str, (rgb, _): &(RgbImage, DepthMap)) -> PyResult<()> {
    match cam.size {
        Some([w, h]) if (w, h) != (rgb.width, rgb.height) => Err(errors::invalid(
            &format!("{side}_rgb"),
            format!(
                "{}x{} (W x H) but cameras[\"{side}\"] gives width x height {w}x{h}",
                rgb.width, rgb.height
            ),
        )),
        _ => Ok(()),
    }
}

/// Depth per eye placed by a camera file (the CLI's --left-depth ... --cameras mode): the frame,
/// the view and the fixation the file gives (fixation_distance or the gaze rays' vergence).
fn camera_job(
    gpu: &Backend,
    a: &CyclopeanArgs<'_, '_>,
    left_depth: &Bound<'_, PyAny>,
    right_depth: &Bound<'_, PyAny>,
    cameras: &Bound<'_, PyAny>,
) -> PyResult<(StereoFrame, MiddleCamera, f64)> {
    // The rig options of the disparity mode: the camera file already places both eyes.
    for (name, given) in [
        ("position", a.position.is_some()),
        ("focal", a.focal.is_some()),
        ("baseline", a.baseline.is_some()),
        ("doffs", a.doffs != 0.0),
    ] {
        if given {
            return Err(errors::invalid(
                name,
                "applies to disparity input only; with cameras the camera file places the eyes and the view",
            ));
        }
    }
    let cams = camera_file(cameras)?;
    let (left, right) = eyes(a, [(left_depth, "left_depth"), (right_depth, "right_depth")])?;
    check_eye_size(&cams.left, "left", &left)?;
    check_eye_size(&cams.right, "right", &right)?;
    gpu.check_image_size("left_rgb", left.0.width, left.0.height)
        .map_err(errors::from_library)?;
    let (mid, fixation) = cams.middle_and_fixation().map_err(camera_error)?;
    gpu.check_image_size("cameras[\"middle\"] width/height", mid.width, mid.height)
        .map_err(errors::from_library)?;
    let eye_input = |(color, depth): (RgbImage, DepthMap), cam: &EyeCameras| EyeInput {
        color,
        depth,
        view: cam.view,
        proj: cam.proj,
    };
    let frame = StereoFrame {
        left: eye_input(left, &cams.left),
        right: eye_input(right, &cams.right),
        depth_kind: cams.depth_kind,
        conv: cams.conventions,
    };
    Ok((frame, mid, fixation))
}

/// Validates `a`, renders the view with the GIL released, and returns the result dict.
pub fn cyclopean<'py>(py: Python<'py>, gpu: Backend, a: CyclopeanArgs<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let method = Method::parse(a.method)?;
    let disparity = a.left_disparity.is_some() || a.right_disparity.is_some();
    let depth = a.left_depth.is_some() || a.right_depth.is_some() || a.cameras.is_some();
    let (frame, mid, fixation, metric) = match (disparity, depth) {
        (true, false) => {
            let missing = |name: &str, other: &str| errors::invalid(name, format!("missing ({other} is given)"));
            let ld = a
                .left_disparity
                .ok_or_else(|| missing("left_disparity", "right_disparity"))?;
            let rd = a
                .right_disparity
                .ok_or_else(|| missing("right_disparity", "left_disparity"))?;
            disparity_job(&gpu, &a, ld, rd)?
        }
        (false, true) => {
            let missing =
                |name: &str| errors::invalid(name, "missing: depth input needs left_depth, right_depth and cameras");
            let ld = a.left_depth.ok_or_else(|| missing("left_depth"))?;
            let rd = a.right_depth.ok_or_else(|| missing("right_depth"))?;
            let cams = a.cameras.ok_or_else(|| missing("cameras"))?;
            let (frame, mid, fixation) = camera_job(&gpu, &a, ld, rd, cams)?;
            (frame, mid, fixation, true)
        }
        (true, true) => {
            return Err(errors::invalid(
                "cameras",
                "give disparities (left_disparity, right_disparity) or depth (left_depth, right_depth, \
                 cameras), not both",
            ))
        }
        (false, false) => {
            return Err(errors::invalid(
                "left_disparity",
                "no stereo input: give left_disparity and right_disparity, or left_depth, right_depth and \
                 cameras",
            ))
        }
    };
    let outputs = match a.outputs {
        Some(_) => crate::shared::output_set(a.outputs)?,
        None => OutputSet {
            rgb: true,
            depth: metric,
            mask: true,
        },
    };
    if outputs.depth && !metric {
        return Err(errors::invalid(
            "outputs",
            "\"depth\" needs focal and baseline (the depth is metric)",
        ));
    }
    frame.validate().map_err(errors::from_library)?;
    let (w, h) = (mid.width, mid.height);
    let job = Job {
        frame,
        mid,
        method,
        fixation,
        // The fill reads both planes whatever is returned.
        wanted: CyclopeanOutputs {
            color: outputs.rgb || a.fill,
            depth: outputs.depth || a.fill,
        },
        fill: a.fill,
    };

    // The inputs were copied out of numpy above; see SameThread for why the move is sound.
    let work = SameThread((gpu, job));
    let result = py.detach(move || {
        let work = work;
        let (gpu, job) = work.0;
        SameThread(render(&gpu, &job))
    });
    let (setup_ms, out, timing) = result.0.map_err(errors::from_library)?;

    let d = PyDict::new(py);
    let rendered = |s: &u8| *s != 0 && *s != FILLED;
    let valid = out.sources.iter().filter(|s| rendered(s)).count();
    d.set_item("coverage", valid as f64 / out.sources.len() as f64)?;
    let timings = PyDict::new(py);
    timings.set_item("setup_ms", setup_ms)?;
    timings.set_item("render_ms", timing.wall_ms)?;
    timings.set_item("gpu_ms", timing.gpu_ms)?;
    d.set_item("timings", timings)?;
    // The forward method renders colour and depth whatever was asked: keep only what was.
    if let Some(img) = out.color.filter(|_| outputs.rgb) {
        d.set_item("rgb", arrays::rgb_array(py, img))?;
    }
    if let Some(z) = out.depth.filter(|_| outputs.depth) {
        d.set_item("depth", arrays::depth_array(py, z))?;
    }
    if outputs.mask {
        let mask = viewsynth::io::Mask::new(w, h, out.sources.iter().map(|s| rendered(s) as u8).collect())
            .map_err(errors::from_library)?;
        d.set_item("mask", arrays::mask_array(py, mask))?;
    }
    if a.fill {
        let filled = viewsynth::io::Mask::new(w, h, out.sources.iter().map(|s| (*s == FILLED) as u8).collect())
            .map_err(errors::from_library)?;
        d.set_item("filled", arrays::mask_array(py, filled))?;
    }
    Ok(d)
}
