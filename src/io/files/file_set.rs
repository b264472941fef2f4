//! The output folder of a run and all-or-none sets of output files in it.
//!
//! [`OutDir`](super::out_dir::OutDir) is `--out-dir` made ready (created, resolved, probed) and the only way to reach
//! folders under it: [`OutDir::subdir`](super::out_dir::OutDir::subdir) refuses a subfolder that is a symlink or resolves
//! elsewhere, so outputs never land outside the real out-dir.
//!
//! [`FileSet`] stages every file of a set in a private folder `.viewsynth-<pid>-<random>/`
//! inside the destination and renames them all into place in [`FileSet::commit`], only once
//! every file was written. Until then the previous run's files stay untouched; on an error or
//! a drop without commit only the set's own staging folder is removed.
//!
//! The commit protocol survives a kill at any instruction:
//! 1. the staging folder is owned by an exclusive `flock` on `.viewsynth-lock` inside it,
//!    held until the set is done (a killed owner's lock is released by the kernel);
//! 2. every file is written and synced in the staging folder ([`FileSet::write_all`] encodes
//!    several side by side and syncs them on background threads; commit waits for every one of
//!    those syncs before step 3);
//! 3. a journal `.viewsynth-commit` listing the names in rename order (the manifest last) is
//!    written and synced: from here on the set is the new one;
//! 4. the files are renamed into place in that order, the manifest last;
//! 5. the folder is emptied in an order that keeps it recognisable: the journal, then the lock
//!    file, then the folder itself.
//!
//! A later run that finds an unlocked staging folder ([`remove_orphan_temporaries`](super::staging::remove_orphan_temporaries)) removes
//! it when it has no journal (killed before step 3: the old set is untouched) and otherwise
//! finishes step 4 (rolls forward to the new set). A folder with no lock file at all (killed
//! while it was being made or removed) is claimed by making its lock file, then treated the
//! same, at once: its maker, if alive, finds its lock file taken or gone and starts again in a
//! new folder (see `staging::claim_lock`), so no age threshold is needed. So after any kill and the
//! next run's start, a folder holds the old set or the new set, complete, and no temporary.
//! `VIEWSYNTH_FAULT_AFTER` injects a kill or a failure after any step (see [`super::atomic`]).
//!
//! ```no_run
//! # fn main() -> viewsynth::Result<()> {
//! use std::io::Write;
//! let out = viewsynth::io::OutDir::prepare("out".as_ref())?;
//! let mut set = out.file_set()?;
//! set.write("a.txt", |w| w.write_all(b"a").map_err(|e| viewsynth::Error::io("a.txt", e)))?;
//! set.write("b.txt", |w| w.write_all(b"b").map_err(|e| viewsynth::Error::io("b.txt", e)))?;
//! let written = set.commit()?; // both appear, or (on an error above) neither changes
//! # Ok(()) }
//! ```

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

mod parallel;
mod replaces;
pub use parallel::FileWriter;
pub(crate) use replaces::remove_own_file;
pub use replaces::{Replaces, MANIFEST_NAME};

use super::atomic::{check_plain_name, check_replaceable, fault_point};
use super::staging::{make_staging, remove_staging, roll_forward, sync_dir, Staging, JOURNAL_NAME, LOCK_NAME};
use crate::error::{Error, Result};

/// Files written all-or-none: staged privately, renamed into place by [`FileSet::commit`].
#[derive(Debug)]
pub struct FileSet {
    /// Destination folder (real path) and how to name it in messages.
    dir: PathBuf,
    shown: PathBuf,
    /// The staging folder's lock, held while this set lives (released before the folder is
    /// removed on drop: one descriptor more for the removal when they ran out).
    _lock: File,
    staging: Staging,
    /// Names written through [`FileSet::write`] and [`FileSet::write_all`], in order.
    written: Vec<String>,
    /// Names of [`FileSet::write`] not synced yet (synced at commit, all at once).
    unsynced: Vec<String>,
    /// The background syncs of [`FileSet::write_all`]'s files, joined at commit.
    syncing: Vec<std::thread::JoinHandle<Result<()>>>,
    /// Which of the previous run's files this set replaces ([`FileSet::replacing`]).
    replaces: Option<Replaces>,
}

impl FileSet {
    /// A set whose files go into `dir` (an existing folder) on commit. The staging folder is
    /// created inside `dir` (same file system, so the renames are atomic).
    pub fn new(dir: &Path) -> Result<Self> {
        let (staging, lock) = make_staging(dir)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            shown: dir.to_path_buf(),
            staging,
            _lock: lock,
            written: Vec::new(),
            unsynced: Vec::new(),
            syncing: Vec::new(),
            replaces: None,
        })
    }

    /// This set replaces the previous one of its command: at commit, in the same journalled
    /// commit as its renames, a file of the previous set (as [`Replaces`] finds it: listed by a
    /// regular file this program wrote, or for [`Replaces::Owned`] exactly named as the command
    /// names its files) that this set does not write is removed. A file the list does not name stays,
    /// whatever its name (the user's own files in the folder). With [`Replaces::Recorded`] the
    /// set's names are recorded in that hidden file (one name a line, renamed with the set, not
    /// among the paths [`FileSet::commit`] returns); a folder with no record (first run, or
    /// written by an older version) loses nothing.
    pub fn replacing(mut self, replaces: Replaces) -> Self {
        self.replaces = Some(replaces);
        self
    }

    pub(super) fn shown_as(mut self, shown: &Path) -> Self {
        self.shown = shown.to_path_buf();
        self
    }

    /// The private folder the set's files are staged in, for writers that take a path (e.g.
    /// `io::save_rgb(&set.staging().join("a.png"), ..)`): every regular file found there at
    /// commit is part of the set.
    pub fn staging(&self) -> &Path {
        self.staging.path()
    }

    /// Where `name` will be once committed (as the out-dir was given).
    pub fn final_path(&self, name: &str) -> PathBuf {
        self.shown.join(name)
    }

    /// `e` with a path inside the staging folder replaced by the final path, for errors of
    /// path-based savers that wrote into [`FileSet::staging`].
    pub fn final_error(&self, e: Error) -> Error {
        let fix = |p: PathBuf| match p.strip_prefix(self.staging.path()) {
            Ok(rest) => self.shown.join(rest),
            Err(_) => p,
        };
        match e {
            Error::Io { path, source } => Error::Io {
                path: fix(path),
                source,
            },
            Error::Decode { path, message } => Error::Decode {
                path: fix(path),
                message,
            },
            Error::Encode { path, message } => Error::Encode {
                path: fix(path),
                message,
            },
            other => other,
        }
    }

    /// Stages `name` (one plain file name) with the bytes `write` produces. Errors name the
    /// final path. Returns the final path.
    pub fn write(&mut self, name: &str, write: impl FnOnce(&mut BufWriter<File>) -> Result<()>) -> Result<PathBuf> {
        let shown = self.check_new_name(name)?;
        self.staging.names.push(name.to_string());
        let file = File::create_new(self.staging.path().join(name)).map_err(|e| Error::io(&shown, e))?;
        // Synced at commit, with the set's other files at once (see `sync_written`).
        write_file(file, &shown, write)?;
        self.written.push(name.to_string());
        self.unsynced.push(name.to_string());
        Ok(shown)
    }

    /// Names about to be created in the staging folder (removed by name if the set is dropped).
    fn note_staged(&mut self, names: impl IntoIterator<Item = String>) {
        self.staging.names.extend(names);
    }

    /// The final path of `name`, refused unless it is a plain name not yet written in this set.
    fn check_new_name(&self, name: &str) -> Result<PathBuf> {
        check_plain_name(name, &self.shown)?;
        let shown = self.final_path(name);
        if self.written.iter().any(|n| n == name) {
            return Err(twice(&shown));
        }
        Ok(shown)
    }

    /// Renames every staged file into the destination and returns the final paths: files put
    /// into [`FileSet::staging`] directly first (by name), then those of [`FileSet::write`] in
    /// the order written, and [`MANIFEST_NAME`] always last (it marks the set complete). Before
    /// the first rename every destination is checked to be absent, a regular file or a
    /// symlink (a folder, FIFO or device is never replaced), and the journal is written (see
    /// the module notes). Nothing is renamed if the staging folder holds anything but regular
    /// files. A rename that fails leaves the journalled staging folder for the next run to
    /// roll forward.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        let mut direct = Vec::new();
        let entries = fs::read_dir(self.staging.path()).map_err(|e| Error::io(&self.shown, e))?;
        for e in entries {
            let e = e.map_err(|e| Error::io(&self.shown, e))?;
            let name = e.file_name().to_str().map(str::to_string).ok_or_else(|| {
                Error::param(
                    "output name",
                    format!("non-UTF-8 name staged for {}", self.shown.display()),
                )
            })?;
            if name == LOCK_NAME {
                continue;
            }
            let regular = e.file_type().map(|t| t.is_file()).unwrap_or(false);
            if !regular {
                return Err(Error::io(
                    self.final_path(&name),
                    io::Error::new(io::ErrorKind::InvalidInput, "staged output is not a regular file"),
                ));
            }
            if !self.written.contains(&name) {
                check_plain_name(&name, &self.shown)?;
                direct.push(name);
            }
        }
        direct.sort();
        let mut order: Vec<String> = direct.into_iter().chain(self.written.iter().cloned()).collect();
        if let Some(i) = order.iter().position(|n| n == MANIFEST_NAME) {
            let manifest = order.remove(i);
            order.push(manifest);
        }
        let record = self.write_record(&mut order)?;
        for name in &order {
            check_replaceable(&self.dir.join(name)).map_err(|e| self.final_error_for(name, e))?;
        }
        let stale = self.stale(&order);
        self.sync_written()?;
        let FileSet {
            dir,
            shown,
            staging,
            _lock: lock,
            ..
        } = self;
        let final_path = |name: &str| shown.join(name);
        // Removals are journalled after the renames as `/name` ('/' is in no plain name).
        let journal = order
            .iter()
            .cloned()
            .chain(stale.iter().map(|n| format!("/{n}")))
            .collect::<Vec<_>>()
            .join("\n");
        let journal_path = staging.path().join(JOURNAL_NAME);
        let mut file = File::create_new(&journal_path).map_err(|e| Error::io(&shown, e))?;
        file.write_all(journal.as_bytes())
            .and_then(|()| file.sync_all())
            .map_err(|e| Error::io(&shown, e))?;
        sync_dir(staging.path());
        // From here on the set is the new one: a failure leaves the journalled folder (still
        // ours, unlocked once this process ends) for the next run to roll forward.
        let staging = staging.keep();
        let result = (|| -> Result<Vec<PathBuf>> {
            fault_point("journal written")?;
            let mut done = Vec::with_capacity(order.len());
            for name in &order {
                fs::rename(staging.join(name), dir.join(name)).map_err(|e| Error::io(final_path(name), e))?;
                fault_point("renamed")?;
                if record.as_ref() != Some(name) {
                    done.push(final_path(name));
                }
            }
            for name in &stale {
                remove_own_file(&dir.join(name)).map_err(|e| Error::io(final_path(name), e))?;
            }
            // Make the renames durable; failure to sync the folder is not worth failing the run.
            sync_dir(&dir);
            remove_staging(&staging).map_err(|e| Error::io(&shown, e))?;
            Ok(done)
        })();
        if result.is_err() {
            // Finish what can be finished now (a later run retries the rest).
            roll_forward(&dir, &staging);
        }
        drop(lock);
        result
    }

    /// Makes every written file durable before the journal names them: waits for the
    /// background syncs of [`FileSet::write_all`], and syncs the files of [`FileSet::write`]
    /// all at once, on up to 16 threads, so the device's flushes overlap (16 files of a VGA
    /// frame: ~8 ms here against ~50 one after another) at no extra CPU.
    fn sync_written(&mut self) -> Result<()> {
        for handle in self.syncing.drain(..) {
            handle.join().unwrap_or_else(|_| Err(sync_panicked(&self.shown)))?;
        }
        let sync = |name: &String| -> Result<()> {
            let path = self.staging.path().join(name);
            File::open(&path)
                .and_then(|f| f.sync_all())
                .map_err(|e| Error::io(self.final_path(name), e))
        };
        let per = self.unsynced.len().div_ceil(16).max(1);
        std::thread::scope(|scope| {
            let handles: Vec<_> = self
                .unsynced
                .chunks(per)
                .map(|names| scope.spawn(move || names.iter().try_for_each(sync)))
                .collect();
            handles
                .into_iter()
                .try_for_each(|h| h.join().unwrap_or_else(|_| Err(sync_panicked(&self.shown))))
        })
    }

    /// Stages the set's record ([`Replaces::Recorded`]): the names of `order`, which
    /// then renames it just before the manifest (if any). Returns its name.
    fn write_record(&mut self, order: &mut Vec<String>) -> Result<Option<String>> {
        let Some(Replaces::Recorded(record)) = &self.replaces else {
            return Ok(None);
        };
        let record = record.clone();
        let text: String = order.iter().map(|n| format!("{n}\n")).collect();
        self.write(&record, |w| {
            w.write_all(text.as_bytes()).map_err(|e| Error::io(&record, e))
        })?;
        let at = order.len() - usize::from(order.last().is_some_and(|n| n == MANIFEST_NAME));
        order.insert(at, record.clone());
        Ok(Some(record))
    }

    /// The files of the previous set (see [`FileSet::replacing`]) that `order` does not
    /// replace, sorted.
    fn stale(&self, order: &[String]) -> Vec<String> {
        let Some(replaces) = &self.replaces else {
            return Vec::new();
        };
        let mut stale = replaces.may_remove(&self.dir);
        stale.retain(|name| !order.contains(name));
        stale
    }

    fn final_error_for(&self, name: &str, e: Error) -> Error {
        match e {
            Error::Io { source, .. } => Error::io(self.final_path(name), source),
            other => other,
        }
    }
}

/// Writes `file` through a [`crate::io::files::atomic::WRITE_BUFFER`]-sized buffer with `write`, flushed;
/// errors name `shown`. Returns the file, not yet synced.
fn write_file(file: File, shown: &Path, write: impl FnOnce(&mut BufWriter<File>) -> Result<()>) -> Result<File> {
    let mut writer = BufWriter::with_capacity(crate::io::files::atomic::WRITE_BUFFER, file);
    write(&mut writer)?;
    writer.flush().map_err(|e| Error::io(shown, e))?;
    writer.into_inner().map_err(|e| Error::io(shown, e.into_error()))
}

fn twice(shown: &Path) -> Error {
    Error::param(
        "output name",
        format!("{} is written twice in one set", shown.display()),
    )
}

fn sync_panicked(dir: &Path) -> Error {
    Error::io(dir, io::Error::other("a thread syncing the set's files panicked"))
}

#[cfg(test)]
mod tests {
    use super::super::out_dir::OutDir;
    use super::super::staging::remove_orphan_temporaries;
    use super::*;
    use crate::io::test_util::{list_dir, scratch_dir};

    fn text(s: &'static str) -> impl FnOnce(&mut BufWriter<File>) -> Result<()> {
        move |w| w.write_all(s.as_bytes()).map_err(|e| Error::io("x", e))
    }

    #[test]
    fn all_files_appear_on_commit_only() {
        let root = scratch_dir("set-ok");
        let out = OutDir::prepare(&root.join("out")).unwrap();
        let mut set = out.file_set().unwrap();
        set.write("b.txt", text("b")).unwrap();
        fs::write(set.staging().join("a.txt"), "a").unwrap();
        set.write("manifest.json", text("{}")).unwrap();
        assert_eq!(
            list_dir(out.real_path()).len(),
            1,
            "only the staging folder before commit"
        );
        let done = set.commit().unwrap();
        let names: Vec<_> = done.iter().map(|p| p.file_name().unwrap().to_str().unwrap()).collect();
        assert_eq!(names, ["a.txt", "b.txt", "manifest.json"]);
        assert_eq!(list_dir(out.real_path()), ["a.txt", "b.txt", "manifest.json"]);
        assert!(done[0].starts_with(root.join("out")));
    }

    #[test]
    fn a_recorded_or_listed_set_replaces_only_the_previous_runs_files() {
        let dir = scratch_dir("set-record");
        fs::write(dir.join("right_notes.txt"), "the user's").unwrap();
        let run = |names: &[&'static str]| {
            let mut set = FileSet::new(&dir).unwrap().replacing(Replaces::recorded("test"));
            for &n in names {
                set.write(n, text("x")).unwrap();
            }
            set.commit().unwrap()
        };
        let done = run(&["left_rgb.png", "right_rgb.png", "right_depth.exr"]);
        // The record is renamed with the set but is not among the files the run reports.
        assert_eq!(done.len(), 3);
        assert_eq!(
            list_dir(&dir),
            [
                ".viewsynth.test.set",
                "left_rgb.png",
                "right_depth.exr",
                "right_notes.txt",
                "right_rgb.png"
            ]
        );
        // A file the user made after the first run, under a name the command could write.
        fs::write(dir.join("left_depth.exr"), "the user's").unwrap();
        // A failed rerun removes nothing.
        let mut set = FileSet::new(&dir).unwrap().replacing(Replaces::recorded("test"));
        set.write("left_rgb.png", text("y")).unwrap();
        drop(set);
        assert_eq!(list_dir(&dir).len(), 6);
        run(&["left_rgb.png"]);
        assert_eq!(
            list_dir(&dir),
            [
                ".viewsynth.test.set",
                "left_depth.exr",
                "left_rgb.png",
                "right_notes.txt"
            ]
        );
        assert_eq!(
            fs::read_to_string(dir.join(".viewsynth.test.set")).unwrap(),
            "left_rgb.png\n"
        );
        // A set its manifest lists: its names go, unless written again; others stay.
        fs::write(dir.join("manifest.json"), "left_rgb.png\n../x\ngone.png").unwrap();
        let lines = |text: &str| text.lines().map(str::to_string).collect();
        let mut set = FileSet::new(&dir).unwrap().replacing(Replaces::Manifest(lines));
        set.write("manifest.json", text("{}")).unwrap();
        set.commit().unwrap();
        assert_eq!(
            list_dir(&dir),
            [
                ".viewsynth.test.set",
                "left_depth.exr",
                "manifest.json",
                "right_notes.txt"
            ]
        );
    }

    #[test]
    fn failed_or_dropped_set_keeps_previous_files() {
        let dir = scratch_dir("set-fail");
        fs::write(dir.join("a.txt"), "old a").unwrap();
        fs::write(dir.join("b.txt"), "old b").unwrap();
        let mut set = FileSet::new(&dir).unwrap();
        set.write("a.txt", text("new a")).unwrap();
        let err = set.write("b.txt", |_| Err(Error::encode("b.txt", "boom"))).unwrap_err();
        assert!(err.to_string().contains("boom"));
        let e = set.final_error(Error::encode(set.staging().join("c.png"), "x"));
        assert_eq!(
            e.to_string(),
            format!("{}: cannot encode: x", dir.join("c.png").display())
        );
        drop(set);
        assert_eq!(fs::read_to_string(dir.join("a.txt")).unwrap(), "old a");
        assert_eq!(list_dir(&dir), ["a.txt", "b.txt"]);
    }

    #[test]
    fn commit_refuses_a_folder_in_the_way_before_renaming_anything() {
        let dir = scratch_dir("set-dir");
        fs::create_dir(dir.join("b.txt")).unwrap();
        let mut set = FileSet::new(&dir).unwrap();
        set.write("a.txt", text("a")).unwrap();
        set.write("b.txt", text("b")).unwrap();
        let err = set.commit().unwrap_err().to_string();
        assert!(err.contains("b.txt") && err.contains("folder"), "{err}");
        assert_eq!(list_dir(&dir), ["b.txt"]);
    }

    /// Folders a kill left without a lock file (while being made or removed) go at the next
    /// start, however young: empty, with staged files (the old set stays), or journalled
    /// (rolled forward to the new set).
    #[test]
    fn lockless_staging_folders_are_recovered_at_once() {
        let dir = scratch_dir("set-lockless");
        fs::write(dir.join("x.txt"), "old x").unwrap();
        let empty = dir.join(".viewsynth-1-empty");
        fs::create_dir(&empty).unwrap();
        let staged = dir.join(".viewsynth-1-staged");
        fs::create_dir(&staged).unwrap();
        fs::write(staged.join("y.txt"), "partial").unwrap();
        let journalled = dir.join(".viewsynth-1-journalled");
        fs::create_dir(&journalled).unwrap();
        fs::write(journalled.join("x.txt"), "new x").unwrap();
        fs::write(journalled.join(JOURNAL_NAME), "x.txt").unwrap();
        assert_eq!(remove_orphan_temporaries(&dir), 3);
        assert_eq!(list_dir(&dir), ["x.txt"]);
        assert_eq!(fs::read_to_string(dir.join("x.txt")).unwrap(), "new x");
    }

    /// Sets made and committed while a cleaner runs without pause: each is made again if the
    /// cleaner takes its folder before the lock, so every commit succeeds and nothing is left.
    #[test]
    fn sets_survive_a_cleaner_racing_them() {
        use std::sync::atomic::{AtomicBool, Ordering};
        let dir = scratch_dir("set-race");
        let stop = AtomicBool::new(false);
        std::thread::scope(|scope| {
            let cleaner = scope.spawn(|| {
                while !stop.load(Ordering::Relaxed) {
                    remove_orphan_temporaries(&dir);
                }
            });
            let makers: Vec<_> = (0..4)
                .map(|t| {
                    let dir = &dir;
                    scope.spawn(move || {
                        for i in 0..100 {
                            let mut set = FileSet::new(dir).unwrap();
                            let body = format!("{t}:{i}");
                            set.write(&format!("t{t}.txt"), |w| {
                                w.write_all(body.as_bytes()).map_err(|e| Error::io("x", e))
                            })
                            .unwrap();
                            set.commit().unwrap();
                            assert_eq!(fs::read_to_string(dir.join(format!("t{t}.txt"))).unwrap(), body);
                        }
                    })
                })
                .collect();
            let results: Vec<_> = makers.into_iter().map(|m| m.join()).collect();
            // Stopped before any panic below, or the scope would wait on the cleaner forever.
            stop.store(true, Ordering::Relaxed);
            cleaner.join().unwrap();
            assert!(results.iter().all(|r| r.is_ok()), "a maker failed");
        });
        assert_eq!(list_dir(&dir), ["t0.txt", "t1.txt", "t2.txt", "t3.txt"]);
    }

    #[test]
    fn names_must_be_plain() {
        let dir = scratch_dir("set-names");
        let mut set = FileSet::new(&dir).unwrap();
        for bad in ["../x", "a/b", "", ".", "..", "/abs", ".viewsynth-1-x"] {
            assert!(set.write(bad, text("x")).is_err(), "{bad}");
        }
        set.write("a", text("1")).unwrap();
        assert!(set.write("a", text("2")).unwrap_err().to_string().contains("twice"));
    }

    #[test]
    fn subdir_refuses_symlinks_and_files() {
        let root = scratch_dir("set-subdir");
        let elsewhere = root.join("elsewhere");
        fs::create_dir(&elsewhere).unwrap();
        let out = OutDir::prepare(&root.join("out")).unwrap();
        std::os::unix::fs::symlink(&elsewhere, out.real_path().join("frame")).unwrap();
        let err = out.subdir("frame").unwrap_err().to_string();
        assert!(err.contains("frame") && err.contains("symlink"), "{err}");
        fs::write(out.real_path().join("file"), "").unwrap();
        assert!(out.subdir("file").is_err());
        assert!(out.subdir("../elsewhere").is_err());
        let sub = out.subdir("ok").unwrap();
        sub.file_set().unwrap().commit().unwrap();
        assert!(list_dir(&elsewhere).is_empty());
        assert_eq!(list_dir(sub.real_path()), Vec::<String>::new());
    }

    #[test]
    fn prepare_follows_a_symlinked_root() {
        let root = scratch_dir("set-root-link");
        fs::create_dir(root.join("real")).unwrap();
        std::os::unix::fs::symlink(root.join("real"), root.join("link")).unwrap();
        let out = OutDir::prepare(&root.join("link")).unwrap();
        assert_eq!(out.path(), root.join("link"));
        assert_eq!(out.real_path(), fs::canonicalize(root.join("real")).unwrap());
    }
}
