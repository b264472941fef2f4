//! NumPy `.npz` archives: the zip members `numpy.savez` / `savez_compressed` write (stored or
//! deflated, zip64 local headers as numpy >= 1.16 writes them), each decoded by the strict
//! `.npy` reader. Members with a trailing data descriptor (zips written to a pipe) are refused.

use std::io::Read;
use std::path::Path;

use super::npy::{decode_npy, NpyArray, NpyDtype};
use crate::error::{Error, Result};

const LOCAL_HEADER: u32 = 0x0403_4b50;
const ZIP64_EXTRA: u16 = 0x0001;

fn u16_at(b: &[u8], o: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(o..o + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], o: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(o..o + 4)?.try_into().ok()?))
}

fn u64_at(b: &[u8], o: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(o..o + 8)?.try_into().ok()?))
}

/// One archive member, still compressed.
struct Member<'a> {
    name: String,
    method: u16,
    unpacked: usize,
    data: &'a [u8],
}

impl Member<'_> {
    /// The array's name as numpy gives it (`arr_0` for `arr_0.npy`).
    fn key(&self) -> &str {
        self.name.strip_suffix(".npy").unwrap_or(&self.name)
    }

    fn inflate(&self) -> std::result::Result<Vec<u8>, String> {
        // The header's size is checked before anything is allocated from it.
        if self.unpacked as u64 > npz_byte_limit() {
            return Err(format!(
                "{}: {} bytes unpacked exceed the pixel budget ({} pixels; --max-pixels)",
                self.name,
                self.unpacked,
                super::input::max_pixels()
            ));
        }
        let out = match self.method {
            0 => self.data.to_vec(),
            8 => {
                let mut out = Vec::with_capacity(self.unpacked);
                flate2::read::DeflateDecoder::new(self.data)
                    .take(self.unpacked as u64 + 1)
                    .read_to_end(&mut out)
                    .map_err(|e| format!("{}: {e}", self.name))?;
                out
            }
            m => return Err(format!("{}: compression method {m} (only stored/deflate)", self.name)),
        };
        if out.len() != self.unpacked {
            return Err(format!(
                "{}: {} bytes, header says {}",
                self.name,
                out.len(),
                self.unpacked
            ));
        }
        Ok(out)
    }
}

/// (uncompressed, compressed) sizes from a zip64 extra field.
fn zip64_sizes(extra: &[u8]) -> Option<(u64, u64)> {
    let mut o = 0;
    while o + 4 <= extra.len() {
        let (id, len) = (u16_at(extra, o)?, usize::from(u16_at(extra, o + 2)?));
        if id == ZIP64_EXTRA && len >= 16 {
            return Some((u64_at(extra, o + 4)?, u64_at(extra, o + 12)?));
        }
        o += 4 + len;
    }
    None
}

/// The members in file order, walking the local headers.
fn members(bytes: &[u8]) -> std::result::Result<Vec<Member<'_>>, String> {
    let mut out = Vec::new();
    let mut o = 0usize;
    while u32_at(bytes, o) == Some(LOCAL_HEADER) {
        let truncated = || format!("truncated header at byte {o}");
        let flags = u16_at(bytes, o + 6).ok_or_else(truncated)?;
        let method = u16_at(bytes, o + 8).ok_or_else(truncated)?;
        let mut packed = u64::from(u32_at(bytes, o + 18).ok_or_else(truncated)?);
        let mut unpacked = u64::from(u32_at(bytes, o + 22).ok_or_else(truncated)?);
        let name_len = usize::from(u16_at(bytes, o + 26).ok_or_else(truncated)?);
        let extra_len = usize::from(u16_at(bytes, o + 28).ok_or_else(truncated)?);
        if flags & 0x8 != 0 {
            return Err("members with a trailing data descriptor are not supported".into());
        }
        let name = bytes.get(o + 30..o + 30 + name_len).ok_or("truncated member name")?;
        let name = String::from_utf8_lossy(name).into_owned();
        let extra = bytes
            .get(o + 30 + name_len..o + 30 + name_len + extra_len)
            .ok_or("truncated extra field")?;
        if packed == 0xFFFF_FFFF || unpacked == 0xFFFF_FFFF {
            (unpacked, packed) = zip64_sizes(extra).ok_or_else(|| format!("{name}: zip64 sizes missing"))?;
        }
        let start = o + 30 + name_len + extra_len;
        let (Ok(packed), Ok(unpacked)) = (usize::try_from(packed), usize::try_from(unpacked)) else {
            return Err(format!("{name}: member too large"));
        };
        let data = start
            .checked_add(packed)
            .and_then(|end| bytes.get(start..end))
            .ok_or_else(|| format!("member {name} at byte {o} runs past the end"))?;
        out.push(Member {
            name,
            method,
            unpacked,
            data,
        });
        o = start + packed;
    }
    if out.is_empty() {
        return Err("not a zip archive (no local file header at byte 0)".into());
    }
    Ok(out)
}

/// Most bytes an archive or one member may hold: 4 values per budget pixel (as `.npy` files),
/// 8 bytes each, plus room for headers.
fn npz_byte_limit() -> u64 {
    super::input::max_pixels().saturating_mul(32).saturating_add(1 << 20)
}

/// Array `key` (e.g. `arr_0`) of an `.npz` file, or with `None` the only array, else the
/// first floating-point one. Returns the key read with the array.
pub fn load_npz_array(path: &Path, key: Option<&str>) -> Result<(String, NpyArray)> {
    let (mut file, len) = super::input::open_regular(path)?;
    if len > npz_byte_limit() {
        return Err(Error::decode(
            path,
            format!(
                "npz: {len} bytes exceed the pixel budget ({} pixels; --max-pixels); refused before reading",
                super::input::max_pixels()
            ),
        ));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    std::io::Read::read_to_end(&mut (&mut file).take(len), &mut bytes).map_err(|e| Error::io(path, e))?;
    let bad = |m: String| Error::decode(path, format!("npz: {m}"));
    let members = members(&bytes).map_err(bad)?;
    let decode = |m: &Member| -> Result<NpyArray> {
        let npy = m.inflate().map_err(bad)?;
        decode_npy(&npy).map_err(|e| bad(format!("{}: {e}", m.key())))
    };
    let keys = || members.iter().map(|m| m.key()).collect::<Vec<_>>().join(", ");
    if let Some(key) = key {
        let m = members
            .iter()
            .find(|m| m.key() == key)
            .ok_or_else(|| bad(format!("no array '{key}' (arrays: {})", keys())))?;
        return Ok((key.to_string(), decode(m)?));
    }
    if let [only] = members.as_slice() {
        return Ok((only.key().to_string(), decode(only)?));
    }
    for m in &members {
        let a = decode(m)?;
        if matches!(a.dtype, NpyDtype::F32 | NpyDtype::F64) {
            return Ok((m.key().to_string(), a));
        }
    }
    Err(bad(format!(
        "no floating-point array (arrays: {}); name one with --npz-key",
        keys()
    )))
}

#[cfg(test)]
#[path = "npz_tests.rs"]
mod tests;
