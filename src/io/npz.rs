//! NumPy `.npz` archives: the zip members `numpy.savez` / `savez_compressed` write (stored or
//! deflated, zip64 local headers as numpy >= 1.16 writes them), each decoded by the strict
//! `.npy` reader. Members with a trailing data descriptor (zips written to a pipe) are refused.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use super::npy::{open_npy_stream, NpyArray, NpyDtype, NpyStream};
use crate::error::{Error, Result};

const LOCAL_HEADER: u32 = 0x0403_4b50;
const ZIP64_EXTRA: u16 = 0x0001;
/// Most members an archive may list (numpy archives hold a handful; the list is kept).
const MAX_MEMBERS: usize = 1024;

fn u16_at(b: &[u8], o: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(o..o + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], o: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(o..o + 4)?.try_into().ok()?))
}

fn u64_at(b: &[u8], o: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(o..o + 8)?.try_into().ok()?))
}

/// One archive member as its local header declares it; nothing of its data is read yet.
struct Member {
    name: String,
    method: u16,
    unpacked: u64,
    packed: u64,
    /// Where its (compressed) data starts in the file.
    offset: u64,
}

impl Member {
    /// The array's name as numpy gives it (`arr_0` for `arr_0.npy`).
    fn key(&self) -> &str {
        self.name.strip_suffix(".npy").unwrap_or(&self.name)
    }

    /// The member's `.npy`, its header read and checked against `max_values` and the member's
    /// declared size; the data is inflated as the payload is decoded, never whole.
    fn open<'f>(&self, file: &'f File, max_values: u64) -> std::result::Result<NpyStream<Box<dyn Read + 'f>>, String> {
        let mut f = file;
        f.seek(SeekFrom::Start(self.offset)).map_err(|e| e.to_string())?;
        let raw = f.take(self.packed);
        // One byte more than declared, so that a member inflating past its size is noticed.
        let reader: Box<dyn Read + 'f> = match self.method {
            0 => Box::new(raw.take(self.unpacked + 1)),
            8 => Box::new(flate2::read::DeflateDecoder::new(raw).take(self.unpacked + 1)),
            m => return Err(format!("{}: compression method {m} (only stored/deflate)", self.name)),
        };
        open_npy_stream(reader, self.unpacked, max_values).map_err(|e| format!("{}: {e}", self.key()))
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

/// Fills `buf` from `at`; false when the file ends first.
fn read_at(file: &File, at: u64, buf: &mut [u8]) -> std::result::Result<bool, String> {
    let mut f = file;
    f.seek(SeekFrom::Start(at)).map_err(|e| e.to_string())?;
    match f.read_exact(buf) {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => Ok(false),
        Err(e) => Err(e.to_string()),
    }
}

/// The members in file order, walking the local headers (a few dozen bytes read per member).
/// Two members of one name are refused: numpy would read the last, a zip walk the first.
fn members(file: &File, len: u64) -> std::result::Result<Vec<Member>, String> {
    let mut out: Vec<Member> = Vec::new();
    let mut o = 0u64;
    let mut fixed = [0u8; 30];
    while o + 4 <= len && read_at(file, o, &mut fixed[..4])? && u32_at(&fixed, 0) == Some(LOCAL_HEADER) {
        if !read_at(file, o, &mut fixed)? {
            return Err(format!("truncated header at byte {o}"));
        }
        let flags = u16_at(&fixed, 6).unwrap_or(0);
        let method = u16_at(&fixed, 8).unwrap_or(0);
        let mut packed = u64::from(u32_at(&fixed, 18).unwrap_or(0));
        let mut unpacked = u64::from(u32_at(&fixed, 22).unwrap_or(0));
        let name_len = usize::from(u16_at(&fixed, 26).unwrap_or(0));
        let extra_len = usize::from(u16_at(&fixed, 28).unwrap_or(0));
        if flags & 0x8 != 0 {
            return Err("members with a trailing data descriptor are not supported".into());
        }
        let mut var = vec![0u8; name_len + extra_len];
        if !read_at(file, o + 30, &mut var)? {
            return Err("truncated member name".into());
        }
        let (name, extra) = var.split_at(name_len);
        let name = super::excerpt(&String::from_utf8_lossy(name));
        if packed == 0xFFFF_FFFF || unpacked == 0xFFFF_FFFF {
            (unpacked, packed) = zip64_sizes(extra).ok_or_else(|| format!("{name}: zip64 sizes missing"))?;
        }
        let start = o + 30 + (name_len + extra_len) as u64;
        let end = start
            .checked_add(packed)
            .filter(|&end| end <= len)
            .ok_or_else(|| format!("member {name} at byte {o} runs past the end"))?;
        let member = Member {
            name,
            method,
            unpacked,
            packed,
            offset: start,
        };
        if out.iter().any(|m| m.key() == member.key()) {
            return Err(format!(
                "two arrays named '{}': ambiguous (numpy reads the last, other readers the first)",
                member.key()
            ));
        }
        if out.len() == MAX_MEMBERS {
            return Err(format!("more than {MAX_MEMBERS} members"));
        }
        out.push(member);
        o = end;
    }
    if out.is_empty() {
        return Err("not a zip archive (no local file header at byte 0)".into());
    }
    Ok(out)
}

/// Array `key` (e.g. `arr_0`) of an `.npz` file, or with `None` the only array, else the
/// first floating-point one. Returns the key read with the array. At most 4 values per
/// budget pixel (as `.npy` files).
pub fn load_npz_array(path: &Path, key: Option<&str>) -> Result<(String, NpyArray)> {
    load_npz_array_within(path, key, super::input::max_pixels().saturating_mul(4), &|_| Ok(()))
}

/// [`load_npz_array`] with at most `max_values` values, and `check` run on the chosen array's
/// shape: both from the member's header, before its data is inflated.
pub(crate) fn load_npz_array_within(
    path: &Path,
    key: Option<&str>,
    max_values: u64,
    check: &dyn Fn(&[usize]) -> Result<()>,
) -> Result<(String, NpyArray)> {
    let (file, len) = super::input::open_regular(path)?;
    let bad = |m: String| Error::decode(path, format!("npz: {m}"));
    let members = members(&file, len).map_err(bad)?;
    let keys = || super::excerpt(&members.iter().map(|m| m.key()).collect::<Vec<_>>().join(", "));
    let chosen = match key {
        Some(key) => {
            let m = members
                .iter()
                .find(|m| m.key() == key)
                .ok_or_else(|| bad(format!("no array '{}' (arrays: {})", super::excerpt(key), keys())))?;
            (m, m.open(&file, max_values).map_err(bad)?)
        }
        None if members.len() == 1 => (&members[0], members[0].open(&file, max_values).map_err(bad)?),
        None => {
            // The first floating-point array, told from the headers alone.
            let mut found = None;
            for m in &members {
                let stream = m.open(&file, max_values).map_err(bad)?;
                if matches!(stream.dtype(), NpyDtype::F32 | NpyDtype::F64) {
                    found = Some((m, stream));
                    break;
                }
            }
            found.ok_or_else(|| {
                bad(format!(
                    "no floating-point array (arrays: {}); name one with --npz-key",
                    keys()
                ))
            })?
        }
    };
    let (m, stream) = chosen;
    check(stream.shape()).map_err(|e| match e {
        Error::Decode { path, message } => Error::decode(path, format!("array '{}': {message}", m.key())),
        other => other,
    })?;
    let array = stream.read().map_err(|e| bad(format!("{}: {e}", m.key())))?;
    Ok((m.key().to_string(), array))
}

#[cfg(test)]
#[path = "npz_tests.rs"]
mod tests;
