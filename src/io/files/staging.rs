//! A [`FileSet`](super::file_set::FileSet)'s private staging folder (steps 1 and 5 of the commit protocol in
//! [`super::file_set`]'s notes) and what a later run does with one a killed run left: removed
//! when it has no journal, rolled forward when it has.

use std::fs::{self, File};
use std::io;
use std::path::{Path, PathBuf};

use super::atomic::{
    check_plain_name, check_replaceable, fault_point, lock_if_current, open_for_lock, own_prefix, TEMP_PREFIX,
};
use super::file_set::remove_own_file;
use crate::error::{Error, Result};

/// The lock file inside a staging folder (see the module notes).
pub(super) const LOCK_NAME: &str = ".viewsynth-lock";
/// The journal naming a committing set's files in rename order.
pub(super) const JOURNAL_NAME: &str = ".viewsynth-commit";
/// How many staging folders `FileSet::new` makes before giving up, when a cleaner of
/// another run takes each one between its creation and its lock (a race of microseconds).
const STAGING_TRIES: usize = 16;

/// Removes the temporaries (files or staging folders named `.viewsynth-…`) that a run killed
/// before it could clean up left in `dir`; returns how many were removed. A temporary whose
/// lock another process holds is a live run's and is never touched, whatever its pid says (a
/// pid is meaningless across PID namespaces); an unlocked one goes at once, however young
/// (its maker, if alive, makes another: see the module notes). A staging folder killed after
/// its journal was written is first rolled forward (its remaining files renamed into `dir`,
/// the manifest last), so a set is always either the old one or the new one, complete.
pub fn remove_orphan_temporaries(dir: &Path) -> usize {
    let Ok(entries) = fs::read_dir(dir) else { return 0 };
    let mut removed = 0;
    for e in entries.flatten() {
        let name = e.file_name();
        if !name.to_str().is_some_and(|n| n.starts_with(TEMP_PREFIX)) {
            continue;
        }
        // file_type does not follow symlinks: a planted link is removed, not its target.
        let ok = match e.file_type() {
            Ok(t) if t.is_dir() => recover_staging(dir, &e.path()),
            Ok(t) if t.is_file() => match open_for_lock(&e.path()) {
                // Removed while locked, so its maker's late lock finds the name gone.
                Ok(f) => lock_if_current(&f, &e.path()).unwrap_or(false) && fs::remove_file(e.path()).is_ok(),
                Err(_) => false,
            },
            // Never ours (we make none) and harmless: left alone.
            _ => false,
        };
        removed += usize::from(ok);
    }
    removed
}

/// Renames the files a journalled staging folder still holds into `dir`, in the journal's
/// order, then removes the folder. True when the folder is gone.
pub(super) fn roll_forward(dir: &Path, staging: &Path) -> bool {
    let Ok(journal) = fs::read_to_string(staging.join(JOURNAL_NAME)) else {
        return false;
    };
    for name in journal.lines() {
        if let Some(stale) = name.strip_prefix('/') {
            if check_plain_name(stale, dir).is_err() || remove_own_file(&dir.join(stale)).is_err() {
                return false;
            }
            continue;
        }
        // Names were checked when the set was made; anything else is not ours to move.
        if check_plain_name(name, dir).is_err() {
            return false;
        }
        let from = staging.join(name);
        match fs::symlink_metadata(&from) {
            Ok(m) if m.is_file() => {
                if check_replaceable(&dir.join(name)).is_err() || fs::rename(&from, dir.join(name)).is_err() {
                    return false;
                }
            }
            Ok(_) => return false,
            Err(_) => {} // renamed before the kill
        }
    }
    sync_dir(dir);
    fs::remove_dir_all(staging).is_ok()
}

/// Makes a staging folder in `dir` and takes its lock. A cleaner of another run may take the
/// folder between its creation and its lock (it looks orphaned then): this maker notices (see
/// [`claim_lock`]) and makes another.
pub(super) fn make_staging(dir: &Path) -> Result<(Staging, File)> {
    for _ in 0..STAGING_TRIES {
        let staging = Staging {
            path: tempfile::Builder::new()
                .prefix(&own_prefix())
                .tempdir_in(dir)
                .map_err(|e| Error::io(dir, e))?
                .keep(),
            names: Vec::new(),
            kept: false,
        };
        match claim_lock(staging.path()) {
            Ok(Some(lock)) => return Ok((staging, lock)),
            // Taken by a cleaner: dropping `staging` removes what it left, if anything.
            Ok(None) => continue,
            Err(e) => return Err(Error::io(dir, e)),
        }
    }
    Err(Error::io(
        dir,
        io::Error::other(format!(
            "another process removed each of {STAGING_TRIES} staging folders as soon as it was made"
        )),
    ))
}

/// A set's staging folder, removed when dropped uncommitted, even when the process ran out of
/// file descriptors (EMFILE: often the very error that failed the set). A removal that lists
/// the folder needs a descriptor, unlinking a name does not: the names staged are removed by
/// name, the listing (for files staged by path) is retried while other threads free theirs,
/// then the lock file and the folder go. `tempfile::TempDir` tried one listing and silently
/// left the folder, with its partial files, when it failed.
#[derive(Debug)]
pub(super) struct Staging {
    path: PathBuf,
    /// Names created in it so far.
    pub(super) names: Vec<String>,
    /// Handed over to the commit: no longer removed on drop.
    kept: bool,
}

/// How long [`Staging`]'s removal waits, in all, for a descriptor to list its folder.
const STAGING_LIST_TRIES: usize = 50;

impl Staging {
    pub(super) fn path(&self) -> &Path {
        &self.path
    }

    /// The folder, no longer removed on drop.
    pub(super) fn keep(mut self) -> PathBuf {
        self.kept = true;
        std::mem::take(&mut self.path)
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if self.kept {
            return;
        }
        for name in self.names.iter().map(String::as_str).chain([JOURNAL_NAME]) {
            let _ = fs::remove_file(self.path.join(name));
        }
        if let Ok(entries) = read_dir_patiently(&self.path) {
            for e in entries.flatten() {
                if e.file_name() != LOCK_NAME {
                    let _ = fs::remove_file(e.path());
                }
            }
        }
        let _ = fs::remove_file(self.path.join(LOCK_NAME));
        let _ = fs::remove_dir(&self.path);
    }
}

/// `fs::read_dir(path)`, retried while the process has no descriptor to spare (EMFILE, ENFILE:
/// other threads free theirs), for at most [`STAGING_LIST_TRIES`] x 10 ms. Listing a folder
/// needs a descriptor; the commit's own cleanup failed on it under `ulimit -n` and left the
/// emptied staging folder of a committed set behind.
fn read_dir_patiently(path: &Path) -> io::Result<fs::ReadDir> {
    let mut tries = 0;
    loop {
        match fs::read_dir(path) {
            Err(e) if matches!(e.raw_os_error(), Some(libc::EMFILE | libc::ENFILE)) && tries < STAGING_LIST_TRIES => {
                tries += 1;
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            r => return r,
        }
    }
}

/// Creates the lock file of the staging folder `staging` and takes its lock: `Some` when this
/// call now owns the folder, `None` when another process got there first (made the lock file,
/// holds its lock, or removed it or the folder meanwhile). The maker of a folder and a cleaner
/// of a lockless one both claim it this way, so exactly one of them wins.
fn claim_lock(staging: &Path) -> io::Result<Option<File>> {
    let path = staging.join(LOCK_NAME);
    let file = match File::options().write(true).create_new(true).open(&path) {
        Ok(f) => f,
        Err(e) if matches!(e.kind(), io::ErrorKind::AlreadyExists | io::ErrorKind::NotFound) => return Ok(None),
        Err(e) => return Err(e),
    };
    // Between the create and the lock a cleaner may have taken the file and removed it.
    Ok(lock_if_current(&file, &path)?.then_some(file))
}

/// Empties and removes this run's own staging folder after its commit: the journal first (a
/// kill now leaves a locked-file folder with nothing to roll forward), then anything else, then
/// the lock file (a kill now leaves an empty folder), then the folder. Every state a kill can
/// leave is one [`recover_staging`] removes at once.
pub(super) fn remove_staging(staging: &Path) -> io::Result<()> {
    let gone = |r: io::Result<()>| match r {
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        other => other,
    };
    gone(fs::remove_file(staging.join(JOURNAL_NAME)))?;
    fault_point("journal removed").map_err(io::Error::other)?;
    for e in read_dir_patiently(staging)?.flatten() {
        if e.file_name() != LOCK_NAME {
            gone(fs::remove_file(e.path()))?;
        }
    }
    gone(fs::remove_file(staging.join(LOCK_NAME)))?;
    fault_point("lock file removed").map_err(io::Error::other)?;
    match fs::remove_dir(staging) {
        // A cleaner claimed the lockless folder meanwhile (its new lock file is inside): the
        // folder holds nothing of this set any more, and that cleaner removes it.
        Err(e) if e.kind() == io::ErrorKind::DirectoryNotEmpty => {}
        r => gone(r)?,
    }
    fault_point("staging removed").map_err(io::Error::other)
}

/// What a later run does with a staging folder `staging` in `dir` (see the module notes):
/// nothing while its lock is held; else rolled forward when journalled, removed otherwise. A
/// folder without a lock file is claimed first (see [`claim_lock`]). True when the folder is
/// gone.
fn recover_staging(dir: &Path, staging: &Path) -> bool {
    let path = staging.join(LOCK_NAME);
    let _lock = match open_for_lock(&path) {
        // Held only if it is still the folder's lock file once locked.
        Ok(f) if lock_if_current(&f, &path).unwrap_or(false) => f,
        Ok(_) => return false,
        Err(e) if e.kind() == io::ErrorKind::NotFound => match claim_lock(staging) {
            Ok(Some(f)) => f,
            _ => return false,
        },
        Err(_) => return false,
    };
    if staging.join(JOURNAL_NAME).exists() {
        roll_forward(dir, staging)
    } else {
        fs::remove_dir_all(staging).is_ok()
    }
}

/// Syncs `dir` itself, so the renames in it are durable; best effort.
pub(super) fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}
