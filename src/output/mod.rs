//! The output layer: one synthesised view ([`ViewOutput`](crate::view::ViewOutput)), the
//! outputs asked for and their formats become files in a [`FileSet`](crate::io::FileSet)
//! (atomic, all or none) and the manifest entry naming them. Every command writes its views
//! through [`write_view`], so a format one command accepts is written the same way by all of
//! them (refocus single frame and batch, reproject, cyclopean, stitch, scene, and Python's
//! batch). It sits above the view type and the files layer (`crate::io`).
//!
//! - `sets.rs`: what a command writes, as data: which outputs ([`OutputSet`]), their formats
//!   ([`FileFormats`]), the names of a view's files ([`ViewNames`]) and the manifest entry
//!   ([`ViewFiles`], [`FileRecord`]);
//! - `paths.rs`: the one rule for every command's output paths, checked before any work
//!   ([`check_outputs`], [`check_out_dir`]);
//! - `write.rs`: [`write_view`].

mod paths;
mod sets;
mod write;

pub use paths::{check_out_dir, check_outputs, NamedPath};
pub use sets::{
    file_crc32, file_records, write_float_exrs, DepthFormats, FileFormats, FileRecord, OutputSet, RgbFormat, ViewFiles,
    ViewNames,
};
pub use write::write_view;
