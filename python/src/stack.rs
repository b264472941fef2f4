//! `Renderer.refocus` on stacks: rgb uint8[N, H, W, 3] with depth float32[N, H, W] (and K one
//! 3x3 matrix for all, or float64[N, 3, 3]) are N frames, each refocused as a single call would
//! (the result is a list of N lists of views).

use crate::errors;
use numpy::{PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// A stack's frames as (rgb, depth, K) items, or None when `rgb` is a single frame.
#[allow(clippy::type_complexity, non_snake_case)]
pub fn frames<'py>(
    rgb: &Bound<'py, PyAny>,
    depth: &Bound<'py, PyAny>,
    K: &Bound<'py, PyAny>,
) -> PyResult<Option<Vec<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)>>> {
    let Ok(stack) = rgb.cast::<PyUntypedArray>() else {
        return Ok(None);
    };
    if stack.ndim() != 4 {
        return Ok(None);
    }
    let n = stack.shape()[0];
    let depth_n = depth
        .cast::<PyUntypedArray>()
        .ok()
        .filter(|d| d.ndim() == 3)
        .map(|d| d.shape()[0]);
    if depth_n != Some(n) {
        return Err(errors::invalid(
            "depth",
            format!("rgb is a stack of {n} frames (N, H, W, 3): expected depth float32[{n}, H, W]"),
        ));
    }
    let per_frame_k = K.cast::<PyUntypedArray>().is_ok_and(|k| k.ndim() == 3);
    if per_frame_k && K.len()? != n {
        return Err(errors::invalid(
            "K",
            format!("a stack of {n} frames takes one 3x3 K or {n} of them (N, 3, 3)"),
        ));
    }
    (0..n)
        .map(|i| {
            let k = if per_frame_k { K.get_item(i)? } else { K.clone() };
            Ok((rgb.get_item(i)?, depth.get_item(i)?, k))
        })
        .collect::<PyResult<Vec<_>>>()
        .map(Some)
}

/// `scales` as given: one list for every frame, or (a stack only) one list per sample, as
/// Kornia-style augmentation draws them: a list of lists, or a float array (N, k).
pub enum Scales {
    /// One list of scales for the frame or for every frame of a stack.
    Shared(Vec<f64>),
    /// A list of scales per frame of a stack.
    PerSample(Vec<Vec<f64>>),
}

/// Reads `scales`: a 1-D array or a flat sequence is [`Scales::Shared`]; a 2-D array, or a
/// sequence whose items are sequences, is [`Scales::PerSample`]. The array's dimensions decide
/// (not whether an item converts to a float: a (N, 1) array's rows would).
pub fn scales(given: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Scales>> {
    let Some(given) = given else { return Ok(None) };
    let expected = "expected a list of numbers, or per sample of a stack a list of lists or an (N, k) array";
    let floats = |item: &Bound<'_, PyAny>, what: &str| {
        item.extract::<Vec<f64>>()
            .map_err(|_| errors::invalid("scales", format!("{what}: {expected}")))
    };
    let nested = match given.cast::<PyUntypedArray>() {
        Ok(array) => match array.ndim() {
            1 => false,
            2 => true,
            d => return Err(errors::invalid("scales", format!("a {d}-D array: {expected}"))),
        },
        Err(_) => {
            let is_sequence = |o: &Bound<'_, PyAny>| {
                o.cast::<PyUntypedArray>().is_ok()
                    || o.cast::<pyo3::types::PyList>().is_ok()
                    || o.cast::<pyo3::types::PyTuple>().is_ok()
            };
            given.len().is_ok() && given.len()? > 0 && is_sequence(&given.get_item(0)?)
        }
    };
    if !nested {
        return Ok(Some(Scales::Shared(floats(given, "scales")?)));
    }
    let mut rows = Vec::new();
    for (i, row) in given.try_iter()?.enumerate() {
        rows.push(floats(&row?, &format!("scales[{i}]"))?);
    }
    Ok(Some(Scales::PerSample(rows)))
}

impl Scales {
    /// The scales of each of `n` frames (`n` None: a single frame), or why they do not fit.
    pub fn per_frame(self, n: Option<usize>) -> PyResult<Vec<Vec<f64>>> {
        match (self, n) {
            (Scales::Shared(s), None) => Ok(vec![s]),
            (Scales::Shared(s), Some(n)) => Ok(vec![s; n]),
            (Scales::PerSample(_), None) => Err(errors::invalid(
                "scales",
                "a list per sample is for a stack (rgb uint8[N, H, W, 3]); one frame takes one list",
            )),
            (Scales::PerSample(rows), Some(n)) if rows.len() != n => Err(errors::invalid(
                "scales",
                format!(
                    "{} lists of scales for a stack of {n} frames: give one per frame",
                    rows.len()
                ),
            )),
            (Scales::PerSample(rows), Some(_)) => Ok(rows),
        }
    }
}
