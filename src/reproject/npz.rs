//! Minimal `.npz` reader: one named member of a zip archive, stored or deflated (what
//! `numpy.savez` / `savez_compressed` write), decoded by the strict `.npy` reader.

use crate::error::{Error, Result};
use crate::io::{load_npy, DepthMap, NpyArray};
use std::io::Read;
use std::path::Path;

const LOCAL_HEADER: u32 = 0x0403_4b50;

fn u16_at(b: &[u8], o: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(o..o + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], o: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(o..o + 4)?.try_into().ok()?))
}

/// The uncompressed bytes of member `name`, walking the local headers in order.
fn member(path: &Path, bytes: &[u8], name: &str) -> Result<Vec<u8>> {
    let bad = |m: String| Error::decode(path, format!("npz: {m}"));
    let mut o = 0usize;
    while u32_at(bytes, o) == Some(LOCAL_HEADER) {
        let field = |off: usize, size: usize| -> Result<usize> {
            let v = if size == 2 {
                u16_at(bytes, o + off).map(usize::from)
            } else {
                u32_at(bytes, o + off).map(|v| v as usize)
            };
            v.ok_or_else(|| bad(format!("truncated header at byte {o}")))
        };
        let (flags, method) = (field(6, 2)?, field(8, 2)?);
        let (packed, unpacked) = (field(18, 4)?, field(22, 4)?);
        let (name_len, extra_len) = (field(26, 2)?, field(28, 2)?);
        if flags & 0x8 != 0 {
            return Err(bad("members with a trailing data descriptor are not supported".into()));
        }
        if packed == 0xFFFF_FFFF || unpacked == 0xFFFF_FFFF {
            return Err(bad("zip64 members are not supported".into()));
        }
        let start = o + 30 + name_len + extra_len;
        let this = bytes
            .get(o + 30..o + 30 + name_len)
            .ok_or_else(|| bad("truncated member name".into()))?;
        let data = bytes
            .get(start..start + packed)
            .ok_or_else(|| bad(format!("member at byte {o} runs past the end")))?;
        if this == name.as_bytes() {
            let out = match method {
                0 => data.to_vec(),
                8 => {
                    let mut out = Vec::with_capacity(unpacked);
                    flate2::read::DeflateDecoder::new(data)
                        .take(unpacked as u64 + 1)
                        .read_to_end(&mut out)
                        .map_err(|e| bad(format!("{name}: {e}")))?;
                    out
                }
                m => return Err(bad(format!("{name}: compression method {m} (only stored/deflate)"))),
            };
            if out.len() != unpacked {
                return Err(bad(format!("{name}: {} bytes, header says {unpacked}", out.len())));
            }
            return Ok(out);
        }
        o = start + packed;
    }
    Err(bad(format!("no member {name}")))
}

/// Array `key` (e.g. `arr_0`) of an `.npz` file.
pub fn load_npz_array(path: &Path, key: &str) -> Result<NpyArray> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let npy = member(path, &bytes, &format!("{key}.npy"))?;
    // The .npy reader takes a path: go through a private temporary file.
    let tmp = std::env::temp_dir().join(format!(
        "viewsynth-npz-{}-{}-{key}.npy",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos())
    ));
    std::fs::write(&tmp, &npy).map_err(|e| Error::io(&tmp, e))?;
    let array = load_npy(&tmp).map_err(|e| match e {
        Error::Decode { message, .. } => Error::decode(path, format!("{key}: {message}")),
        other => other,
    });
    let _ = std::fs::remove_file(&tmp);
    array
}

/// A 2-D array of an `.npz` as a map (rows top-down), values kept as stored (inf stays inf).
pub fn load_npz_map(path: &Path, key: &str) -> Result<DepthMap> {
    let a = load_npz_array(path, key)?;
    let [h, w] = a.shape[..] else {
        return Err(Error::decode(path, format!("{key}: shape {:?} is not 2-D", a.shape)));
    };
    DepthMap::new(w as u32, h as u32, a.data.iter().map(|v| *v as f32).collect())
}
