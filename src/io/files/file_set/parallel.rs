//! [`FileSet::write_all`]: several files of a set encoded side by side on the rayon pool (a
//! view's colour PNG, depth EXR and mask PNG, the EXR's blocks themselves split into tasks), then
//! synced on background threads, one a file, while the caller goes on to the next view.
//!
//! The commit protocol is unchanged: [`FileSet::commit`] waits for those syncs, and fails on
//! any of them, before its journal names the files (step 2 of the module notes); what moves is
//! only when the device's flush happens, overlapping the next view's encoding instead of
//! following the last one.

use std::fs::{self, File};
use std::io::BufWriter;
use std::path::PathBuf;

use super::{twice, write_file, FileSet};
use crate::error::{Error, Result};

/// Writes one file's bytes, on any thread: a job of [`FileSet::write_all`].
pub type FileWriter<'a> = Box<dyn FnOnce(&mut BufWriter<File>) -> Result<()> + Send + 'a>;

/// Background sync threads a set keeps before it waits for the oldest (bounds the threads and
/// open files of a set that writes many files).
const MAX_SYNCING: usize = 32;

impl FileSet {
    /// Stages every `(name, writer)` of `files` at once: the names are checked and the files
    /// created first (nothing is encoded when one is refused), then the writers run in parallel
    /// on the rayon pool. Names are recorded in the order given, as [`FileSet::write`] records
    /// them one call after another. Errors name the final path; a file whose writer failed is
    /// removed from the staging folder, so a commit never renames a partial file. Returns the
    /// final paths.
    pub fn write_all(&mut self, files: Vec<(String, FileWriter<'_>)>) -> Result<Vec<PathBuf>> {
        self.bound_syncing()?;
        let mut names = Vec::with_capacity(files.len());
        for (i, (name, _)) in files.iter().enumerate() {
            let shown = self.check_new_name(name)?;
            if files[..i].iter().any(|(n, _)| n == name) {
                return Err(twice(&shown));
            }
            names.push((name.clone(), shown));
        }
        let mut work = Vec::with_capacity(files.len());
        self.note_staged(names.iter().map(|(n, _)| n.clone()));
        for ((_, write), (name, shown)) in files.into_iter().zip(&names) {
            match File::create_new(self.staging().join(name)) {
                Ok(file) => work.push((file, write)),
                Err(e) => {
                    for (created, _) in &names[..work.len()] {
                        let _ = fs::remove_file(self.staging().join(created));
                    }
                    return Err(Error::io(shown, e));
                }
            }
        }
        let mut results: Vec<Option<Result<File>>> = names.iter().map(|_| None).collect();
        rayon_core::scope(|scope| {
            for ((file, write), (slot, (_, shown))) in work.into_iter().zip(results.iter_mut().zip(&names)) {
                scope.spawn(move |_| *slot = Some(write_file(file, shown, write)));
            }
        });
        let (mut first_error, mut done, mut to_sync) = (None, Vec::new(), Vec::new());
        for ((name, shown), result) in names.into_iter().zip(results) {
            let result = result.unwrap_or_else(|| Err(Error::io(&shown, std::io::Error::other("not written"))));
            match result {
                Ok(file) => {
                    self.written.push(name);
                    done.push(shown.clone());
                    to_sync.push((shown, file));
                }
                Err(e) => {
                    let _ = fs::remove_file(self.staging().join(&name));
                    first_error.get_or_insert(e);
                }
            }
        }
        let synced = self.sync_in_background(to_sync);
        first_error.map_or(synced.map(|()| done), Err)
    }

    /// Syncs each of `files` on a thread of its own, joined at commit (inline where no thread
    /// can be started): the device's flushes of a view's files overlap one another and the
    /// encoding of the next view.
    fn sync_in_background(&mut self, files: Vec<(PathBuf, File)>) -> Result<()> {
        for (shown, file) in files {
            // The file goes to the thread once it runs, so it is still here to sync if it cannot.
            let (tx, rx) = std::sync::mpsc::channel::<File>();
            let path = shown.clone();
            let spawned = std::thread::Builder::new()
                .name("viewsynth-sync".into())
                .spawn(move || rx.recv().map_or(Ok(()), |f| sync_file(&f, &path)));
            match spawned {
                Ok(handle) => {
                    self.syncing.push(handle);
                    tx.send(file).or_else(|unsent| sync_file(&unsent.0, &shown))?;
                }
                Err(_) => sync_file(&file, &shown)?,
            }
        }
        Ok(())
    }

    /// Waits for the oldest background syncs while more than [`MAX_SYNCING`] are running.
    fn bound_syncing(&mut self) -> Result<()> {
        while self.syncing.len() >= MAX_SYNCING {
            let oldest = self.syncing.remove(0);
            oldest
                .join()
                .unwrap_or_else(|_| Err(super::sync_panicked(&self.shown)))?;
        }
        Ok(())
    }
}

fn sync_file(file: &File, shown: &std::path::Path) -> Result<()> {
    file.sync_all().map_err(|e| Error::io(shown, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::{list_dir, scratch_dir};
    use std::io::Write;

    fn text(s: &'static str) -> FileWriter<'static> {
        Box::new(move |w: &mut BufWriter<File>| w.write_all(s.as_bytes()).map_err(|e| Error::io("x", e)))
    }

    #[test]
    fn files_written_together_commit_in_the_order_given() {
        let dir = scratch_dir("set-all");
        let mut set = FileSet::new(&dir).unwrap();
        set.write("first.txt", |w| w.write_all(b"1").map_err(|e| Error::io("x", e)))
            .unwrap();
        let jobs = vec![
            ("z.txt".to_string(), text("z")),
            ("a.txt".to_string(), text("a")),
            ("m.txt".to_string(), text("m")),
        ];
        let paths = set.write_all(jobs).unwrap();
        assert_eq!(paths, [dir.join("z.txt"), dir.join("a.txt"), dir.join("m.txt")]);
        let done = set.commit().unwrap();
        let names: Vec<_> = done.iter().map(|p| p.file_name().unwrap().to_str().unwrap()).collect();
        assert_eq!(names, ["first.txt", "z.txt", "a.txt", "m.txt"]);
        assert_eq!(fs::read_to_string(dir.join("a.txt")).unwrap(), "a");
        assert_eq!(fs::read_to_string(dir.join("z.txt")).unwrap(), "z");
    }

    #[test]
    fn a_failed_writer_leaves_no_partial_file_and_the_old_set_stays() {
        let dir = scratch_dir("set-all-fail");
        fs::write(dir.join("b.txt"), "old b").unwrap();
        let mut set = FileSet::new(&dir).unwrap();
        let failing: FileWriter = Box::new(|w: &mut BufWriter<File>| {
            w.write_all(b"half").map_err(|e| Error::io("b", e))?;
            Err(Error::encode("b.txt", "boom"))
        });
        let err = set
            .write_all(vec![("a.txt".to_string(), text("a")), ("b.txt".to_string(), failing)])
            .unwrap_err();
        assert!(err.to_string().contains("boom"), "{err}");
        assert_eq!(list_dir(set.staging()), [".viewsynth-lock", "a.txt"]);
        // The file that was written stays in the set; the failed one is not there to commit.
        set.commit().unwrap();
        assert_eq!(list_dir(&dir), ["a.txt", "b.txt"]);
        assert_eq!(fs::read_to_string(dir.join("b.txt")).unwrap(), "old b");
    }

    #[test]
    fn names_are_checked_before_anything_is_written() {
        let dir = scratch_dir("set-all-names");
        let mut set = FileSet::new(&dir).unwrap();
        set.write("a.txt", |w| w.write_all(b"1").map_err(|e| Error::io("x", e)))
            .unwrap();
        for bad in [
            vec![("b.txt".to_string(), text("b")), ("a.txt".to_string(), text("a"))],
            vec![("c.txt".to_string(), text("c")), ("c.txt".to_string(), text("c"))],
            vec![("d.txt".to_string(), text("d")), ("../e".to_string(), text("e"))],
        ] {
            assert!(set.write_all(bad).is_err());
        }
        assert_eq!(list_dir(set.staging()), [".viewsynth-lock", "a.txt"]);
        for i in 0..2 * MAX_SYNCING {
            set.write_all(vec![(format!("f{i}"), text("x"))]).unwrap();
            assert!(set.syncing.len() <= MAX_SYNCING);
        }
        assert_eq!(set.commit().unwrap().len(), 1 + 2 * MAX_SYNCING);
    }
}
