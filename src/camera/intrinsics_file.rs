//! Pinhole intrinsics from the calibration files users already have, the format told from the
//! content (not the extension):
//!
//! - a 3x3 K, row-major: JSON (nested `[[fx,0,cx],[0,fy,cy],[0,0,1]]`, flat 9 numbers, or an
//!   object with `K` or `camera_matrix` holding either, optional `width`/`height`), or 9
//!   whitespace-separated numbers as text (`#` comments allowed);
//! - Open3D `PinholeCameraIntrinsic` JSON: `intrinsic_matrix` (9 numbers, column-major),
//!   `width`, `height`;
//! - Middlebury 2014 `calib.txt`: `cam0=[f 0 cx; 0 f cy; 0 0 1]` (the left view), with
//!   `width`, `height`, `doffs`, `baseline` (mm) kept;
//! - COLMAP `cameras.txt`: one `PINHOLE` (fx fy cx cy) or `SIMPLE_PINHOLE` (f cx cy) camera.
//!   Models with lens distortion are refused, naming the model: the images must be undistorted
//!   first. COLMAP puts the centre of the top-left pixel at (0.5, 0.5), so 0.5 is subtracted
//!   from its cx, cy to reach this crate's convention (centre at (0, 0)).
//!
//! K, Open3D and Middlebury values are taken as stored (pixel centre at integer coordinates,
//! as OpenCV and Open3D define it).

use std::path::Path;

use super::Intrinsics;
use crate::error::{Error, Result};

/// Largest intrinsics file read: a K, an Open3D JSON, a calib.txt or a cameras.txt of one
/// camera are well under 1 KiB; 1 MiB leaves room for comments and many-camera files.
pub const MAX_INTRINSICS_BYTES: u64 = 1 << 20;

/// Which format a file was read as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntrinsicsFormat {
    /// A 3x3 K as JSON (nested rows or 9 numbers).
    KMatrixJson,
    /// A 3x3 K as whitespace-separated text.
    KMatrixText,
    /// Open3D `PinholeCameraIntrinsic` JSON.
    Open3d,
    /// Middlebury `calib.txt` (cam0).
    MiddleburyCalib,
    /// COLMAP `cameras.txt` (PINHOLE, SIMPLE_PINHOLE).
    Colmap,
}

impl IntrinsicsFormat {
    /// The format's name in messages.
    pub fn label(self) -> &'static str {
        match self {
            IntrinsicsFormat::KMatrixJson => "3x3 K (JSON)",
            IntrinsicsFormat::KMatrixText => "3x3 K (text)",
            IntrinsicsFormat::Open3d => "Open3D PinholeCameraIntrinsic",
            IntrinsicsFormat::MiddleburyCalib => "Middlebury calib.txt (cam0)",
            IntrinsicsFormat::Colmap => "COLMAP cameras.txt",
        }
    }
}

/// A Middlebury rig's stereo terms, as `calib.txt` gives them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MiddleburyStereo {
    /// cx_right - cx_left, pixels.
    pub doffs: f64,
    /// Camera baseline, millimetres.
    pub baseline_mm: f64,
}

/// Intrinsics read from a file, with the image size when the format carries one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntrinsicsFile {
    /// The intrinsics, in this crate's convention (COLMAP's cx/cy shifted by -0.5).
    pub k: Intrinsics,
    /// Image width and height, when the format carries them.
    pub size: Option<(u32, u32)>,
    /// The format the file was read as.
    pub format: IntrinsicsFormat,
    /// Middlebury's doffs and baseline, from a `calib.txt`.
    pub stereo: Option<MiddleburyStereo>,
}

impl IntrinsicsFile {
    /// Reads and parses `path`; errors name the file.
    pub fn load(path: &Path) -> Result<Self> {
        // The input layer's rule: a regular file (FIFOs and devices refused before opening),
        // its size checked before it is read.
        let text = crate::io::read_text(path, MAX_INTRINSICS_BYTES)?;
        Self::parse(&text).map_err(|m| Error::decode(path, m))
    }

    /// Parses file contents, detecting the format; the error message says what was expected.
    pub fn parse(text: &str) -> std::result::Result<Self, String> {
        let trimmed = text.trim_start();
        let file = if trimmed.starts_with('{') || trimmed.starts_with('[') {
            parse_json(trimmed)?
        } else if text.lines().any(|l| l.trim_start().starts_with("cam0")) {
            parse_middlebury(text)?
        } else if is_colmap(text) {
            parse_colmap(text)?
        } else {
            parse_k_text(text)?
        };
        file.k.validate("intrinsics").map_err(|e| e.to_string())?;
        Ok(file)
    }

    /// Checks the file's size (when it has one) against the image the intrinsics are used with.
    pub fn check_size(&self, path: &Path, width: u32, height: u32) -> Result<()> {
        match self.size {
            Some((w, h)) if (w, h) != (width, height) => Err(Error::decode(
                path,
                format!(
                    "intrinsics for {w}x{h} but the image is {width}x{height} \
                     (scale fx, fy, cx, cy with the resize, or give --fx/--fy/--cx/--cy)"
                ),
            )),
            _ => Ok(()),
        }
    }
}

/// Row-major K to intrinsics: zero skew and a last row of (0, 0, 1) required.
fn from_k(k: [[f64; 3]; 3]) -> std::result::Result<Intrinsics, String> {
    if k.iter().flatten().any(|v| !v.is_finite()) {
        return Err(format!("K holds a non-finite value: {k:?}"));
    }
    if k[0][1] != 0.0 {
        return Err(format!("K has skew {} (K[0][1]); only zero skew is supported", k[0][1]));
    }
    if k[1][0] != 0.0 || k[2] != [0.0, 0.0, 1.0] {
        return Err(format!(
            "K is not a pinhole matrix [[fx,0,cx],[0,fy,cy],[0,0,1]]: {k:?}"
        ));
    }
    Ok(Intrinsics {
        fx: k[0][0],
        fy: k[1][1],
        cx: k[0][2],
        cy: k[1][2],
    })
}

fn rows_of(flat: &[f64]) -> [[f64; 3]; 3] {
    [
        [flat[0], flat[1], flat[2]],
        [flat[3], flat[4], flat[5]],
        [flat[6], flat[7], flat[8]],
    ]
}

/// A 3x3 matrix from JSON: nested rows or 9 numbers (row-major).
fn json_matrix(v: &serde_json::Value, what: &str) -> std::result::Result<[[f64; 3]; 3], String> {
    let bad = || format!("{what}: expected a 3x3 matrix as [[a,b,c],[d,e,f],[g,h,i]] or 9 numbers");
    let items = v.as_array().ok_or_else(bad)?;
    let flat: Vec<f64> = if items.len() == 3 && items.iter().all(|r| r.is_array()) {
        let mut flat = Vec::with_capacity(9);
        for row in items {
            let row = row.as_array().filter(|r| r.len() == 3).ok_or_else(bad)?;
            for x in row {
                flat.push(x.as_f64().ok_or_else(bad)?);
            }
        }
        flat
    } else {
        items
            .iter()
            .map(|x| x.as_f64().ok_or_else(bad))
            .collect::<std::result::Result<_, _>>()?
    };
    if flat.len() != 9 {
        return Err(bad());
    }
    Ok(rows_of(&flat))
}

fn json_size(obj: &serde_json::Map<String, serde_json::Value>) -> std::result::Result<Option<(u32, u32)>, String> {
    let side = |key: &str| -> std::result::Result<Option<u32>, String> {
        match obj.get(key) {
            None => Ok(None),
            Some(v) => v
                .as_u64()
                .and_then(|n| u32::try_from(n).ok())
                .filter(|n| *n > 0)
                .map(Some)
                .ok_or_else(|| format!("{key}: expected a positive integer, got {v}")),
        }
    };
    match (side("width")?, side("height")?) {
        (Some(w), Some(h)) => Ok(Some((w, h))),
        (None, None) => Ok(None),
        _ => Err("give both width and height, or neither".into()),
    }
}

fn parse_json(text: &str) -> std::result::Result<IntrinsicsFile, String> {
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| format!("invalid JSON: {e}"))?;
    if v.is_array() {
        return Ok(IntrinsicsFile {
            k: from_k(json_matrix(&v, "K")?)?,
            size: None,
            format: IntrinsicsFormat::KMatrixJson,
            stereo: None,
        });
    }
    let obj = v.as_object().ok_or("expected a JSON object or array")?;
    if let Some(m) = obj.get("intrinsic_matrix") {
        // Open3D writes Eigen's storage order: column-major.
        let cols = json_matrix(m, "intrinsic_matrix")?;
        let k = [0, 1, 2].map(|r| [0, 1, 2].map(|c| cols[c][r]));
        return Ok(IntrinsicsFile {
            k: from_k(k)?,
            size: json_size(obj)?,
            format: IntrinsicsFormat::Open3d,
            stereo: None,
        });
    }
    for key in ["K", "camera_matrix"] {
        if let Some(m) = obj.get(key) {
            return Ok(IntrinsicsFile {
                k: from_k(json_matrix(m, key)?)?,
                size: json_size(obj)?,
                format: IntrinsicsFormat::KMatrixJson,
                stereo: None,
            });
        }
    }
    Err("JSON object without intrinsic_matrix (Open3D) or K / camera_matrix (3x3, row-major)".into())
}

/// Numbers of a text, `#` starting a comment.
fn numbers(text: &str) -> std::result::Result<Vec<f64>, String> {
    text.lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .flat_map(|l| l.split(|c: char| c.is_whitespace() || c == ',' || c == ';'))
        .filter(|t| !t.is_empty())
        .map(|t| {
            t.trim_matches(|c| c == '[' || c == ']')
                .parse::<f64>()
                .map_err(|_| format!("'{t}' is not a number"))
        })
        .collect()
}

fn parse_k_text(text: &str) -> std::result::Result<IntrinsicsFile, String> {
    let n = numbers(text).map_err(|e| {
        format!(
            "not a recognised intrinsics file ({e}); expected a 3x3 K (JSON or 9 numbers), \
             Open3D JSON, Middlebury calib.txt or COLMAP cameras.txt"
        )
    })?;
    if n.len() != 9 {
        return Err(format!(
            "a K text file holds 9 numbers (3x3, row-major), found {}",
            n.len()
        ));
    }
    Ok(IntrinsicsFile {
        k: from_k(rows_of(&n))?,
        size: None,
        format: IntrinsicsFormat::KMatrixText,
        stereo: None,
    })
}

fn parse_middlebury(text: &str) -> std::result::Result<IntrinsicsFile, String> {
    let mut fields = std::collections::HashMap::new();
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        let (key, value) = line
            .split_once('=')
            .ok_or_else(|| format!("calib.txt line '{line}': expected key=value"))?;
        fields.insert(key.trim(), value.trim());
    }
    let cam0 = fields.get("cam0").ok_or("calib.txt: no cam0=[...] line")?;
    let m = numbers(cam0).map_err(|e| format!("calib.txt cam0: {e}"))?;
    if m.len() != 9 {
        return Err(format!(
            "calib.txt cam0: expected [f 0 cx; 0 f cy; 0 0 1], found {} numbers",
            m.len()
        ));
    }
    let k = from_k(rows_of(&m)).map_err(|e| format!("calib.txt cam0: {e}"))?;
    let number = |key: &str| -> std::result::Result<Option<f64>, String> {
        fields
            .get(key)
            .map(|v| {
                v.parse::<f64>()
                    .map_err(|_| format!("calib.txt {key}='{v}' is not a number"))
            })
            .transpose()
    };
    let side = |key: &str| -> std::result::Result<Option<u32>, String> {
        fields
            .get(key)
            .map(|v| {
                v.parse::<u32>()
                    .ok()
                    .filter(|n| *n > 0)
                    .ok_or_else(|| format!("calib.txt {key}='{v}' is not a positive integer"))
            })
            .transpose()
    };
    let stereo = match (number("doffs")?, number("baseline")?) {
        (Some(doffs), Some(baseline_mm)) => Some(MiddleburyStereo { doffs, baseline_mm }),
        _ => None,
    };
    Ok(IntrinsicsFile {
        k,
        size: side("width")?.zip(side("height")?),
        format: IntrinsicsFormat::MiddleburyCalib,
        stereo,
    })
}

/// Non-comment lines of a COLMAP cameras.txt: `ID MODEL WIDTH HEIGHT PARAMS...`.
fn colmap_lines(text: &str) -> impl Iterator<Item = Vec<&str>> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().collect())
}

fn is_colmap(text: &str) -> bool {
    let mut lines = colmap_lines(text).peekable();
    lines.peek().is_some()
        && lines.all(|t| {
            t.len() >= 4 && t[0].parse::<u64>().is_ok() && t[1].chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        })
}

fn parse_colmap(text: &str) -> std::result::Result<IntrinsicsFile, String> {
    let cameras: Vec<Vec<&str>> = colmap_lines(text).collect();
    let [camera] = cameras.as_slice() else {
        return Err(format!(
            "COLMAP cameras.txt with {} cameras; give a file with the one camera of these images",
            cameras.len()
        ));
    };
    let (id, model) = (camera[0], camera[1]);
    let values: Vec<f64> = camera[2..]
        .iter()
        .map(|t| {
            t.parse::<f64>()
                .map_err(|_| format!("COLMAP camera {id}: '{t}' is not a number"))
        })
        .collect::<std::result::Result<_, _>>()?;
    let (w, h, params) = (values[0], values[1], &values[2..]);
    let need = match model {
        "PINHOLE" => 4,
        "SIMPLE_PINHOLE" => 3,
        other => {
            return Err(format!(
                "COLMAP camera {id} has model {other}, which has lens distortion (or is not a \
                 pinhole): undistort the images first (colmap image_undistorter writes PINHOLE \
                 cameras); PINHOLE and SIMPLE_PINHOLE are accepted"
            ))
        }
    };
    if params.len() != need {
        return Err(format!(
            "COLMAP camera {id}: {model} takes {need} parameters, found {}",
            params.len()
        ));
    }
    let (fx, fy, cx, cy) = match params {
        [f, cx, cy] => (*f, *f, *cx, *cy),
        [fx, fy, cx, cy] => (*fx, *fy, *cx, *cy),
        _ => unreachable!("checked above"),
    };
    let side = |v: f64, what: &str| {
        (v.fract() == 0.0 && v >= 1.0 && v <= u32::MAX as f64)
            .then_some(v as u32)
            .ok_or_else(|| format!("COLMAP camera {id}: {what} {v} is not a positive integer"))
    };
    Ok(IntrinsicsFile {
        // COLMAP's top-left pixel centre is (0.5, 0.5); ours is (0, 0).
        k: Intrinsics {
            fx,
            fy,
            cx: cx - 0.5,
            cy: cy - 0.5,
        },
        size: Some((side(w, "width")?, side(h, "height")?)),
        format: IntrinsicsFormat::Colmap,
        stereo: None,
    })
}

#[cfg(test)]
#[path = "intrinsics_file_tests.rs"]
mod tests;
