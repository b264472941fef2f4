//! JSON inputs (camera files, scene files) read with bounds: a regular file of limited size,
//! an optional UTF-8 byte-order mark skipped, and every number finite and within a stated
//! magnitude, so that values like 1e308 are refused with the place they occur.

use std::io::Read;
use std::path::Path;

use serde::de::DeserializeOwned;
use serde_json::Value;

use super::files::input::{check_file_len, open_regular};
use crate::error::{Error, Result};

/// Largest JSON input read (camera and scene files are a few KiB).
pub const MAX_JSON_BYTES: u64 = 16 << 20;

/// Largest magnitude of any number in a camera or scene file: 1e6 covers metres up to
/// 1000 km, pixels and matrix entries of any sensible camera; beyond it f32 GPU maths loses
/// all precision.
pub const MAX_JSON_MAGNITUDE: f64 = 1e6;

/// Reads `path` as `T`, refusing any number whose magnitude exceeds `max_abs` (the error
/// names the JSON path of the value, e.g. `left.proj[0][0]`).
pub fn load_json<T: DeserializeOwned>(path: &Path, max_abs: f64) -> Result<T> {
    let text = read_text(path, MAX_JSON_BYTES)?;
    let value: Value = serde_json::from_str(&text).map_err(|e| Error::decode(path, e.to_string()))?;
    check_numbers(&value, max_abs, &mut String::new()).map_err(|m| Error::decode(path, m))?;
    serde_json::from_value(value).map_err(|e| Error::decode(path, e.to_string()))
}

/// A text input of at most `max_len` bytes with a leading UTF-8 byte-order mark removed.
pub fn read_text(path: &Path, max_len: u64) -> Result<String> {
    let (file, len) = open_regular(path)?;
    check_file_len(path, len, max_len, "a text input")?;
    let mut text = String::new();
    file.take(max_len)
        .read_to_string(&mut text)
        .map_err(|e| Error::io(path, e))?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

fn check_numbers(v: &Value, max_abs: f64, at: &mut String) -> std::result::Result<(), String> {
    match v {
        Value::Number(n) => match n.as_f64() {
            Some(x) if x.is_finite() && x.abs() <= max_abs => Ok(()),
            _ => Err(format!(
                "{} = {n}: numbers must be finite with magnitude <= {max_abs:e}",
                if at.is_empty() { "(top level)" } else { at.as_str() }
            )),
        },
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                let len = at.len();
                at.push_str(&format!("[{i}]"));
                check_numbers(item, max_abs, at)?;
                at.truncate(len);
            }
            Ok(())
        }
        Value::Object(map) => {
            for (k, item) in map {
                let len = at.len();
                if !at.is_empty() {
                    at.push('.');
                }
                at.push_str(k);
                check_numbers(item, max_abs, at)?;
                at.truncate(len);
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::scratch_dir;

    #[test]
    fn huge_numbers_are_refused_with_their_place() {
        let dir = scratch_dir("json");
        let path = dir.join("c.json");
        std::fs::write(&path, r#"{"left": {"proj": [[1, 2], [3, 1e308]]}}"#).unwrap();
        let err = load_json::<Value>(&path, MAX_JSON_MAGNITUDE).unwrap_err().to_string();
        assert!(err.contains("left.proj[1][1]") && err.contains("c.json"), "{err}");
        std::fs::write(&path, "\u{feff}{\"a\": [1.5, -2e5]}").unwrap();
        let v: Value = load_json(&path, MAX_JSON_MAGNITUDE).unwrap();
        assert_eq!(v["a"][1], -2e5);
    }
}
