//! NumPy `.npz` archives: the zip members `numpy.savez` / `savez_compressed` write (stored or
//! deflated, zip64 as numpy >= 1.16 writes them), found through the `zip` crate's reading of
//! the central directory (CRC-32 checked) and each decoded by the strict `.npy` reader.
//!
//! Memory stays bounded before any array is inflated:
//! - the zip crate holds the whole central directory before we see it: at most one entry per
//!   46 bytes of the file (a zip32 count is at most 65535 and below the directory's offset, a
//!   zip64 count is checked against the bytes it would fill), so a small multiple of the file's
//!   length; more than [`MAX_MEMBERS`] members are then refused;
//! - members must tile the archive (see [`check_tiling`]);
//! - a member's `.npy` header is read within the size the directory declares, its shape checked
//!   against the budget and that size before its data, and inflation stops one byte past it.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Take};
use std::path::Path;

use zip::read::ZipFile;
use zip::{CompressionMethod, ZipArchive};

use crate::error::{Error, Result};
use crate::io::formats::npy::{NpyArray, NpyStream};
use crate::io::NpyDtype;

/// Most members an archive may list (numpy archives hold a handful).
const MAX_MEMBERS: usize = 1024;
/// A local file header's fixed part: a gap shorter than this between members hides none (it
/// is a data descriptor, which zips written to a pipe put after each member's data).
const LOCAL_HEADER_LEN: u64 = 30;

/// One listed member, as the central directory describes it.
struct Member {
    name: String,
    method: CompressionMethod,
}

/// The array's name as numpy gives it (`arr_0` for `arr_0.npy`).
fn key(name: &str) -> &str {
    name.strip_suffix(".npy").unwrap_or(name)
}

/// Array `key` (e.g. `arr_0`) of an `.npz` file, or with `None` the only array, else the
/// first floating-point one. Returns the key read with the array. At most 4 values per
/// budget pixel (as `.npy` files).
pub fn load_npz_array(path: &Path, key: Option<&str>) -> Result<(String, NpyArray)> {
    load_npz_array_within(
        path,
        key,
        crate::io::files::input::max_pixels().saturating_mul(4),
        &|_| Ok(()),
    )
}

/// [`load_npz_array`] with at most `max_values` values, and `check` run on the chosen array's
/// shape: both from the member's header, before its data is inflated.
pub(crate) fn load_npz_array_within(
    path: &Path,
    wanted: Option<&str>,
    max_values: u64,
    check: &dyn Fn(&[usize]) -> Result<()>,
) -> Result<(String, NpyArray)> {
    let (file, _) = crate::io::files::input::open_regular(path)?;
    let bad = |m: String| Error::decode(path, format!("npz: {m}"));
    // Every read of the archive seeks first, so `unlisted` may share the file's cursor.
    let mut zip =
        ZipArchive::new(&file).map_err(|e| bad(format!("not a zip archive, or a truncated or corrupt one ({e})")))?;
    if zip.len() > MAX_MEMBERS {
        return Err(bad(format!("{} members, more than {MAX_MEMBERS}", zip.len())));
    }
    let members = check_tiling(&mut zip, &file).map_err(bad)?;
    let keys = || crate::io::excerpt(&members.iter().map(|m| key(&m.name)).collect::<Vec<_>>().join(", "));
    let index = match wanted {
        Some(wanted) => members.iter().position(|m| key(&m.name) == wanted).ok_or_else(|| {
            bad(format!(
                "no array '{}' (arrays: {})",
                crate::io::excerpt(wanted),
                keys()
            ))
        })?,
        None if members.len() == 1 => 0,
        None => {
            // The first floating-point array, told from the headers alone: an array of a type
            // this reader does not decode (a boolean mask, int64 ids) is not one, and is passed.
            let mut found = None;
            for (i, m) in members.iter().enumerate() {
                if matches!(dtype(&mut zip, m, i).map_err(bad)?, Some(NpyDtype::F32 | NpyDtype::F64)) {
                    found = Some(i);
                    break;
                }
            }
            let none = if members.is_empty() {
                "the archive holds no arrays".to_string()
            } else {
                format!("no floating-point array (arrays: {}); name one with --npz-key", keys())
            };
            found.ok_or_else(|| bad(none))?
        }
    };
    let m = &members[index];
    let stream = open(&mut zip, m, index, max_values).map_err(bad)?;
    check(stream.shape()).map_err(|e| match e {
        Error::Decode { path, message } => {
            Error::decode(path, format!("array '{}': {message}", crate::io::excerpt(key(&m.name))))
        }
        other => other,
    })?;
    let array = stream
        .read()
        .map_err(|e| bad(format!("{}: {e}", crate::io::excerpt(key(&m.name)))))?;
    Ok((key(&m.name).to_string(), array))
}

/// Member `index`'s `.npy`, its header read and checked against `max_values` and the size the
/// central directory declares; the data is inflated as the payload is decoded, never whole,
/// and never past one byte more than declared.
fn open<'z, 'f>(
    zip: &'z mut ZipArchive<&'f File>,
    m: &Member,
    index: usize,
    max_values: u64,
) -> std::result::Result<NpyStream<Take<ZipFile<'z, &'f File>>>, String> {
    let name = crate::io::excerpt(key(&m.name));
    let file = member(zip, m, index)?;
    let size = file.size();
    NpyStream::open(file.take(size.saturating_add(1)), size, max_values).map_err(|e| format!("{name}: {e}"))
}

/// Member `index`, opened for reading (stored or deflated only).
fn member<'z, 'f>(
    zip: &'z mut ZipArchive<&'f File>,
    m: &Member,
    index: usize,
) -> std::result::Result<ZipFile<'z, &'f File>, String> {
    let name = crate::io::excerpt(key(&m.name));
    if !matches!(m.method, CompressionMethod::Stored | CompressionMethod::Deflated) {
        return Err(format!(
            "{name}: compression method {} (only stored and deflate)",
            m.method
        ));
    }
    zip.by_index(index).map_err(|e| format!("{name}: {e}"))
}

/// Member `index`'s element type from its `.npy` header (`None`: a type the reader does not
/// decode), read within the size the central directory declares.
fn dtype(zip: &mut ZipArchive<&File>, m: &Member, index: usize) -> std::result::Result<Option<NpyDtype>, String> {
    let name = crate::io::excerpt(key(&m.name));
    let file = member(zip, m, index)?;
    let size = file.size();
    crate::io::formats::npy::read_dtype(&mut file.take(size), size).map_err(|e| format!("{name}: {e}"))
}

/// The listed members, in directory order, once they are known to tile the archive: each
/// starts where the one before ended (after at most a data descriptor), the last ends where the
/// central directory starts, and no two share a key. So no member's bytes serve two entries,
/// and no member hides between them (two of one name, which the directory keeps once: numpy
/// reads the last, a reader walking the local headers the first).
fn check_tiling(zip: &mut ZipArchive<&File>, file: &File) -> std::result::Result<Vec<Member>, String> {
    let mut members = Vec::with_capacity(zip.len());
    let mut spans = Vec::with_capacity(zip.len());
    for i in 0..zip.len() {
        // The local header is read here (its name and extra lengths give where the data starts).
        let f = zip.by_index_raw(i).map_err(|e| e.to_string())?;
        let name = f.name().to_string();
        let end = f
            .data_start()
            .and_then(|start| start.checked_add(f.compressed_size()))
            .ok_or_else(|| format!("member {}: its data runs past the end", crate::io::excerpt(&name)))?;
        if members.iter().any(|m: &Member| key(&m.name) == key(&name)) {
            return Err(ambiguous(&name));
        }
        spans.push((f.header_start(), end, i));
        members.push(Member {
            name,
            method: f.compression(),
        });
    }
    spans.sort_unstable();
    let directory = zip.central_directory_start();
    let mut at = zip.offset();
    for &(start, end, i) in &spans {
        if start < at {
            return Err(format!(
                "member {} at byte {start} overlaps the one before it",
                crate::io::excerpt(&members[i].name)
            ));
        }
        unlisted(file, at, start, &members)?;
        at = end;
    }
    if at > directory {
        let last = crate::io::excerpt(spans.last().map_or("", |s| members[s.2].name.as_str()));
        return Err(format!(
            "member {last}: its data runs past the end of the members (the central directory at byte {directory})"
        ));
    }
    unlisted(file, at, directory, &members)?;
    Ok(members)
}

/// Refuses bytes `from..to` between members when they could hold one (naming it when its local
/// header can be read).
fn unlisted(mut file: &File, from: u64, to: u64, members: &[Member]) -> std::result::Result<(), String> {
    if to.saturating_sub(from) < LOCAL_HEADER_LEN {
        return Ok(());
    }
    file.seek(SeekFrom::Start(from)).map_err(|e| e.to_string())?;
    // At most the header (two u16-sized fields past its fixed part) is read.
    let mut header = file.take((to - from).min(LOCAL_HEADER_LEN + 2 * 65535));
    let hidden = match zip::read::read_zipfile_from_stream(&mut header) {
        Ok(Some(f)) => f.name().to_string(),
        _ => return Err(format!("bytes {from}..{to} between members belong to none")),
    };
    if members.iter().any(|m| key(&m.name) == key(&hidden)) {
        return Err(ambiguous(&hidden));
    }
    Err(format!(
        "bytes {from}..{to} hold member {}, which the central directory does not list",
        crate::io::excerpt(&hidden)
    ))
}

fn ambiguous(name: &str) -> String {
    format!(
        "two arrays named '{}': ambiguous (numpy reads the last, other readers the first)",
        crate::io::excerpt(key(name))
    )
}

#[cfg(test)]
#[path = "npz_tests.rs"]
mod tests;
