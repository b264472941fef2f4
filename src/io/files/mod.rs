//! Files written safely and read within limits: atomic saves, the output folder, all-or-none
//! sets of files with the commit protocol and recovery after a kill, and guarded opening of
//! inputs (regular files only, bounded lengths, the pixel budget).

pub(crate) mod atomic;
pub(crate) mod file_set;
pub(crate) mod input;
pub(crate) mod out_dir;
pub(crate) mod staging;
pub(crate) mod write_paths;
