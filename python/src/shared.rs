//! Helpers every binding uses (the capability modules, their `Renderer` methods, `index`), kept
//! apart from any one of them so that no binding imports from a sibling capability.

use crate::errors;
use pyo3::prelude::*;
use pyo3::types::PyString;
use viewsynth::refocus::OutputSet;

/// Moves a value into `Python::detach`, whose closure runs synchronously on the calling thread.
/// The `Gpu` inside is an `Rc`: it is sound here because nothing else can reach it while the GIL
/// is released (the Renderer's handle is `ThreadBound`, refused to every other thread, and the
/// call holds a mutable borrow of the Renderer until detach returns).
pub(crate) struct SameThread<T>(pub(crate) T);
// SAFETY: see above; the value never leaves the thread that made it.
unsafe impl<T> Send for SameThread<T> {}

/// A named choice keyword argument (`method="seed"`), parsed by the library's names for it;
/// `option` is the request field it fills (errors name its keyword argument).
pub(crate) fn choice<T: serde::de::DeserializeOwned>(option: viewsynth::Field, text: &str) -> PyResult<T> {
    viewsynth::job::choice(option, text).map_err(errors::from_request)
}

/// `outputs=` where None leaves the choice to the library's request.
pub(crate) fn outputs_given(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<OutputSet>> {
    obj.map(|_| output_set(obj)).transpose()
}

/// `outputs=`: a name or a sequence of "rgb", "depth", "mask" (None: all three).
pub(crate) fn output_set(obj: Option<&Bound<'_, PyAny>>) -> PyResult<OutputSet> {
    let Some(obj) = obj else {
        return Ok(OutputSet::default());
    };
    let list: Vec<String> = if let Ok(s) = obj.cast::<PyString>() {
        vec![s.to_string()]
    } else {
        obj.extract()
            .map_err(|_| errors::invalid("outputs", "expected a sequence of \"rgb\", \"depth\", \"mask\""))?
    };
    OutputSet::parse(&list.join(",")).map_err(errors::from_library)
}
