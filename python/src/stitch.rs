//! `Renderer.stitch` (the method in its own `#[pymethods]` block): an omni-directional stereo
//! (ODS) 360 from each eye's six over-wide cube faces, numpy in and out: the library calls of
//! `viewsynth stitch --faces DIR` with the same defaults and checks, the faces given as stacked
//! arrays instead of a folder.

use crate::arrays;
use crate::backend::Backend;
use crate::errors;
use crate::renderer::Renderer;
use crate::shared::{choice, outputs_given, SameThread};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use viewsynth::convention::{Conventions, RowOrder};
use viewsynth::depth::DepthEncoding;
use viewsynth::io::{DepthMap, RgbImage};
use viewsynth::job::stitch::{StitchPlan, StitchRequest};
use viewsynth::output::OutputSet;
use viewsynth::stitch::faces::{faces_from_images, view_z_of};
use viewsynth::stitch::render::{StitchOutput, StitchRenderer};
use viewsynth::stitch::{FaceSet, OdsRig, Side, StitchParams};

/// The arguments of one call, as Python gave them.
struct StitchArgs<'a, 'py> {
    pub left_rgb: &'a Bound<'py, PyAny>,
    pub left_depth: &'a Bound<'py, PyAny>,
    pub right_rgb: &'a Bound<'py, PyAny>,
    pub right_depth: &'a Bound<'py, PyAny>,
    pub fov: Option<f64>,
    pub overlap: Option<f64>,
    pub method: &'a str,
    pub width: u32,
    pub height: u32,
    pub ipd: f64,
    pub pole_fade: f64,
    pub depth_kind: &'a str,
    pub near: Option<f64>,
    pub far: Option<f64>,
    pub ndc: &'a str,
    pub reversed_z: bool,
    pub outputs: Option<&'a Bound<'py, PyAny>>,
}

#[pymethods]
impl Renderer {
    #[doc = include_str!("doc/stitch.txt")]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (left_rgb, left_depth, right_rgb, right_depth, *, fov = None, overlap = None,
                        method = "reproject", width = 2048, height = 1024, ipd = 0.064, pole_fade = 45.0,
                        depth_kind = "view-z", near = None, far = None, ndc = "gl", reversed_z = false,
                        outputs = None))]
    fn stitch<'py>(
        &self,
        py: Python<'py>,
        left_rgb: &Bound<'py, PyAny>,
        left_depth: &Bound<'py, PyAny>,
        right_rgb: &Bound<'py, PyAny>,
        right_depth: &Bound<'py, PyAny>,
        fov: Option<f64>,
        overlap: Option<f64>,
        method: &str,
        #[pyo3(from_py_with = crate::ints::width)] width: u32,
        #[pyo3(from_py_with = crate::ints::height)] height: u32,
        ipd: f64,
        pole_fade: f64,
        depth_kind: &str,
        near: Option<f64>,
        far: Option<f64>,
        ndc: &str,
        reversed_z: bool,
        outputs: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (gpu, _busy) = self.enter()?;
        stitch(
            py,
            gpu,
            StitchArgs {
                left_rgb,
                left_depth,
                right_rgb,
                right_depth,
                fov,
                overlap,
                method,
                width,
                height,
                ipd,
                pole_fade,
                depth_kind,
                near,
                far,
                ndc,
                reversed_z,
                outputs,
            },
        )
    }
}

impl StitchArgs<'_, '_> {
    /// The settings as the library's request (choices parsed by the library's names).
    fn request(&self) -> PyResult<StitchRequest> {
        Ok(StitchRequest {
            fov: self.fov,
            overlap: self.overlap,
            method: choice(viewsynth::Field::Method, self.method)?,
            width: self.width,
            height: self.height,
            ipd: self.ipd,
            pole_fade: self.pole_fade,
            depth_kind: choice(viewsynth::Field::DepthKind, self.depth_kind)?,
            near: self.near,
            far: self.far,
            ndc: choice(viewsynth::Field::Ndc, self.ndc)?,
            reversed_z: self.reversed_z,
            outputs: outputs_given(self.outputs)?,
        })
    }
}

/// One eye's six faces as the library's face set (device depth converted to view Z).
fn face_set(
    rig: &OdsRig,
    side: Side,
    fov: f64,
    (colours, depths): (Vec<RgbImage>, Vec<DepthMap>),
    kind: &DepthEncoding,
    conv: &Conventions,
) -> PyResult<FaceSet> {
    let mut images = Vec::with_capacity(6);
    for (c, d) in colours.into_iter().zip(depths) {
        images.push((c, view_z_of(&d, kind, conv).map_err(errors::from_library)?));
    }
    faces_from_images(rig, side, fov, images).map_err(errors::from_library)
}

/// One eye's faces from its two arrays, checked against each other.
fn eye_faces(rgb: &Bound<'_, PyAny>, depth: &Bound<'_, PyAny>, eye: &str) -> PyResult<(Vec<RgbImage>, Vec<DepthMap>)> {
    let (rgb_name, depth_name) = (format!("{eye}_rgb"), format!("{eye}_depth"));
    let colours = arrays::rgb_faces(rgb, &rgb_name)?;
    let depths = arrays::depth_faces(depth, &depth_name)?;
    let (n, m) = (colours[0].width, depths[0].width);
    if n != m {
        return Err(errors::invalid(
            &depth_name,
            format!("faces of {m}x{m} but {rgb_name}'s are {n}x{n}"),
        ));
    }
    Ok((colours, depths))
}

fn render(
    gpu: &Backend,
    left: &FaceSet,
    right: &FaceSet,
    params: &StitchParams,
    conv: &Conventions,
    outputs: OutputSet,
) -> viewsynth::Result<(f64, StitchOutput)> {
    let t0 = std::time::Instant::now();
    let mut renderer = StitchRenderer::with_conventions(gpu, left, right, *conv)?;
    let setup_ms = t0.elapsed().as_secs_f64() * 1e3;
    let out = renderer.render_outputs(params, outputs)?;
    Ok((setup_ms, out))
}

/// Validates `a`, stitches both eyes with the GIL released, and returns the result dict.
fn stitch<'py>(py: Python<'py>, gpu: Backend, a: StitchArgs<'_, 'py>) -> PyResult<Bound<'py, PyDict>> {
    // The faces' own frame: the circle centre only translates the face eyes and the ODS rays
    // together (as the CLI's --faces); arrays are top-down, as the CLI's files.
    let base = OdsRig {
        centre: [0.0; 3],
        ..OdsRig::demo()
    };
    let plan = a
        .request()?
        .plan(base, RowOrder::default())
        .map_err(errors::from_request)?;
    let StitchPlan {
        fov,
        rig,
        params,
        depth_kind: kind,
        conventions: conv,
        outputs,
    } = plan;
    let overlap = params.overlap_deg;
    let left = eye_faces(a.left_rgb, a.left_depth, "left")?;
    let right = eye_faces(a.right_rgb, a.right_depth, "right")?;
    let (n, m) = (left.0[0].width, right.0[0].width);
    if n != m {
        return Err(errors::invalid(
            "right_rgb",
            format!("faces of {m}x{m} but the left eye's are {n}x{n}"),
        ));
    }
    let left = face_set(&rig, Side::Left, fov, left, &kind, &conv)?;
    let right = face_set(&rig, Side::Right, fov, right, &kind, &conv)?;

    // The inputs were copied out of numpy above; see SameThread for why the move is sound.
    let work = SameThread((gpu, left, right, params, conv));
    let result = py.detach(move || {
        let work = work;
        let (gpu, left, right, params, conv) = work.0;
        SameThread(render(&gpu, &left, &right, &params, &conv, outputs))
    });
    let (setup_ms, out) = result.0.map_err(errors::from_library)?;
    let timing = out.timing;

    let d = PyDict::new(py);
    // Each eye is `height` rows of the W x 2H image; the eyes are views of the top-bottom
    // array (left on top), no copy.
    let h = params.height as isize;
    let eyes = |whole: &Bound<'py, PyAny>, left: &str, right: &str| -> PyResult<()> {
        d.set_item(left, whole.get_item(pyo3::types::PySlice::new(py, 0, h, 1))?)?;
        d.set_item(right, whole.get_item(pyo3::types::PySlice::new(py, h, 2 * h, 1))?)
    };
    if let Some(img) = out.color {
        let top_bottom = arrays::rgb_array(py, img);
        eyes(&top_bottom, "left", "right")?;
        d.set_item("rgb", top_bottom)?;
    }
    if let Some(distance) = out.distance {
        let top_bottom = arrays::depth_array(py, distance);
        eyes(&top_bottom, "left_depth", "right_depth")?;
        d.set_item("depth", top_bottom)?;
    }
    d.set_item("fov", fov)?;
    d.set_item("overlap", overlap)?;
    let timings = PyDict::new(py);
    timings.set_item("setup_ms", setup_ms)?;
    timings.set_item("render_ms", timing.wall_ms)?;
    timings.set_item("gpu_ms", timing.gpu_ms)?;
    d.set_item("timings", timings)?;
    Ok(d)
}
