//! What a run may delete: the one rule every command's set follows.
//!
//! A set removes, at its commit and in the same journal as its renames (so only once the run
//! knows it succeeded), the previous run's files it does not write again. Only a file that a
//! regular file this program wrote itself says it wrote: the folder's `manifest.json` or its set
//! record, each read only when it is a regular file (never through a symlink: `O_NOFOLLOW`, and
//! the opened file must be the one listed) of a bounded size. A name must be a plain one, and the
//! file a regular file when it is removed. A run's inputs are never among them: each command
//! refuses, before any work, inputs that are files the previous set lists
//! ([`crate::output::check_out_dir`] takes this rule).

use std::fs::{self, File};
use std::io::{self, Read};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::Path;

use crate::io::files::atomic::check_plain_name;

/// The name renamed last in every set: its presence marks the set complete.
pub const MANIFEST_NAME: &str = "manifest.json";

/// The largest manifest or set record read (a 10 000-frame scene's record is about 3 MB): a
/// larger file is not one this program wrote, and nothing is removed on its word.
const MAX_LIST_BYTES: u64 = 64 << 20;

/// Which of the previous run's files a set replaces.
#[derive(Debug, Clone)]
pub enum Replaces {
    /// Those the folder's `manifest.json` lists, as `listed` reads them from its text.
    Manifest(fn(&str) -> Vec<String>),
    /// Those of the folder's hidden record of this name (one name a line), which every commit
    /// of the set writes again (see [`super::FileSet::replacing`]).
    Recorded(String),
    /// Every regular file whose name is one the command writes exactly (`is_own(name)` holds
    /// only for the names its writer makes, never for a pattern a user's file may match: the
    /// batch index's `index.jsonl` and `index.part-K-of-N.jsonl`).
    Owned(fn(&str) -> bool),
}

impl Replaces {
    /// The set recorded in `.viewsynth.{command}.set`.
    pub fn recorded(command: &str) -> Self {
        Replaces::Recorded(format!(".viewsynth.{command}.set"))
    }

    /// The names in `dir` a set of this kind may remove (before taking out those it writes
    /// again): plain names of regular files, sorted. None when the list is missing or not a
    /// file this program wrote.
    pub fn may_remove(&self, dir: &Path) -> Vec<String> {
        let listed = match self {
            Replaces::Manifest(listed) => read_own_text(&dir.join(MANIFEST_NAME))
                .map(|text| listed(&text))
                .unwrap_or_default(),
            Replaces::Recorded(record) => read_own_text(&dir.join(record))
                .map(|text| text.lines().filter(|l| !l.is_empty()).map(str::to_string).collect())
                .unwrap_or_default(),
            Replaces::Owned(owned) => fs::read_dir(dir)
                .into_iter()
                .flatten()
                .flatten()
                .filter_map(|e| e.file_name().to_str().map(str::to_string))
                .filter(|n| owned(n))
                .collect(),
        };
        let mut names: Vec<String> = listed
            .into_iter()
            .filter(|n| check_plain_name(n, dir).is_ok() && is_regular(&dir.join(n)))
            .collect();
        names.sort();
        names.dedup();
        names
    }
}

/// Whether `path` itself (not what a symlink there leads to) is a regular file.
pub(crate) fn is_regular(path: &Path) -> bool {
    fs::symlink_metadata(path).is_ok_and(|m| m.is_file())
}

/// The text of `path` when it is a regular file of at most [`MAX_LIST_BYTES`] in UTF-8: the
/// name is not followed if it is a symlink (`O_NOFOLLOW`), a FIFO is never opened (checked
/// first, and `O_NONBLOCK`), and the file opened must be the regular file checked.
fn read_own_text(path: &Path) -> Option<String> {
    let before = fs::symlink_metadata(path).ok()?;
    if !before.is_file() || before.len() > MAX_LIST_BYTES {
        return None;
    }
    let file = File::options()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
        .ok()?;
    let m = file.metadata().ok()?;
    if !m.is_file() || (m.dev(), m.ino()) != (before.dev(), before.ino()) {
        return None;
    }
    let mut text = String::new();
    file.take(MAX_LIST_BYTES + 1).read_to_string(&mut text).ok()?;
    (text.len() as u64 <= MAX_LIST_BYTES).then_some(text)
}

/// Removes a previous set's file: gone already is fine, anything but a regular file stays.
pub(crate) fn remove_own_file(path: &Path) -> io::Result<()> {
    match fs::symlink_metadata(path) {
        Ok(m) if m.is_file() => match fs::remove_file(path) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
            r => r,
        },
        Ok(_) => Ok(()),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::scratch_dir;

    fn names(text: &str) -> Vec<String> {
        text.split(',').map(str::to_string).collect()
    }

    #[test]
    fn only_a_regular_list_is_believed() {
        let dir = scratch_dir("replaces-list");
        for n in ["a.png", "b.png"] {
            fs::write(dir.join(n), "x").unwrap();
        }
        let elsewhere = scratch_dir("replaces-elsewhere").join("list");
        fs::write(&elsewhere, "a.png,b.png").unwrap();
        std::os::unix::fs::symlink(&elsewhere, dir.join(MANIFEST_NAME)).unwrap();
        let manifest = Replaces::Manifest(names);
        assert!(manifest.may_remove(&dir).is_empty(), "a symlinked manifest");
        fs::remove_file(dir.join(MANIFEST_NAME)).unwrap();
        fs::write(dir.join(MANIFEST_NAME), "b.png,../x,missing.png,a.png").unwrap();
        assert_eq!(manifest.may_remove(&dir), ["a.png", "b.png"]);
        let record = Replaces::recorded("t");
        std::os::unix::fs::symlink(&elsewhere, dir.join(".viewsynth.t.set")).unwrap();
        assert!(record.may_remove(&dir).is_empty(), "a symlinked record");
    }
}
