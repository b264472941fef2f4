//! Typed errors of the library. Every variant names the file or parameter at fault.

use crate::field::{Message, Spelling};
use std::path::PathBuf;

/// Result alias used across the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything the library can fail with; the message names the file or parameter at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be opened, read, created or renamed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A file was read but its contents are not what the format requires.
    #[error("{path}: {message}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A file could not be encoded or written in the requested format.
    #[error("{path}: cannot encode: {message}")]
    Encode {
        /// The file.
        path: PathBuf,
        /// Why it could not be encoded.
        message: String,
    },
    /// A parameter is out of its domain (non-finite, non-positive, too large, mismatched).
    #[error("invalid {name}: {message}")]
    InvalidParameter {
        /// The parameter: a request field ([`crate::Field`], spelled by each front end), or the
        /// library's own name for it.
        name: Message,
        /// Why its value is refused (it may name fields too).
        message: Message,
    },
    /// An image side exceeds what the GPU context renders (`pass::check_image_size`).
    #[error("invalid {name}: {width}x{height} exceeds this GPU's limit of {limit} px per side")]
    ImageTooLarge {
        /// The parameter giving the size.
        name: String,
        /// Width asked for.
        width: u64,
        /// Height asked for.
        height: u64,
        /// The context's largest side.
        limit: u32,
    },
    /// Two inputs that must agree in size do not.
    #[error("size mismatch: {message}")]
    SizeMismatch {
        /// The two sizes and what they belong to.
        message: String,
    },
    /// libEGL is missing, no display could be opened, or no GL 4.5 core context is available.
    #[error("EGL/OpenGL unavailable: {0}")]
    Egl(String),
    /// Hardware rendering was required (`--require-gpu`, `VIEWSYNTH_REQUIRE_GPU=1`) but the
    /// context renders in software.
    #[error("{}", self.software_renderer().unwrap_or_default())]
    SoftwareRenderer {
        /// GL_RENDERER of the context.
        renderer: String,
        /// The EGL device or platform the context was created on.
        location: String,
        /// The hardware seen (and why it was not used), or that none is visible.
        seen: String,
    },
    /// A GL call or object failed (shader compile/link, incomplete framebuffer, GL error).
    #[error("OpenGL error: {0}")]
    Gl(String),
    /// A run did not hand back what its pass asked for (an output not read back, a run waited
    /// twice). Raised by backend-neutral code, so it names the graphics API the run was on
    /// (`pass::Api::name`): an "OpenGL error" on GL as before, never one on Vulkan.
    #[error("{backend} error: {message}")]
    Readback {
        /// The graphics API of the run: "OpenGL" or "Vulkan".
        backend: &'static str,
        /// What is missing, naming the pass.
        message: String,
    },
    /// The Vulkan loader or a device is missing, or a Vulkan call failed (`--backend vulkan`).
    #[error("Vulkan error: {0}")]
    Vulkan(String),
    /// An image-sized buffer could not be allocated (`ulimit -v`, a full machine): the run
    /// stops with this error instead of aborting.
    #[error("out of memory: {what} needs {bytes} bytes ({:.1} MiB) more than this process may allocate", *bytes as f64 / 1048576.0)]
    OutOfMemory {
        /// What the buffer was for.
        what: String,
        /// Its size.
        bytes: usize,
    },
}

/// Most characters of an input a message quotes (a name, a key, a line).
pub const MAX_EXCERPT: usize = 120;
/// Most characters of any error message built by [`Error::decode`], [`Error::encode`] or
/// [`Error::param`]: whatever an input holds (a 15 MB JSON key, a huge line), the message
/// quoting it stays short.
pub const MAX_MESSAGE: usize = 2048;

/// `text` cut to `max` characters, with how much was left out.
fn cut(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        None => text.to_string(),
        Some((at, _)) => format!("{}... ({} bytes in all)", &text[..at], text.len()),
    }
}

/// `text` (taken from an input) cut to [`MAX_EXCERPT`] characters for a message.
pub fn excerpt(text: &str) -> String {
    cut(text, MAX_EXCERPT)
}

impl Error {
    /// An [`Error::InvalidParameter`] renamed `name` (how a front end spells the parameter, e.g.
    /// the option `--png-compression` for the library's `png-compression`); any other error as
    /// it is.
    pub fn renamed(self, name: impl Into<Message>) -> Self {
        match self {
            Error::InvalidParameter { message, .. } => Error::param(name, message),
            other => other,
        }
    }

    /// An [`Error::Io`] on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
    /// An [`Error::Decode`] of `path`.
    pub fn decode(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Decode {
            path: path.into(),
            message: cut(&message.into(), MAX_MESSAGE),
        }
    }
    /// An [`Error::Encode`] of `path`.
    pub fn encode(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Encode {
            path: path.into(),
            message: cut(&message.into(), MAX_MESSAGE),
        }
    }
    /// An [`Error::InvalidParameter`] naming `name`.
    pub fn param(name: impl Into<Message>, message: impl Into<Message>) -> Self {
        Error::InvalidParameter {
            name: name.into().map_text(|t| cut(t, MAX_EXCERPT)),
            message: message.into().map_text(|t| cut(t, MAX_MESSAGE)),
        }
    }

    /// The fields the error names, in order: its parameter's, then its message's.
    pub fn fields(&self) -> Vec<crate::Field> {
        match self {
            Error::InvalidParameter { name, message } => name.fields().chain(message.fields()).collect(),
            Error::SoftwareRenderer { .. } => vec![crate::Field::RequireGpu],
            _ => Vec::new(),
        }
    }

    /// [`Error::SoftwareRenderer`]'s message, naming the option that asks for hardware.
    fn software_renderer(&self) -> Option<Message> {
        let Error::SoftwareRenderer {
            renderer,
            location,
            seen,
        } = self
        else {
            return None;
        };
        Some(crate::msg![
            "a hardware GPU is required (",
            crate::Field::RequireGpu,
            format!(" or VIEWSYNTH_REQUIRE_GPU=1) but the renderer is software: '{renderer}' on {location}; {seen}")
        ])
    }

    /// The message with the fields it names in `spelling`'s words (`Display` is
    /// [`Spelling::Cli`]'s).
    pub fn spelled(&self, spelling: Spelling) -> String {
        if let Some(m) = self.software_renderer() {
            return m.spelled(spelling);
        }
        match self {
            Error::InvalidParameter { name, message } => {
                format!("invalid {}: {}", name.spelled(spelling), message.spelled(spelling))
            }
            other => other.to_string(),
        }
    }
}
