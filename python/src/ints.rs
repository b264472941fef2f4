//! Integer keyword arguments (`size`, `jobs`, `steps`, `refine_steps`, `width`, `height`), extracted here rather
//! than by pyo3, whose conversion of -1 or 2**40 to an unsigned type raises a bare
//! OverflowError naming no argument. Every one goes through [`int`]: anything that is not an
//! integer (operator.index refuses it; bool too) is a TypeError, and an integer outside the
//! type's range an InvalidInputError (a ValueError), both naming the argument.

use crate::errors;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyBool;

/// `obj` as an integer in 0..=`max`, or an error naming `name`.
fn int(obj: &Bound<'_, PyAny>, name: &str, max: u64) -> PyResult<u64> {
    let py = obj.py();
    let type_error = || {
        let ty = obj
            .get_type()
            .name()
            .map_or_else(|_| "?".to_string(), |n| n.to_string());
        PyTypeError::new_err(format!("invalid {name}: expected an integer, got {ty}"))
    };
    // True and False are ints to Python, but never a size or a count.
    if obj.is_instance_of::<PyBool>() {
        return Err(type_error());
    }
    // numpy integers are fine, floats (even 3.0) are not: operator.index is Python's own rule.
    let value = py
        .import("operator")?
        .call_method1("index", (obj,))
        .map_err(|_| type_error())?;
    // Compared as Python ints: a value of any size is judged without an overflow.
    if value.lt(0)? || value.gt(max)? {
        let text = value.str().map_or_else(|_| "?".to_string(), |s| s.to_string());
        return Err(errors::invalid(
            name,
            format!("{}: expected an integer in 0..={max}", viewsynth::error::excerpt(&text)),
        ));
    }
    value.extract::<u64>()
}

fn u32_of(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<u32> {
    // In range by the check above.
    int(obj, name, u32::MAX.into()).map(|v| v as u32)
}

/// An optional (width, height) pair of u32.
fn size_of(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Option<(u32, u32)>> {
    if obj.is_none() {
        return Ok(None);
    }
    let items: Vec<Bound<'_, PyAny>> = match obj.try_iter() {
        Ok(it) if !obj.is_instance_of::<pyo3::types::PyString>() => it.collect::<PyResult<_>>()?,
        _ => {
            return Err(PyTypeError::new_err(format!(
                "invalid {name}: expected a (width, height) pair of integers"
            )))
        }
    };
    let [w, h] = items.as_slice() else {
        return Err(errors::invalid(
            name,
            format!("{} items: expected a (width, height) pair", items.len()),
        ));
    };
    Ok(Some((
        u32_of(w, &format!("{name}[0] (width)"))?,
        u32_of(h, &format!("{name}[1] (height)"))?,
    )))
}

/// `size=(width, height)` or None.
pub fn size(obj: &Bound<'_, PyAny>) -> PyResult<Option<(u32, u32)>> {
    size_of(obj, "size")
}

/// `jobs=` or None.
pub fn jobs(obj: &Bound<'_, PyAny>) -> PyResult<Option<usize>> {
    if obj.is_none() {
        return Ok(None);
    }
    int(obj, "jobs", usize::MAX as u64).map(|v| Some(v as usize))
}

/// `steps=`.
pub fn steps(obj: &Bound<'_, PyAny>) -> PyResult<u32> {
    u32_of(obj, "steps")
}

/// `width=`.
pub fn width(obj: &Bound<'_, PyAny>) -> PyResult<u32> {
    u32_of(obj, "width")
}

/// `height=`.
pub fn height(obj: &Bound<'_, PyAny>) -> PyResult<u32> {
    u32_of(obj, "height")
}

/// `refine_steps=` or None.
pub fn refine_steps(obj: &Bound<'_, PyAny>) -> PyResult<Option<u32>> {
    match obj.is_none() {
        true => Ok(None),
        false => u32_of(obj, "refine_steps").map(Some),
    }
}

/// `max_disparity=` or None.
pub fn max_disparity(obj: &Bound<'_, PyAny>) -> PyResult<Option<u32>> {
    match obj.is_none() {
        true => Ok(None),
        false => u32_of(obj, "max_disparity").map(Some),
    }
}
