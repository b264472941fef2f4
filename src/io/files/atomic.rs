//! Write-to-temp-then-rename, so readers never see a partial file under the final name.
//!
//! Temporaries are made by the `tempfile` crate in the destination folder: a fresh random
//! name opened with `O_CREAT | O_EXCL` (a planted symlink or file under that name makes the
//! open fail, it is never followed or truncated), named `.viewsynth-<pid>-<random>`. Each is
//! held under an exclusive `flock(2)` while its writer lives (a staging folder through the
//! lock file inside it), so the file set's `remove_orphan_temporaries` (which sits above
//! this file: it also rolls staging folders forward) tells a killed run's leftovers from a
//! live run's by trying the lock: unlike a pid, a lock means the same in every PID namespace
//! and container sharing the volume, and it is released by the kernel when its holder dies.
//!
//! A temporary is unlocked for the microseconds between its creation and its lock, when a
//! cleaner may take it. The maker then checks, once locked, that the name is still its file
//! ([`is_same_file`]) and otherwise makes another, so a cleaner can remove any unlocked
//! temporary at once, however young: a kill leaves nothing that outlives the next run's start.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::{Component, Path};

use crate::error::{Error, Result};

/// Prefix of every temporary file or folder this crate creates beside its outputs.
pub const TEMP_PREFIX: &str = ".viewsynth-";

/// How many temporaries [`temp_file_in`] makes before giving up, when a cleaner of another run
/// takes each one between its creation and its lock.
const TEMP_TRIES: usize = 16;

/// Takes `file`'s exclusive lock without waiting: Ok(true) when taken, Ok(false) when another
/// open file holds it.
fn try_lock(file: &File) -> io::Result<bool> {
    use rustix::fs::{flock, FlockOperation};
    match flock(file, FlockOperation::NonBlockingLockExclusive) {
        Ok(()) => Ok(true),
        Err(e) if e == rustix::io::Errno::WOULDBLOCK => Ok(false),
        Err(e) => Err(e.into()),
    }
}

/// Takes `file`'s lock (as [`try_lock`]) and tells whether this process now owns the
/// temporary at `path`: locked, and `path` still names `file` (a cleaner may have taken and
/// removed it before the lock; see the module notes).
pub(crate) fn lock_if_current(file: &File, path: &Path) -> io::Result<bool> {
    Ok(try_lock(file)? && is_same_file(file, path))
}

/// Whether `file` is still the file at `path` (not followed): false once `path` was removed
/// or replaced.
fn is_same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), fs::symlink_metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Opens an existing temporary to try its lock: never through a symlink, never blocking on
/// a FIFO planted under our prefix.
pub(crate) fn open_for_lock(path: &Path) -> io::Result<File> {
    fs::OpenOptions::new()
        .read(true)
        .custom_flags(rustix::fs::OFlags::NOFOLLOW.bits() as i32 | rustix::fs::OFlags::NONBLOCK.bits() as i32)
        .open(path)
}

/// Refuses to replace anything at `path` but a regular file or a symlink (which is replaced,
/// never followed): a folder, FIFO, socket or device (`--json /dev/null` run as root) stays.
pub(crate) fn check_replaceable(path: &Path) -> Result<()> {
    let t = match fs::symlink_metadata(path) {
        Ok(m) => m.file_type(),
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(Error::io(path, e)),
    };
    let what = if t.is_file() || t.is_symlink() {
        return Ok(());
    } else if t.is_dir() {
        "a folder"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else {
        "not a regular file"
    };
    Err(Error::io(
        path,
        io::Error::new(
            io::ErrorKind::AlreadyExists,
            format!("{what} is in the way of this output: only regular files are replaced"),
        ),
    ))
}

/// The fault-injection hook of the file layer, for tests of the commit protocol:
/// `VIEWSYNTH_FAULT_AFTER=<k>` ends the process at once with status 137 (as SIGKILL would) right after the
/// k-th step (1-based) of the process's commits, `<k>:fail` returns an error there instead.
/// Steps: a set's journal written, each rename, then its staging folder's journal, lock file and
/// folder removed. Unset: no effect.
pub(crate) fn fault_point(what: &str) -> Result<()> {
    use std::sync::atomic::{AtomicU64, Ordering};
    use std::sync::OnceLock;
    static PLAN: OnceLock<Option<(u64, bool)>> = OnceLock::new();
    static STEP: AtomicU64 = AtomicU64::new(0);
    let plan = PLAN.get_or_init(|| {
        let v = std::env::var("VIEWSYNTH_FAULT_AFTER").ok()?;
        let (k, fail) = match v.split_once(':') {
            Some((k, "fail")) => (k, true),
            Some(_) => return None,
            None => (v.as_str(), false),
        };
        Some((k.parse().ok()?, fail))
    });
    let Some((k, fail)) = *plan else { return Ok(()) };
    let step = STEP.fetch_add(1, Ordering::SeqCst) + 1;
    if step != k {
        return Ok(());
    }
    if fail {
        return Err(Error::io(
            what,
            io::Error::other(format!("injected fault after step {k} (VIEWSYNTH_FAULT_AFTER)")),
        ));
    }
    // At once, without destructors (staging folders stay, locks are released by the kernel),
    // as SIGKILL leaves things; 137 is the shell's status of a SIGKILLed process.
    std::process::exit(137)
}

/// Buffer of the files written: an output of a few MB goes to the kernel in a few writes (8 KiB,
/// `BufWriter`'s default, cost a VGA frame's files ~300 write calls).
pub(crate) const WRITE_BUFFER: usize = 1 << 20;

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
/// Held under its lock (see the module notes) until closed.
pub(crate) fn temp_file_in(dir: &Path, shown: &Path) -> Result<tempfile::NamedTempFile> {
    use std::os::unix::fs::PermissionsExt;
    for _ in 0..TEMP_TRIES {
        let temp = tempfile::Builder::new()
            .prefix(&own_prefix())
            .suffix(".tmp")
            // What a plain create gives (the umask applies), not tempfile's private 0600.
            .permissions(fs::Permissions::from_mode(0o666))
            .tempfile_in(dir)
            .map_err(|e| Error::io(shown, e))?;
        // Taken by a cleaner before the lock (see the module notes): make another.
        if lock_if_current(temp.as_file(), temp.path()).map_err(|e| Error::io(shown, e))? {
            return Ok(temp);
        }
    }
    Err(Error::io(
        shown,
        io::Error::other(format!(
            "another process removed each of {TEMP_TRIES} temporaries as soon as it was made"
        )),
    ))
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
    check_replaceable(path)?;
    let temp = temp_file_in(parent_dir(path), path)?;
    let (file, temp_path) = temp.into_parts();
    let mut writer = BufWriter::with_capacity(WRITE_BUFFER, file);
    write(&mut writer)?;
    writer.flush().map_err(|e| Error::io(path, e))?;
    let file = writer.into_inner().map_err(|e| Error::io(path, e.into_error()))?;
    file.sync_all().map_err(|e| Error::io(path, e))?;
    // Checked again just before the rename: the path may have changed while writing.
    check_replaceable(path)?;
    // `persist` renames; on failure the TempPath it hands back removes the file when dropped.
    // The file (and its lock) is closed only after the rename.
    temp_path.persist(path).map_err(|e| Error::io(path, e.error))?;
    drop(file);
    Ok(())
}

/// Checks that `dir` accepts new files by creating and removing an exclusive temporary: an
/// existing file or symlink of any name is never opened, so nothing outside `dir` can change.
pub fn probe_writable(dir: &Path) -> Result<()> {
    let temp = temp_file_in(dir, dir)?;
    temp.close().map_err(|e| Error::io(dir, e))
}

/// `name` must be one normal path component and not look like one of our temporaries.
pub(crate) fn check_plain_name(name: &str, dir: &Path) -> Result<()> {
    let mut parts = Path::new(name).components();
    let plain = matches!((parts.next(), parts.next()), (Some(Component::Normal(_)), None));
    if !plain || name.starts_with(TEMP_PREFIX) {
        return Err(Error::param(
            "output name",
            format!(
                "'{name}' in {}: must be a plain file name (no '/', '..' or '{TEMP_PREFIX}' prefix)",
                dir.display()
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::files::staging::remove_orphan_temporaries;
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
    fn orphan_clean_up_spares_locked_temporaries_whatever_their_pid() {
        let dir = scratch_dir("atomic-orphans");
        // pid 1 is alive here, u32::MAX - 1 is no pid: neither decides any more, the lock does.
        let unlocked = format!("{TEMP_PREFIX}1-abc.tmp");
        let locked = format!("{TEMP_PREFIX}{}-abc.tmp", u32::MAX - 1);
        for n in [&unlocked, &locked, &"keep.png".to_string()] {
            fs::write(dir.join(n), b"x").unwrap();
        }
        let holder = File::open(dir.join(&locked)).unwrap();
        assert!(try_lock(&holder).unwrap());
        // Unlocked goes at once, however young (its maker, if alive, makes another).
        assert_eq!(remove_orphan_temporaries(&dir), 1);
        let mut want = vec![locked.clone(), "keep.png".to_string()];
        want.sort();
        assert_eq!(list_dir(&dir), want);
        drop(holder);
        assert_eq!(remove_orphan_temporaries(&dir), 1);
        assert_eq!(list_dir(&dir), ["keep.png"]);
    }

    /// Writers racing a cleaner that runs without pause: every write lands (a temporary taken
    /// before its lock is made again), and nothing is left behind.
    #[test]
    fn writes_survive_a_cleaner_racing_them() {
        use std::sync::atomic::{AtomicBool, Ordering};
        let dir = scratch_dir("atomic-race");
        let stop = AtomicBool::new(false);
        let removed = std::thread::scope(|scope| {
            let cleaner = scope.spawn(|| {
                let mut n = 0;
                while !stop.load(Ordering::Relaxed) {
                    n += remove_orphan_temporaries(&dir);
                }
                n
            });
            let writers: Vec<_> = (0..4)
                .map(|t| {
                    let dir = &dir;
                    scope.spawn(move || {
                        for i in 0..200 {
                            let path = dir.join(format!("w{t}.bin"));
                            atomic_write(&path, |w| w.write_all(&[i as u8; 64]).map_err(|e| Error::io("w", e)))
                                .unwrap();
                            assert_eq!(fs::read(&path).unwrap(), [i as u8; 64]);
                        }
                    })
                })
                .collect();
            let results: Vec<_> = writers.into_iter().map(|w| w.join()).collect();
            // Stopped before any panic below, or the scope would wait on the cleaner forever.
            stop.store(true, Ordering::Relaxed);
            let removed = cleaner.join().unwrap();
            assert!(results.iter().all(|r| r.is_ok()), "a writer failed");
            removed
        });
        assert_eq!(list_dir(&dir), ["w0.bin", "w1.bin", "w2.bin", "w3.bin"]);
        // A cleaner taking a temporary before its lock is rare (a window of microseconds).
        eprintln!("temporaries the cleaner took: {removed}");
    }

    #[test]
    fn non_regular_destinations_are_never_replaced() {
        let dir = scratch_dir("atomic-nonregular");
        let fifo = dir.join("fifo");
        rustix::fs::mknodat(
            rustix::fs::CWD,
            &fifo,
            rustix::fs::FileType::Fifo,
            rustix::fs::Mode::from_raw_mode(0o600),
            0,
        )
        .unwrap();
        let err = atomic_write(&fifo, |w| w.write_all(b"x").map_err(|e| Error::io("x", e))).unwrap_err();
        assert!(err.to_string().contains("FIFO"), "{err}");
        assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
        let err = atomic_write(Path::new("/dev/null"), |_| Ok(())).unwrap_err();
        assert!(err.to_string().contains("device"), "{err}");
        assert!(fs::symlink_metadata("/dev/null").unwrap().file_type().is_char_device());
        assert_eq!(list_dir(&dir), ["fifo"]);
    }
}
