//! [`OutDir`]: `--out-dir` made ready (created, resolved, probed) and the only way to reach
//! folders under it: [`OutDir::subdir`] refuses a subfolder that is a symlink or resolves
//! elsewhere, so outputs never land outside the real out-dir.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use super::atomic::{check_plain_name, probe_writable};
use super::file_set::FileSet;
use super::staging::remove_orphan_temporaries;
use crate::error::{Error, Result};

/// An output folder that exists, accepts files, and bounds where outputs may go.
#[derive(Debug, Clone)]
pub struct OutDir {
    /// As the user gave it (for messages and the paths printed).
    shown: PathBuf,
    /// Resolved (symlinks followed once, at the root only).
    real: PathBuf,
}

impl OutDir {
    /// Creates `dir` (and its parents) if missing, resolves it, checks that it accepts new
    /// files (without opening any existing name) and removes temporaries that killed runs left
    /// in it (never those of a live process). The folder itself may be a symlink: where it
    /// points is the out-dir.
    pub fn prepare(dir: &Path) -> Result<Self> {
        check_not_a_broken_link(dir)?;
        fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let real = fs::canonicalize(dir).map_err(|e| Error::io(dir, e))?;
        if !real.is_dir() {
            return Err(Error::io(
                dir,
                io::Error::new(io::ErrorKind::NotADirectory, "not a directory"),
            ));
        }
        probe_writable(&real).map_err(|e| match e {
            Error::Io { source, .. } => Error::Io {
                path: dir.to_path_buf(),
                source: io::Error::new(source.kind(), format!("output directory is not writable ({source})")),
            },
            other => other,
        })?;
        remove_orphan_temporaries(&real);
        Ok(Self {
            shown: dir.to_path_buf(),
            real,
        })
    }

    /// The folder as given (join output names onto this for messages).
    pub fn path(&self) -> &Path {
        &self.shown
    }

    /// The folder with symlinks resolved.
    pub fn real_path(&self) -> &Path {
        &self.real
    }

    /// The folder `name` (one plain path component) directly inside, created if missing.
    /// Refused, with the path named, when it exists as a symlink or as anything but a folder,
    /// or when it resolves outside this out-dir.
    pub fn subdir(&self, name: &str) -> Result<OutDir> {
        check_plain_name(name, &self.shown)?;
        let shown = self.shown.join(name);
        let real = self.real.join(name);
        match fs::symlink_metadata(&real) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = fs::read_link(&real)
                    .map(|t| t.display().to_string())
                    .unwrap_or_default();
                return Err(outside(&shown, &self.shown, &format!("is a symlink to {target}")));
            }
            Ok(m) if !m.is_dir() => {
                return Err(Error::io(
                    &shown,
                    io::Error::new(io::ErrorKind::NotADirectory, "exists and is not a directory"),
                ))
            }
            Ok(_) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => match fs::create_dir(&real) {
                Ok(()) => {}
                // Another process made it meanwhile: checked below like any existing folder.
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
                Err(e) => return Err(Error::io(&shown, e)),
            },
            Err(e) => return Err(Error::io(&shown, e)),
        }
        let resolved = fs::canonicalize(&real).map_err(|e| Error::io(&shown, e))?;
        if resolved.parent() != Some(self.real.as_path()) || !resolved.is_dir() {
            return Err(outside(
                &shown,
                &self.shown,
                &format!("resolves to {}", resolved.display()),
            ));
        }
        remove_orphan_temporaries(&resolved);
        Ok(OutDir { shown, real: resolved })
    }

    /// A new, empty set of files to be written into this folder.
    pub fn file_set(&self) -> Result<FileSet> {
        FileSet::new(&self.real).map(|s| s.shown_as(&self.shown))
    }
}

/// A symlink that leads nowhere (dangling, or a loop) is refused saying so: creating the folder
/// would fail with a bare "File exists".
fn check_not_a_broken_link(dir: &Path) -> Result<()> {
    let is_link = fs::symlink_metadata(dir).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link {
        return Ok(());
    }
    let what = match fs::metadata(dir) {
        Ok(_) => return Ok(()),
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => "is a symlink loop".to_string(),
        Err(e) if e.kind() == io::ErrorKind::NotFound => format!(
            "is a dangling symlink (to {}, which does not exist)",
            fs::read_link(dir).map(|t| t.display().to_string()).unwrap_or_default()
        ),
        Err(e) => return Err(Error::io(dir, e)),
    };
    Err(Error::io(
        dir,
        io::Error::new(
            io::ErrorKind::NotFound,
            format!("the output directory {what}: create its target or give another --out-dir"),
        ),
    ))
}

fn outside(path: &Path, root: &Path, what: &str) -> Error {
    Error::io(
        path,
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{what}: outputs are only written inside --out-dir {}; remove or rename it",
                root.display()
            ),
        ),
    )
}
