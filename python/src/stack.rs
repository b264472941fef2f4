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
