//! Write-to-temp-then-rename, so readers never see a partial file under the final name.
//!
//! Temporaries are made by the `tempfile` crate in the destination folder: a fresh random
//! name opened with `O_CREAT | O_EXCL` (a planted symlink or file under that name makes the
//! open fail, it is never followed or truncated), named `.viewsynth-<pid>-<random>` so that
//! [`remove_orphan_temporaries`] can tell a killed run's leftovers from a live run's.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::Path;

use crate::error::{Error, Result};

/// Prefix of every temporary file or folder this crate creates beside its outputs.
pub const TEMP_PREFIX: &str = ".viewsynth-";

/// The prefix of this process's temporaries: `.viewsynth-<pid>-`.
pub(crate) fn own_prefix() -> String {
    format!("{TEMP_PREFIX}{}-", std::process::id())
}

/// The folder `path` lives in (`.` for a bare file name).
pub(crate) fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A new temporary file in `dir`, created exclusively (never through an existing name).
/// Errors name `shown`.
pub(crate) fn temp_file_in(dir: &Path, shown: &Path) -> Result<tempfile::NamedTempFile> {
    use std::os::unix::fs::PermissionsExt;
    tempfile::Builder::new()
        .prefix(&own_prefix())
        .suffix(".tmp")
        // What a plain create gives (the umask applies), not tempfile's private 0600.
        .permissions(fs::Permissions::from_mode(0o666))
        .tempfile_in(dir)
        .map_err(|e| Error::io(shown, e))
}

/// Writes `path` atomically: `write` fills a fresh temporary in the same folder (so the final
/// rename never crosses file systems), which is then flushed, synced and renamed over `path`.
/// On any error (or a panic in `write`) the temporary is removed and an existing file at
/// `path` is left untouched. A symlink at `path` is replaced, never written through. Errors
/// from the file system name `path`.
pub fn atomic_write(path: &Path, write: impl FnOnce(&mut BufWriter<File>) -> Result<()>) -> Result<()> {
    if path.file_name().is_none() {
        return Err(Error::io(
            path,
            io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"),
        ));
    }
    let temp = temp_file_in(parent_dir(path), path)?;
    let (file, temp_path) = temp.into_parts();
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    writer.flush().map_err(|e| Error::io(path, e))?;
    let file = writer.into_inner().map_err(|e| Error::io(path, e.into_error()))?;
    file.sync_all().map_err(|e| Error::io(path, e))?;
    drop(file);
    // `persist` renames; on failure the TempPath it hands back removes the file when dropped.
    temp_path.persist(path).map_err(|e| Error::io(path, e.error))?;
    Ok(())
}

/// Checks that `dir` accepts new files by creating and removing an exclusive temporary: an
/// existing file or symlink of any name is never opened, so nothing outside `dir` can change.
pub fn probe_writable(dir: &Path) -> Result<()> {
    let temp = temp_file_in(dir, dir)?;
    temp.close().map_err(|e| Error::io(dir, e))
}

/// Removes the temporaries (files or staging folders named `.viewsynth-<pid>-…`) that a run
/// killed before it could clean up left in `dir`. Only those whose process no longer exists
/// are removed: a concurrent run's temporaries are never touched. Returns how many were
/// removed. Where liveness cannot be checked (no `/proc`), nothing is removed.
pub fn remove_orphan_temporaries(dir: &Path) -> usize {
    if !Path::new("/proc/self").exists() {
        return 0;
    }
    let Ok(entries) = fs::read_dir(dir) else { return 0 };
    let mut removed = 0;
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(pid) = name.to_str().and_then(temp_owner) else {
            continue;
        };
        if pid == std::process::id() || Path::new(&format!("/proc/{pid}")).exists() {
            continue;
        }
        // file_type does not follow symlinks: a planted link is removed, not its target.
        let ok = match e.file_type() {
            Ok(t) if t.is_dir() => fs::remove_dir_all(e.path()).is_ok(),
            Ok(_) => fs::remove_file(e.path()).is_ok(),
            Err(_) => false,
        };
        removed += usize::from(ok);
    }
    removed
}

/// The pid in a temporary's name `.viewsynth-<pid>-<random>`, if it is one.
fn temp_owner(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(TEMP_PREFIX)?;
    let (pid, random) = rest.split_once('-')?;
    if random.is_empty() {
        return None;
    }
    pid.parse().ok()
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

    #[test]
    fn symlink_at_target_is_replaced_not_followed() {
        let dir = scratch_dir("atomic-link");
        let victim = dir.join("victim");
        fs::write(&victim, b"precious").unwrap();
        let out = dir.join("sub");
        fs::create_dir(&out).unwrap();
        std::os::unix::fs::symlink(&victim, out.join("out.bin")).unwrap();
        atomic_write(&out.join("out.bin"), |w| {
            w.write_all(b"new").map_err(|e| Error::io("x", e))
        })
        .unwrap();
        assert_eq!(fs::read(&victim).unwrap(), b"precious");
        assert!(!fs::symlink_metadata(out.join("out.bin"))
            .unwrap()
            .file_type()
            .is_symlink());
    }

    #[test]
    fn probe_never_follows_a_planted_symlink() {
        let dir = scratch_dir("atomic-probe");
        let victim = dir.join("victim");
        fs::write(&victim, b"precious").unwrap();
        let out = dir.join("out");
        fs::create_dir(&out).unwrap();
        // Names an older probe used, and this process's own prefix.
        for name in [
            format!(".viewsynth-write-test-{}", std::process::id()),
            format!("{}x", own_prefix()),
        ] {
            std::os::unix::fs::symlink(&victim, out.join(name)).unwrap();
        }
        probe_writable(&out).unwrap();
        assert_eq!(fs::read(&victim).unwrap(), b"precious");
        assert_eq!(list_dir(&out).len(), 2);
    }

    #[test]
    fn orphan_clean_up_spares_live_processes() {
        let dir = scratch_dir("atomic-orphans");
        let own = format!("{}abc.tmp", own_prefix());
        // pid 1 is always alive; u32::MAX - 1 is above any pid_max.
        let live = format!("{TEMP_PREFIX}1-abc.tmp");
        let dead = format!("{TEMP_PREFIX}{}-abc.tmp", u32::MAX - 1);
        let dead_dir = format!("{TEMP_PREFIX}{}-set", u32::MAX - 1);
        for n in [&own, &live, &dead, &"keep.png".to_string()] {
            fs::write(dir.join(n), b"x").unwrap();
        }
        fs::create_dir(dir.join(&dead_dir)).unwrap();
        fs::write(dir.join(&dead_dir).join("a.png"), b"x").unwrap();
        assert_eq!(remove_orphan_temporaries(&dir), 2);
        let mut want = vec![own, live, "keep.png".to_string()];
        want.sort();
        assert_eq!(list_dir(&dir), want);
    }
}
