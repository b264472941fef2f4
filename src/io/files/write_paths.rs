//! Files at arbitrary paths written all-or-none, each staged in a [`FileSet`] of its own folder.

use std::fs::{self, File};
use std::io;
use std::path::{Path, PathBuf};

use super::atomic::check_replaceable;
use super::file_set::FileSet;
use crate::error::{Error, Result};

/// Writes files at arbitrary paths (e.g. `compare --diff D --json J`) all-or-none: each is
/// staged in a [`FileSet`] of its own folder, and nothing is renamed until every one was
/// written and every destination checked (absent, a regular file or a symlink; never a
/// folder). A character device or FIFO (`--json /dev/stdout`, `/dev/null`, a pipe), or any
/// path under `/dev/`, is a stream, not a file to replace: it is written in place, without
/// staging, after the staged files were written and before they are renamed. Returns the
/// paths written.
pub fn write_paths_all_or_none(jobs: Vec<(PathBuf, PathWriter<'_>)>) -> Result<Vec<PathBuf>> {
    let mut sets = Vec::with_capacity(jobs.len());
    let mut streams = Vec::new();
    for (path, _) in &jobs {
        if path.file_name().is_none() {
            return Err(Error::io(
                path,
                io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"),
            ));
        }
        if !is_stream(path) {
            check_replaceable(path)?;
        }
    }
    for (path, write) in jobs {
        if is_stream(&path) {
            streams.push((path, write));
            continue;
        }
        let dir = crate::io::files::atomic::parent_dir(&path).to_path_buf();
        let name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
        let set = FileSet::new(&dir)?.shown_as(&dir);
        write(&set.staging().join(&name)).map_err(|e| set.final_error(e))?;
        sets.push(set);
    }
    let mut done = Vec::new();
    for (path, write) in streams {
        // Held open while writing: a FIFO's reader then sees one writer, start to end.
        let _reader_present = check_reader(&path)?;
        write(&path)?;
        done.push(path);
    }
    for set in sets {
        done.extend(set.commit()?);
    }
    Ok(done)
}

/// A FIFO without a reader would block the run forever: refused at once, naming it. Returns
/// the FIFO opened for writing (without blocking), to hold while the writer writes.
fn check_reader(path: &Path) -> Result<Option<File>> {
    use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
    if !fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo()) {
        return Ok(None);
    }
    match fs::OpenOptions::new()
        .write(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
    {
        Ok(f) => Ok(Some(f)),
        Err(e) if e.raw_os_error() == Some(libc::ENXIO) => Err(Error::io(
            path,
            io::Error::new(
                io::ErrorKind::BrokenPipe,
                "a FIFO that no process reads: start its reader first",
            ),
        )),
        Err(e) => Err(Error::io(path, e)),
    }
}

/// Whether `path` is written in place: a character device or FIFO (after symlinks), or a path
/// under `/dev/` (`/dev/stdout` resolves to whatever stdout is, a regular file included).
fn is_stream(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    path.starts_with("/dev/")
        || fs::metadata(path).is_ok_and(|m| m.file_type().is_char_device() || m.file_type().is_fifo())
}

/// Writes one file given its path (the path-based savers: `io::save_rgb`, ...).
pub type PathWriter<'a> = Box<dyn FnOnce(&Path) -> Result<()> + 'a>;
