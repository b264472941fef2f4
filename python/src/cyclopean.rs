//! `Renderer.cyclopean` (the method in its own `#[pymethods]` block, its keyword arguments
//! filling the library's `CyclopeanRequest`): the library calls of `viewsynth cyclopean`, numpy
//! in and out, for both of its set-ups: a rectified pair with disparities (`--left-disparity
//! ...`), or any pair with depth placed by a camera file (`--left-depth ... --cameras`). The
//! cameras come as the file's path or as a dict with the file's keys, read by the library's own
//! `CameraFile` parser (K, R, t converted to GL matrices exactly as for the CLI); see
//! `camera_json` for the dict.

use crate::arrays;
use crate::backend::Backend;
use crate::errors;
use crate::errors::Kind;
use crate::renderer::Renderer;
use crate::shared::{choice, outputs_given, SameThread};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use viewsynth::cyclopean::pipeline::{CyclopeanPlan, Framed, InputName, StereoInput, StereoKind, Synthesised};
use viewsynth::io::{DepthMap, RgbImage, MASK_FILLED};
use viewsynth::job::cyclopean::{CyclopeanRequest, StereoGiven};
use viewsynth::pass::ToDevice;
use viewsynth::stereo::camera_file::CameraFile;
use viewsynth::stereo::one_eye::other_eye_disparity;
use viewsynth::stereo::Eye;

/// The arguments of one call, as Python gave them.
struct CyclopeanArgs<'a, 'py> {
    pub left_rgb: &'a Bound<'py, PyAny>,
    pub right_rgb: &'a Bound<'py, PyAny>,
    pub left_disparity: Option<&'a Bound<'py, PyAny>>,
    pub right_disparity: Option<&'a Bound<'py, PyAny>>,
    pub left_depth: Option<&'a Bound<'py, PyAny>>,
    pub right_depth: Option<&'a Bound<'py, PyAny>>,
    pub cameras: Option<&'a Bound<'py, PyAny>>,
    /// Every other keyword argument, named as the library's request names it.
    pub request: CyclopeanRequest,
}

#[pymethods]
impl Renderer {
    #[doc = include_str!("doc/cyclopean.txt")]
    #[allow(clippy::too_many_arguments, clippy::doc_lazy_continuation)] // the doc: Python text
    #[pyo3(signature = (left_rgb, right_rgb, left_disparity = None, right_disparity = None, position = None, *,
                        left_depth = None, right_depth = None, cameras = None, method = None,
                        refine_steps = None, blend = None, z_threshold = None, dominant = None,
                        focal = None, baseline = None, doffs = 0.0, outputs = None, fill = false,
                        max_disparity = None, min_confidence = None, confidence = false, matcher = None))]
    fn cyclopean<'py>(
        &self,
        py: Python<'py>,
        left_rgb: &Bound<'py, PyAny>,
        right_rgb: &Bound<'py, PyAny>,
        left_disparity: Option<&Bound<'py, PyAny>>,
        right_disparity: Option<&Bound<'py, PyAny>>,
        position: Option<f64>,
        left_depth: Option<&Bound<'py, PyAny>>,
        right_depth: Option<&Bound<'py, PyAny>>,
        cameras: Option<&Bound<'py, PyAny>>,
        method: Option<&str>,
        #[pyo3(from_py_with = crate::ints::refine_steps)] refine_steps: Option<u32>,
        blend: Option<&str>,
        z_threshold: Option<f64>,
        dominant: Option<String>,
        focal: Option<f64>,
        baseline: Option<f64>,
        doffs: f64,
        outputs: Option<&Bound<'py, PyAny>>,
        fill: bool,
        #[pyo3(from_py_with = crate::ints::max_disparity)] max_disparity: Option<u32>,
        min_confidence: Option<f64>,
        confidence: bool,
        matcher: Option<&str>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (gpu, _busy) = self.enter()?;
        // The settings as the library's request: it alone decides and checks them.
        let request = CyclopeanRequest {
            method: method.map(|m| choice(viewsynth::Field::Method, m)).transpose()?,
            refine_steps,
            blend: blend.map(|b| choice(viewsynth::Field::Blend, b)).transpose()?,
            z_threshold,
            dominant,
            position,
            focal,
            baseline,
            doffs,
            outputs: outputs_given(outputs)?,
            fill,
            max_disparity: max_disparity.map(|m| m.min(i32::MAX as u32) as i32),
            min_disparity: None,
            min_confidence,
            confidence,
            matcher: matcher.map(|m| choice(viewsynth::Field::Matcher, m)).transpose()?,
        };
        cyclopean(
            py,
            gpu,
            CyclopeanArgs {
                left_rgb,
                right_rgb,
                left_disparity,
                right_disparity,
                left_depth,
                right_depth,
                cameras,
                request,
            },
        )
    }
}

/// The work of one call once validated: render with the GIL released.
fn render(
    gpu: &Backend,
    plan: &CyclopeanPlan,
    input: StereoInput,
) -> viewsynth::Result<(Synthesised, Option<[DepthMap; 2]>)> {
    let names = match plan.kind() {
        StereoKind::Disparity => ["left_rgb", "right_rgb", "left_disparity", "cameras"],
        StereoKind::Images => ["left_rgb", "right_rgb", "left_rgb", "left_rgb"],
        StereoKind::Cameras => ["left_rgb", "right_rgb", "left_depth", "cameras"],
    }
    .map(InputName::Argument);
    let device = gpu.to_device()?;
    let Framed {
        frame,
        mid,
        fixation,
        confidence,
        dense,
        ..
    } = plan.frame(&device, input, names, None)?;
    gpu.check_image_size("the view (cameras[\"middle\"] width/height)", mid.width, mid.height)?;
    Ok((
        plan.synthesise(&device, &frame, &mid, fixation, dense.as_ref(), None)?,
        confidence,
    ))
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

/// Validates `a`, renders the view with the GIL released, and returns the result dict.
fn cyclopean<'py>(py: Python<'py>, gpu: Backend, a: CyclopeanArgs<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    let kind = StereoGiven {
        left_disparity: a.left_disparity.is_some(),
        right_disparity: a.right_disparity.is_some(),
        left_depth: a.left_depth.is_some(),
        right_depth: a.right_depth.is_some(),
        cameras: a.cameras.is_some(),
    }
    .kind()
    .map_err(errors::from_request)?;
    let plan = a.request.plan(kind).map_err(errors::from_request)?;
    let input = match (
        kind,
        a.left_disparity,
        a.right_disparity,
        a.left_depth,
        a.right_depth,
        a.cameras,
    ) {
        (StereoKind::Disparity, Some(ld), Some(rd), ..) => {
            let (left, right) = eyes(&a, [(ld, "left_disparity"), (rd, "right_disparity")])?;
            StereoInput::Disparity { left, right }
        }
        // One eye's disparity: the other eye's is derived by the library's rule (one_eye).
        (StereoKind::Disparity, Some(ld), None, ..) => {
            let (left, mut right) = eyes(&a, [(ld, "left_disparity"), (ld, "left_disparity")])?;
            right.1 = other_eye_disparity(&left.1, Eye::Left);
            StereoInput::Disparity { left, right }
        }
        (StereoKind::Disparity, None, Some(rd), ..) => {
            let (mut left, right) = eyes(&a, [(rd, "right_disparity"), (rd, "right_disparity")])?;
            left.1 = other_eye_disparity(&right.1, Eye::Right);
            StereoInput::Disparity { left, right }
        }
        (StereoKind::Images, ..) => {
            let left = arrays::rgb_image(a.left_rgb, "left_rgb")?;
            let right = arrays::rgb_image(a.right_rgb, "right_rgb")?;
            if (right.width, right.height) != (left.width, left.height) {
                return Err(errors::invalid(
                    "right_rgb",
                    format!(
                        "{}x{} (W x H) differs from left_rgb's {}x{}",
                        right.width, right.height, left.width, left.height
                    ),
                ));
            }
            StereoInput::Images { left, right }
        }
        (StereoKind::Cameras, _, _, Some(ld), Some(rd), Some(cams)) => {
            let cameras = Box::new(camera_file(cams)?);
            let (left, right) = eyes(&a, [(ld, "left_depth"), (rd, "right_depth")])?;
            StereoInput::Cameras { left, right, cameras }
        }
        // StereoGiven::kind only names a set-up whose inputs are all given.
        _ => return Err(errors::invalid("left_rgb", "the stereo inputs make no set-up")),
    };
    let (w, h) = input_size(&input);
    gpu.check_image_size("left_rgb", w, h).map_err(errors::from_library)?;

    let outputs = plan.outputs();
    // The inputs were copied out of numpy above; see SameThread for why the move is sound.
    let work = SameThread((gpu, plan, input));
    let result = py.detach(move || {
        let work = work;
        let (gpu, plan, input) = work.0;
        SameThread(render(&gpu, &plan, input))
    });
    let (done, confidence) = result.0.map_err(errors::from_library)?;

    let d = PyDict::new(py);
    d.set_item("coverage", done.coverage)?;
    let timing = done.view.timing.unwrap_or_default();
    let timings = PyDict::new(py);
    timings.set_item("setup_ms", done.setup_ms)?;
    timings.set_item("render_ms", timing.wall_ms)?;
    timings.set_item("gpu_ms", timing.gpu_ms)?;
    d.set_item("timings", timings)?;
    let (w, h) = (done.view.width, done.view.height);
    if let Some(img) = done.view.color {
        d.set_item("rgb", arrays::rgb_array(py, img))?;
    }
    if let Some(z) = done.view.depth {
        d.set_item("depth", arrays::depth_array(py, z))?;
    }
    let sources = done.view.mask.map(|m| m.data).unwrap_or_default();
    let plane = |f: &dyn Fn(u8) -> bool| {
        viewsynth::io::Mask::new(w, h, sources.iter().map(|s| f(*s) as u8).collect()).map_err(errors::from_library)
    };
    if outputs.mask {
        d.set_item("mask", arrays::mask_array(py, plane(&|s| s == 1)?))?;
    }
    if a.request.fill {
        d.set_item("filled", arrays::mask_array(py, plane(&|s| s == MASK_FILLED)?))?;
    }
    if let Some([left, right]) = confidence {
        d.set_item("left_confidence", arrays::depth_array(py, left))?;
        d.set_item("right_confidence", arrays::depth_array(py, right))?;
    }
    Ok(d)
}

/// The left eye's size (every input was checked to share it).
fn input_size(input: &StereoInput) -> (u32, u32) {
    match input {
        StereoInput::Disparity { left, .. } | StereoInput::Cameras { left, .. } => (left.0.width, left.0.height),
        StereoInput::Images { left, .. } => (left.width, left.height),
    }
}
