//! numpy in: strict checks with messages naming the argument (dtype, shape, alignment), then one
//! copy into the library's owned images (a strided view, e.g. `bgr[..., ::-1]`, a slice or a
//! transpose, is copied in C order by that same one copy). numpy out: the library's buffers handed to numpy without
//! a copy.

use crate::errors;
use numpy::ndarray::{Array2, Array3};
use numpy::{
    dtype, IntoPyArray, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use viewsynth::camera::Intrinsics;
use viewsynth::io::{DepthMap, Mask, RgbImage};

/// A shape as numpy prints it: (72, 96, 3), (5,).
fn shape_text(shape: &[usize]) -> String {
    let items: Vec<String> = shape.iter().map(|n| n.to_string()).collect();
    match items.len() {
        1 => format!("({},)", items[0]),
        _ => format!("({})", items.join(", ")),
    }
}

/// `obj` as a numpy array of element type `T`, aligned, with `ndim` axes (any strides).
fn checked<'py, T: numpy::Element>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    ndim: usize,
    expected: &str,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let py = obj.py();
    let Ok(array) = obj.cast::<PyUntypedArray>() else {
        let ty = obj.get_type().name().map(|n| n.to_string()).unwrap_or_default();
        return Err(errors::invalid(
            name,
            format!("expected a numpy array {expected}, got {ty}"),
        ));
    };
    let dt = array.dtype();
    if !dt.is_equiv_to(&dtype::<T>(py)) {
        return Err(errors::invalid(
            name,
            format!("dtype {dt} but expected {expected} (convert with .astype)"),
        ));
    }
    if array.ndim() != ndim {
        return Err(errors::invalid(
            name,
            format!("shape {} but expected {expected}", shape_text(array.shape())),
        ));
    }
    let aligned: bool = array.getattr("flags")?.getattr("aligned")?.extract()?;
    if !aligned {
        return Err(errors::invalid(
            name,
            format!(
                "array of shape {} is not aligned (a view into a packed buffer); pass numpy.ascontiguousarray({name})",
                shape_text(array.shape())
            ),
        ));
    }
    Ok(array.cast::<PyArrayDyn<T>>()?.clone())
}

/// The elements in C order: one copy, straight from memory when C-contiguous, else walked in
/// logical order through the strides (numpy's own copy would be a second one).
fn c_order<T: numpy::Element + Copy>(array: &Bound<'_, PyArrayDyn<T>>) -> PyResult<Vec<T>> {
    let view = array.readonly();
    // `as_slice` also takes Fortran order, whose memory is not C order: ask for C order itself.
    match array.is_c_contiguous() {
        true => Ok(view.as_slice()?.to_vec()),
        false => Ok(view.as_array().iter().copied().collect()),
    }
}

fn size(shape: &[usize], name: &str) -> PyResult<(u32, u32)> {
    let h = u32::try_from(shape[0]).map_err(|_| errors::invalid(name, format!("{} rows is too many", shape[0])))?;
    let w = u32::try_from(shape[1]).map_err(|_| errors::invalid(name, format!("{} columns is too many", shape[1])))?;
    Ok((w, h))
}

/// uint8[H, W, 3] -> RgbImage (one copy); `name` is the argument named in errors.
pub fn rgb_image(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<RgbImage> {
    let array = checked::<u8>(obj, name, 3, "uint8[H, W, 3]")?;
    let shape = array.shape().to_vec();
    if shape[2] != 3 {
        return Err(errors::invalid(
            name,
            format!(
                "shape {} but expected uint8[H, W, 3] (RGB, no alpha)",
                shape_text(&shape)
            ),
        ));
    }
    let (w, h) = size(&shape, name)?;
    let data = c_order(&array)?;
    RgbImage::new(w, h, data).map_err(errors::from_library)
}

/// float32[H, W] -> DepthMap (one copy): metric depth (view-space Z in metres; 0, NaN, inf or
/// negative = no depth) or disparity (pixels), as `name` says.
pub fn float_map(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<DepthMap> {
    let array = checked::<f32>(obj, name, 2, "float32[H, W]")?;
    let (w, h) = size(array.shape(), name)?;
    let mut data = c_order(&array)?;
    // The library's rule for every depth input: magnitudes no pass computes finitely are holes.
    viewsynth::depth::clear_unusable_depth(&mut data);
    DepthMap::new(w, h, data).map_err(errors::from_library)
}

/// The side N of six square cube faces of `shape` ([6, N, N, ...], at least 2x2); `rest_ok`
/// says whether the dimensions after the faces' are the ones `expected` names.
fn face_side(shape: &[usize], rest_ok: bool, name: &str, expected: &str) -> PyResult<u32> {
    if shape[0] != 6 || shape[1] != shape[2] || !rest_ok {
        return Err(errors::invalid(
            name,
            format!("shape {} but expected {expected}", shape_text(shape)),
        ));
    }
    let (n, _) = size(&shape[1..], name)?;
    if n < 2 {
        return Err(errors::invalid(name, format!("faces of {n}x{n}: at least 2x2 needed")));
    }
    Ok(n)
}

/// The six cube faces of one eye, uint8[6, N, N, 3] (order pz, nz, up, down, px, nx) ->
/// six RgbImages (one copy).
pub fn rgb_faces(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<RgbImage>> {
    let expected = "uint8[6, N, N, 3] (faces pz, nz, up, down, px, nx)";
    let array = checked::<u8>(obj, name, 4, expected)?;
    let shape = array.shape().to_vec();
    let n = face_side(&shape, shape[3] == 3, name, expected)?;
    let data = c_order(&array)?;
    data.chunks_exact(data.len() / 6)
        .map(|face| RgbImage::new(n, n, face.to_vec()).map_err(errors::from_library))
        .collect()
}

/// The six cube faces' view-space Z of one eye, float32[6, N, N] -> six DepthMaps (one copy).
pub fn depth_faces(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<DepthMap>> {
    let expected = "float32[6, N, N] (faces pz, nz, up, down, px, nx)";
    let array = checked::<f32>(obj, name, 3, expected)?;
    let shape = array.shape().to_vec();
    let n = face_side(&shape, true, name, expected)?;
    let data = c_order(&array)?;
    data.chunks_exact(data.len() / 6)
        .map(|face| {
            let mut face = face.to_vec();
            viewsynth::depth::clear_unusable_depth(&mut face);
            DepthMap::new(n, n, face).map_err(errors::from_library)
        })
        .collect()
}

/// A 3x3 pinhole matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] from anything numpy reads as
/// numbers (any float or int dtype, nested lists).
pub fn intrinsics(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Intrinsics> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let converted = np
        .call_method("asarray", (obj,), Some(&kwargs))
        .map_err(|e| errors::invalid(name, format!("expected a 3x3 matrix of numbers: {e}")))?;
    let array = converted
        .cast::<PyArrayDyn<f64>>()
        .map_err(|_| errors::invalid(name, "expected a 3x3 matrix of numbers"))?;
    if array.shape() != [3, 3] {
        return Err(errors::invalid(
            name,
            format!("shape {} but expected a 3x3 matrix", shape_text(array.shape())),
        ));
    }
    let m = array.readonly();
    let m = m.as_array();
    let at = |r: usize, c: usize| m[[r, c]];
    for v in m.iter() {
        if !v.is_finite() {
            return Err(errors::invalid(name, format!("{v} is not finite")));
        }
    }
    // The library's cameras are pinhole without skew: any other entry would be silently ignored.
    let fixed = [
        ((0, 1), 0.0),
        ((1, 0), 0.0),
        ((2, 0), 0.0),
        ((2, 1), 0.0),
        ((2, 2), 1.0),
    ];
    for ((r, c), want) in fixed {
        if at(r, c) != want {
            return Err(errors::invalid(
                name,
                format!(
                    "{name}[{r}, {c}] is {} but must be {want} (pinhole [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], no skew)",
                    at(r, c)
                ),
            ));
        }
    }
    let k = Intrinsics {
        fx: at(0, 0),
        fy: at(1, 1),
        cx: at(0, 2),
        cy: at(1, 2),
    };
    k.validate(name).map_err(errors::from_library)?;
    Ok(k)
}

/// The 3x3 matrix of `k` as a float64 array.
pub fn k_matrix<'py>(py: Python<'py>, k: &Intrinsics) -> Bound<'py, PyAny> {
    let m = Array2::from_shape_vec((3, 3), vec![k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0])
        .expect("3x3 from 9 values");
    m.into_pyarray(py).into_any()
}

// The library's images are row-major with the shapes below, so from_shape_vec cannot fail; the
// Vec moves into numpy (no copy).

pub fn rgb_array(py: Python<'_>, img: RgbImage) -> Bound<'_, PyAny> {
    let (w, h) = (img.width as usize, img.height as usize);
    Array3::from_shape_vec((h, w, 3), img.data)
        .expect("RgbImage holds H*W*3 bytes")
        .into_pyarray(py)
        .into_any()
}

pub fn depth_array(py: Python<'_>, depth: DepthMap) -> Bound<'_, PyAny> {
    let (w, h) = (depth.width as usize, depth.height as usize);
    Array2::from_shape_vec((h, w), depth.data)
        .expect("DepthMap holds H*W values")
        .into_pyarray(py)
        .into_any()
}

/// The mask as bool[H, W] (the library's 0/1 bytes; one pass to make them bools).
pub fn mask_array(py: Python<'_>, mask: Mask) -> Bound<'_, PyAny> {
    let (w, h) = (mask.width as usize, mask.height as usize);
    let data: Vec<bool> = mask.data.into_iter().map(|m| m != 0).collect();
    Array2::from_shape_vec((h, w), data)
        .expect("Mask holds H*W values")
        .into_pyarray(py)
        .into_any()
}
