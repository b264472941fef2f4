//! The library's typed errors as the Python exception classes of `viewsynth.errors`, carrying
//! the library's message with the fields it names spelled as Python's keyword arguments.

use pyo3::prelude::*;
use pyo3::types::PyType;
use viewsynth::{Error, Message, Spelling};

/// Which class of `viewsynth/errors.py` a failure belongs to.
#[derive(Clone, Copy)]
pub enum Kind {
    /// Bad argument: wrong dtype, shape, layout, or a value out of its domain (a ValueError).
    InvalidInput,
    /// No EGL / GL 4.5 context, or only a software one when a GPU was required.
    GpuUnavailable,
    /// A call of the graphics API (OpenGL or Vulkan) or one of its objects failed.
    Gpu,
    /// A file could not be read, decoded or written (an OSError).
    File,
    /// A Renderer used in a process forked after it was created.
    Forked,
    /// A Renderer used after `close()`.
    Closed,
    /// A Renderer used on a thread other than its creator's.
    WrongThread,
    /// A Renderer used (to render or close) from inside one of its own calls.
    Busy,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::InvalidInput => "InvalidInputError",
            Kind::GpuUnavailable => "GpuUnavailableError",
            Kind::Gpu => "GpuError",
            Kind::File => "FileError",
            Kind::Forked => "RendererForkedError",
            Kind::Closed => "RendererClosedError",
            Kind::WrongThread => "WrongThreadError",
            Kind::Busy => "RendererBusyError",
        }
    }
}

fn class<'py>(py: Python<'py>, kind: Kind) -> PyResult<Bound<'py, PyType>> {
    let module = py.import("viewsynth.errors")?;
    Ok(module.getattr(kind.class_name())?.cast_into::<PyType>()?)
}

/// A Python exception of `kind` with `message`; `parameter` (when known) becomes its attribute.
pub fn raise(kind: Kind, message: impl Into<String>, parameter: Option<&str>) -> PyErr {
    let message = message.into();
    Python::attach(|py| {
        let built = class(py, kind).and_then(|cls| {
            let exc = cls.call1((message.clone(),))?;
            exc.setattr("parameter", parameter)?;
            Ok(PyErr::from_value(exc))
        });
        // Only a broken installation (viewsynth.errors missing) gets here; keep the message.
        built.unwrap_or_else(|e| {
            pyo3::exceptions::PyRuntimeError::new_err(format!("{message} (and viewsynth.errors failed: {e})"))
        })
    })
}

/// A bad-argument error naming the parameter.
pub fn invalid(parameter: &str, message: impl std::fmt::Display) -> PyErr {
    raise(
        Kind::InvalidInput,
        format!("invalid {parameter}: {message}"),
        Some(parameter),
    )
}

/// The library's error as its Python class, with the library's own message, the fields it
/// names spelled as keyword arguments.
pub fn from_library(e: Error) -> PyErr {
    let message = e.spelled(Spelling::Python);
    match &e {
        Error::InvalidParameter { name, .. } => raise(Kind::InvalidInput, message, Some(&parameter(name))),
        Error::ImageTooLarge { name, .. } => raise(Kind::InvalidInput, message, Some(name)),
        Error::SizeMismatch { .. } => raise(Kind::InvalidInput, message, None),
        Error::Egl(_) | Error::SoftwareRenderer { .. } => raise(Kind::GpuUnavailable, message, None),
        Error::Gl(_) | Error::Vulkan(_) | Error::Readback { .. } => raise(Kind::Gpu, message, None),
        Error::Io { .. } | Error::Decode { .. } | Error::Encode { .. } => raise(Kind::File, message, None),
        // Python's own class for it: the host could not allocate an image-sized buffer.
        Error::OutOfMemory { .. } => pyo3::exceptions::PyMemoryError::new_err(message),
        // `Error` is non-exhaustive: a variant added later and not classed here yet keeps its
        // message, as a plain RuntimeError.
        _ => pyo3::exceptions::PyRuntimeError::new_err(message),
    }
}

/// The keyword a library error's parameter names: its first field's (`--near/--far` -> `near`),
/// else the library's own name for it, up to a `/`.
fn parameter(name: &Message) -> String {
    match name.fields().next() {
        Some(field) => field.python().to_string(),
        None => name.to_string().split('/').next().unwrap_or_default().to_string(),
    }
}

/// A request the library refused (the CLI's usage errors), worded for Python: the fields it
/// names are keyword arguments, and `parameter` is the one a library error inside names, else
/// the first field named.
pub fn from_request(e: viewsynth::job::ArgError) -> PyErr {
    use std::error::Error as _;
    // A file or GPU failure found while checking is no bad argument: its own class.
    let e = match e {
        viewsynth::job::ArgError::Invalid(lib) if !matches!(lib, Error::InvalidParameter { .. }) => {
            return from_library(lib)
        }
        e => e,
    };
    let mut message = e.spelled(Spelling::Python);
    let mut fields = e.fields();
    let mut named = match &e {
        viewsynth::job::ArgError::Invalid(Error::InvalidParameter { name, .. }) => Some(parameter(name)),
        _ => None,
    };
    let mut source = e.source();
    while let Some(s) = source {
        match s.downcast_ref::<Error>() {
            Some(lib) => {
                message.push_str(&format!(": {}", lib.spelled(Spelling::Python)));
                fields.extend(lib.fields());
                if let Error::InvalidParameter { name, .. } = lib {
                    named.get_or_insert_with(|| parameter(name));
                }
            }
            None => message.push_str(&format!(": {s}")),
        }
        source = s.source();
    }
    let parameter = named.or_else(|| fields.first().map(|f| f.python().to_string()));
    let message = match message.starts_with("invalid ") {
        true => message,
        false => format!("invalid {}: {message}", parameter.as_deref().unwrap_or("argument")),
    };
    raise(Kind::InvalidInput, message, parameter.as_deref())
}
