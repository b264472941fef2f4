//! Write-to-temp-then-rename, so readers never see a partial file under the final name.

use std::ffi::OsString;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Distinguishes concurrent writes to the same path from one process.
static NEXT_TEMP: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically: `write` fills a temporary sibling `.{name}.tmp-{pid}-{n}` in the
/// same directory (so the final rename never crosses file systems), which is then flushed,
/// synced and renamed over `path`. On any error (or a panic in `write`) the temporary file
/// is removed and an existing file at `path` is left untouched. Errors from the file system
/// name `path`.
pub fn atomic_write(path: &Path, write: impl FnOnce(&mut BufWriter<File>) -> Result<()>) -> Result<()> {
    let name = path.file_name().ok_or_else(|| {
        Error::io(
            path,
            io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"),
        )
    })?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut temp_name = OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(
        ".tmp-{}-{}",
        std::process::id(),
        NEXT_TEMP.fetch_add(1, Ordering::Relaxed)
    ));
    let temp = dir.join(temp_name);

    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&temp)
        .map_err(|e| Error::io(path, e))?;
    let mut guard = TempGuard(Some(temp));
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    writer.flush().map_err(|e| Error::io(path, e))?;
    let file = writer.into_inner().map_err(|e| Error::io(path, e.into_error()))?;
    file.sync_all().map_err(|e| Error::io(path, e))?;
    drop(file);
    if let Some(temp) = &guard.0 {
        fs::rename(temp, path).map_err(|e| Error::io(path, e))?;
    }
    guard.0 = None;
    Ok(())
}

/// Removes the temporary file unless disarmed (set to `None`) after the rename.
struct TempGuard(Option<PathBuf>);

impl Drop for TempGuard {
    fn drop(&mut self) {
        if let Some(temp) = &self.0 {
            let _ = fs::remove_file(temp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::{list_dir, scratch_dir};

    #[test]
    fn writes_and_replaces() {
        let dir = scratch_dir("atomic-ok");
        let path = dir.join("out.bin");
        atomic_write(&path, |w| w.write_all(b"first").map_err(|e| Error::io("out.bin", e))).unwrap();
        atomic_write(&path, |w| w.write_all(b"second").map_err(|e| Error::io("out.bin", e))).unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"second");
        assert_eq!(list_dir(&dir), vec!["out.bin".to_string()]);
    }

    #[test]
    fn failure_mid_way_leaves_no_files() {
        let dir = scratch_dir("atomic-fail");
        let path = dir.join("out.bin");
        let err = atomic_write(&path, |w| {
            w.write_all(&[7u8; 100_000]).map_err(|e| Error::io("x", e))?;
            Err(Error::encode("x", "boom"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("boom"));
        assert!(list_dir(&dir).is_empty(), "{:?}", list_dir(&dir));
    }

    #[test]
    fn failure_keeps_previous_file() {
        let dir = scratch_dir("atomic-keep");
        let path = dir.join("out.bin");
        fs::write(&path, b"old").unwrap();
        let _ = atomic_write(&path, |w| {
            w.write_all(b"partial").map_err(|e| Error::io("x", e))?;
            Err(Error::encode("x", "boom"))
        });
        assert_eq!(fs::read(&path).unwrap(), b"old");
        assert_eq!(list_dir(&dir), vec!["out.bin".to_string()]);
    }

    #[test]
    fn panic_in_writer_leaves_no_temp() {
        let dir = scratch_dir("atomic-panic");
        let path = dir.join("out.bin");
        let result = std::panic::catch_unwind(|| {
            let _ = atomic_write(&path, |_| panic!("writer panicked"));
        });
        assert!(result.is_err());
        assert!(list_dir(&dir).is_empty());
    }

    #[test]
    fn missing_directory_names_path() {
        let dir = scratch_dir("atomic-missing");
        let path = dir.join("no-such-dir").join("out.png");
        let err = atomic_write(&path, |_| Ok(())).unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert!(err.to_string().contains(&path.display().to_string()), "{err}");
    }

    #[test]
    fn unwritable_directory_names_path() {
        // A regular file as parent fails even for root, unlike permission bits.
        let dir = scratch_dir("atomic-unwritable");
        let blocker = dir.join("file");
        fs::write(&blocker, b"x").unwrap();
        let path = blocker.join("out.png");
        let err = atomic_write(&path, |_| Ok(())).unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert!(err.to_string().contains(&path.display().to_string()), "{err}");
        assert_eq!(list_dir(&dir), vec!["file".to_string()]);
    }

    #[test]
    fn target_is_directory_fails_cleanly() {
        let dir = scratch_dir("atomic-isdir");
        fs::create_dir(dir.join("out.png")).unwrap();
        let err = atomic_write(&dir.join("out.png"), |_| Ok(())).unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert_eq!(list_dir(&dir), vec!["out.png".to_string()]);
    }
}
