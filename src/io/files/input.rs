//! Bounded input: the pixel budget every loader checks from a file's header before it reads
//! the body or allocates pixel memory, and opening inputs that must have a known size.

use std::fs::{self, File};
use std::io::{Read, Seek, SeekFrom};
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Default pixel budget per input or output image: 8192 x 8192. The heaviest command
/// (cyclopean: two eyes of colour and depth, their GPU textures and the outputs) needs about
/// 22 bytes per pixel, so a run at the budget stays within about 1.5 GB.
pub const DEFAULT_MAX_PIXELS: u64 = 8192 * 8192;

static MAX_PIXELS: AtomicU64 = AtomicU64::new(DEFAULT_MAX_PIXELS);

/// Sets the pixel budget (width x height) every loader enforces from the header, process
/// wide (the CLI's `--max-pixels`). 0 is refused.
pub fn set_max_pixels(pixels: u64) -> Result<()> {
    if pixels == 0 {
        return Err(Error::param("max-pixels", "must be at least 1"));
    }
    MAX_PIXELS.store(pixels, Ordering::Relaxed);
    Ok(())
}

/// The pixel budget in force (see [`set_max_pixels`]).
pub fn max_pixels() -> u64 {
    MAX_PIXELS.load(Ordering::Relaxed)
}

/// Refuses a `width x height` image of `path` above the pixel budget, naming both.
pub(crate) fn check_budget(path: &Path, width: u64, height: u64) -> Result<()> {
    let pixels = width.saturating_mul(height);
    let budget = max_pixels();
    if pixels > budget {
        return Err(Error::decode(
            path,
            format!(
                "{width}x{height} = {pixels} pixels exceeds the pixel budget of {budget} \
                 (--max-pixels; refused before reading the pixels)"
            ),
        ));
    }
    Ok(())
}

/// Same check for an image about to be rendered (`what` names the parameter).
pub fn check_output_pixels(what: impl Into<crate::Message>, width: u32, height: u32) -> Result<()> {
    let pixels = u64::from(width) * u64::from(height);
    let budget = max_pixels();
    if pixels > budget {
        return Err(Error::param(
            what,
            crate::msg![
                format!("{width}x{height} = {pixels} pixels exceeds the pixel budget of {budget} ("),
                crate::Field::MaxPixels,
                ")"
            ],
        ));
    }
    Ok(())
}

/// Opens an input that must be a regular file (a FIFO, device or folder has no size to check
/// and could be read forever). Symlinks to regular files are fine. Returns the file and its
/// length.
pub(crate) fn open_regular(path: &Path) -> Result<(File, u64)> {
    // stat before open: opening a FIFO would block until a writer appears.
    let meta = fs::metadata(path).map_err(|e| Error::io(path, e))?;
    refuse_irregular(path, &meta)?;
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    refuse_irregular(path, &meta)?;
    Ok((file, meta.len()))
}

fn refuse_irregular(path: &Path, meta: &fs::Metadata) -> Result<()> {
    let t = meta.file_type();
    let kind = if t.is_file() {
        return Ok(());
    } else if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    };
    Err(Error::decode(
        path,
        format!("{kind}: inputs must be regular files (their size is checked before reading)"),
    ))
}

/// The first `min(len, cap)` bytes of `file` (a text header and what follows it).
pub(crate) fn read_prefix(path: &Path, file: &mut File, len: u64, cap: usize) -> Result<Vec<u8>> {
    let n = usize::try_from(len).map_or(cap, |l| l.min(cap));
    let mut buf = vec![0; n];
    file.seek(SeekFrom::Start(0)).map_err(|e| Error::io(path, e))?;
    file.read_exact(&mut buf).map_err(|e| Error::io(path, e))?;
    Ok(buf)
}

/// Exactly `n` bytes of `file` from `offset` (the declared body, never more).
pub(crate) fn read_body(path: &Path, file: &mut File, offset: u64, n: usize) -> Result<Vec<u8>> {
    let mut buf = Vec::new();
    buf.try_reserve_exact(n)
        .map_err(|_| Error::decode(path, format!("cannot allocate {n} bytes for the pixels")))?;
    file.seek(SeekFrom::Start(offset)).map_err(|e| Error::io(path, e))?;
    let got = file
        .by_ref()
        .take(n as u64)
        .read_to_end(&mut buf)
        .map_err(|e| Error::io(path, e))?;
    if got != n {
        return Err(Error::decode(
            path,
            format!("truncated: {n} bytes of pixels expected, the file holds {got}"),
        ));
    }
    Ok(buf)
}

/// Refuses a file whose length exceeds what its header can account for (`what` says why).
pub(crate) fn check_file_len(path: &Path, len: u64, most: u64, what: &str) -> Result<()> {
    if len > most {
        return Err(Error::decode(
            path,
            format!("file is {len} bytes, more than the {most} that {what} can hold"),
        ));
    }
    Ok(())
}
