//! What a caller demands of the renderer: `--require-gpu` and `VIEWSYNTH_REQUIRE_GPU`, for
//! either backend (each checks its own device list against it).

use crate::error::{Error, Result};

/// Environment variable that makes every context creation require a hardware renderer.
pub const REQUIRE_GPU_ENV: &str = "VIEWSYNTH_REQUIRE_GPU";

/// What a caller demands of the renderer when a context is created.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GpuPolicy {
    /// Refuse a software renderer (llvmpipe, softpipe) with [`Error::SoftwareRenderer`].
    pub require_hardware: bool,
}

impl GpuPolicy {
    /// This policy, with `require_hardware` also set when `VIEWSYNTH_REQUIRE_GPU` says so.
    pub fn with_env(self) -> Result<Self> {
        let env = std::env::var(REQUIRE_GPU_ENV).ok();
        Ok(GpuPolicy {
            require_hardware: self.require_hardware || parse_require_env(env.as_deref())?,
        })
    }
}

/// `1`, `true`, `yes`, `on` require hardware; unset, empty, `0`, `false`, `no`, `off` do not;
/// anything else is an error naming the variable (a typo must not silently allow software).
pub fn parse_require_env(value: Option<&str>) -> Result<bool> {
    let Some(v) = value else { return Ok(false) };
    match v.trim().to_ascii_lowercase().as_str() {
        "1" | "true" | "yes" | "on" => Ok(true),
        "" | "0" | "false" | "no" | "off" => Ok(false),
        other => Err(Error::param(
            REQUIRE_GPU_ENV,
            format!("'{other}': expected 1/true/yes/on or 0/false/no/off"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn require_env_values() {
        assert!(!parse_require_env(None).unwrap());
        for v in ["1", "true", "YES", " on "] {
            assert!(parse_require_env(Some(v)).unwrap(), "{v}");
        }
        for v in ["", "0", "false", "No", "off"] {
            assert!(!parse_require_env(Some(v)).unwrap(), "{v}");
        }
        let e = parse_require_env(Some("maybe")).unwrap_err().to_string();
        assert!(e.contains(REQUIRE_GPU_ENV) && e.contains("maybe"), "{e}");
    }
}
