//! The library's typed errors as the Python exception classes of `viewsynth.errors`, carrying
//! the library's message unchanged.

use pyo3::prelude::*;
use pyo3::types::PyType;
use viewsynth::Error;

/// Which class of `viewsynth/errors.py` a failure belongs to.
#[derive(Clone, Copy)]
pub enum Kind {
    /// Bad argument: wrong dtype, shape, layout, or a value out of its domain (a ValueError).
    InvalidInput,
    /// No EGL / GL 4.5 context, or only a software one when a GPU was required.
    GpuUnavailable,
    /// A GL call or object failed.
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

/// The library's error as its Python class, with the library's own message.
pub fn from_library(e: Error) -> PyErr {
    let message = e.to_string();
    match &e {
        Error::InvalidParameter { name, .. } => raise(Kind::InvalidInput, message, Some(&name.to_string())),
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

/// A command-line option as the keyword argument that gives the same request field
/// (tests/data/front_ends.json maps them all): `--tau-rel` -> `tau_rel`; `--from`/`--to` ->
/// `source`/`target` (`from` is a Python keyword); refocus's target options -> `scales`,
/// `size`, `principal`; `--force` -> `resume`.
pub fn keyword(option: &str) -> String {
    match option.trim_start_matches('-') {
        "from" => "source".to_string(),
        "to" => "target".to_string(),
        "zoom-range" => "scales".to_string(),
        "width-out" | "height-out" => "size".to_string(),
        "cx-out" | "cy-out" => "principal".to_string(),
        "force" => "resume".to_string(),
        name => name.replace('-', "_"),
    }
}

/// `text` with each `--option` written as its keyword argument.
fn keywords_in(text: &str) -> (String, Option<String>) {
    let mut out = String::with_capacity(text.len());
    let mut first = None;
    let mut rest = text;
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let tail = &rest[at + 2..];
        let len = tail
            .find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'))
            .unwrap_or(tail.len());
        match len {
            0 => out.push_str("--"),
            _ => {
                let kw = keyword(&tail[..len]);
                first.get_or_insert_with(|| kw.clone());
                out.push_str(&kw);
            }
        }
        rest = &tail[len..];
    }
    out.push_str(rest);
    (out, first)
}

/// A request the library refused (the CLI's usage errors), worded for Python: options become
/// keyword arguments, and `parameter` is the field the library named, else the first option
/// in the message.
pub fn from_request(e: viewsynth::job::ArgError) -> PyErr {
    use std::error::Error as _;
    // A file or GPU failure found while checking is no bad argument: its own class.
    let e = match e {
        viewsynth::job::ArgError::Invalid(lib) if !matches!(lib, Error::InvalidParameter { .. }) => {
            return from_library(lib)
        }
        e => e,
    };
    let mut chain = e.to_string();
    let mut named = None;
    let mut source = e.source();
    while let Some(s) = source {
        chain.push_str(&format!(": {s}"));
        if let Some(Error::InvalidParameter { name, .. }) = s.downcast_ref::<Error>() {
            named = Some(name.to_string());
        }
        source = s.source();
    }
    if let viewsynth::job::ArgError::Invalid(Error::InvalidParameter { name, .. }) = &e {
        named = Some(name.to_string());
    }
    let (message, first) = keywords_in(&chain);
    let parameter = named
        .map(|n| keywords_in(&n).0.split('/').next().unwrap_or_default().to_string())
        .or(first);
    let message = match message.starts_with("invalid ") {
        true => message,
        false => format!("invalid {}: {message}", parameter.as_deref().unwrap_or("argument")),
    };
    raise(Kind::InvalidInput, message, parameter.as_deref())
}
