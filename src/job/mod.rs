//! Jobs: one validated description per `viewsynth` command, and the code that runs it.
//!
//! The command line is turned into a job before any work starts (the binary's `args.rs` per
//! command, in the spirit of ripgrep's low-level flags -> high-level arguments): every option
//! is parsed, range-checked and checked against the others in that conversion, and a refusal
//! is an [`ArgError`] naming the option. A job then only runs: it reads its inputs, asks its
//! [`Host`] for a GPU when it is about to render, and writes its files all-or-none. What it
//! has to tell a person (input-depth summaries, progress, the result) goes through the host as
//! an [`Event`] or comes back as a typed report, so the library prints nothing.

mod depth_file;
mod error;
mod files;
mod host;
mod intrinsics;

#[cfg(feature = "compare")]
pub mod compare;
pub mod cyclopean;
pub mod manifest;
pub mod refocus;
pub mod reproject;
pub mod scene;
pub mod stitch;

pub use depth_file::{DepthFileReading, DepthFileRequest};
pub use error::{ArgError, InContext, JobError, PerFrameOption};
pub use files::{depth_formats, file_formats, png_compression, FileOptions};
pub use host::{Backend, Event, GpuRequest, Host};
pub use intrinsics::SourceIntrinsics;

/// Largest magnitude of a real-valued option (pixels, metres, degrees, scales): far beyond any
/// camera, and small enough that f32 GPU maths keeps meaning.
pub const MAX_OPTION_MAGNITUDE: f64 = 1e6;

/// A finite number with magnitude at most [`MAX_OPTION_MAGNITUDE`] (the rule of every
/// real-valued option), or the message saying why `text` is not one.
pub fn finite_value(text: &str) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number"))?;
    if v.is_finite() && v.abs() <= MAX_OPTION_MAGNITUDE {
        Ok(v)
    } else {
        Err(format!(
            "{text} must be finite with magnitude <= {MAX_OPTION_MAGNITUDE:e}"
        ))
    }
}

/// A `--shard K/N` as the command line's parser checks it (a malformed one is a usage error,
/// as a number out of range is): the text back, or why it is not a shard.
pub fn shard_value(text: &str) -> Result<String, String> {
    text.parse::<crate::refocus::batch::Shard>()
        .map(|_| text.to_string())
        .map_err(|e| e.to_string())
}

/// Refuses `--npz-key` when a depth file it would apply to is not a `.npz` (by its name), and
/// an empty key: the command line is wrong (exit 2), seen before any file is read.
pub(crate) fn check_npz_key(key: Option<&str>, depths: &[&std::path::Path]) -> Result<(), ArgError> {
    let Some(key) = key else { return Ok(()) };
    if key.is_empty() {
        return Err(ArgError::Invalid(crate::Error::param(
            crate::Field::NpzKey,
            "an empty name names no array",
        )));
    }
    let is_npz = |p: &std::path::Path| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("npz"));
    match depths.iter().find(|p| !is_npz(p)) {
        Some(p) => Err(ArgError::Invalid(crate::Error::param(
            crate::Field::NpzKey,
            format!(
                "{}: applies to .npz files only (it names an array of one)",
                crate::error::excerpt(&p.display().to_string())
            ),
        ))),
        None => Ok(()),
    }
}

/// A request's outputs as the text `--outputs` takes ("rgb,depth,mask"), or none: one value
/// for each front end's default to be compared with.
pub(crate) fn outputs_text<S: serde::Serializer>(
    outputs: &Option<crate::output::OutputSet>,
    s: S,
) -> Result<S::Ok, S::Error> {
    match outputs {
        Some(o) => s.serialize_some(&o.names()),
        None => s.serialize_none(),
    }
}

/// The commands whose settings both front ends give through one request type.
pub const REQUEST_COMMANDS: &[&str] = &["cyclopean", "refocus", "reproject", "stitch"];

/// The request of `command` (one of [`REQUEST_COMMANDS`]) at its defaults, as JSON: what the
/// front-end mapping tests hold the CLI's and Python's defaults to.
pub fn request_defaults(command: &str) -> Option<serde_json::Value> {
    let value = match command {
        "cyclopean" => serde_json::to_value(cyclopean::CyclopeanRequest::default()),
        "reproject" => serde_json::to_value(reproject::ReprojectRequest::default()),
        "stitch" => serde_json::to_value(stitch::StitchRequest::default()),
        "refocus" => serde_json::to_value(refocus::RefocusRequest::default()),
        _ => return None,
    };
    value.ok()
}

/// A named choice (`--method`'s "shift-scan", `--depth-kind`'s "view-z", ...) by the names
/// the request's serialisation gives it, so that each front end parses choices the same way;
/// a refusal names `option` and the choices.
pub fn choice<T: serde::de::DeserializeOwned>(option: crate::Field, text: &str) -> Result<T, ArgError> {
    serde_json::from_value(serde_json::Value::String(text.to_string())).map_err(|e| {
        // serde's words: "unknown variant `x`, expected one of `a`, `b`"; the position is noise.
        let why = e.to_string();
        let why = why.split(" at line").next().unwrap_or(&why).to_string();
        ArgError::Invalid(crate::Error::param(
            option,
            format!("'{}': {why}", crate::error::excerpt(text)),
        ))
    })
}

/// As [`finite_value`], or `inf` where infinity has a meaning (a far plane, a disabled limit).
pub fn finite_or_inf(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v == f64::INFINITY => Ok(v),
        _ => finite_value(text),
    }
}

/// Threads per CPU pool (`--jobs`): the number of cores when none is given, at most
/// [`crate::refocus::batch::MAX_JOBS`].
pub fn pool_threads(jobs: Option<usize>) -> Result<usize, ArgError> {
    let max = crate::refocus::batch::MAX_JOBS;
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(2, |n| n.get()));
    match jobs > max {
        true => Err(ArgError::TooManyJobs { jobs, max }),
        false => Ok(jobs),
    }
}

#[cfg(test)]
mod tests {
    use super::{finite_or_inf, finite_value};

    #[test]
    fn option_values_are_finite_and_bounded() {
        assert_eq!(finite_value(" 2.5 "), Ok(2.5));
        assert!(finite_value("1e308").unwrap_err().contains("magnitude <= 1e6"));
        assert!(finite_value("nan").is_err());
        assert!(finite_value("forty").unwrap_err().contains("not a number"));
        assert_eq!(finite_or_inf("inf"), Ok(f64::INFINITY));
        assert!(finite_or_inf("-inf").is_err());
    }
}
