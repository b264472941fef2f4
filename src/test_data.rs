//! Where the unit tests find the real data: `VIEWSYNTH_DATA_DIR`, else `../shared/data` beside
//! the repository; missing, they fail saying how to fetch it.

use std::path::PathBuf;

pub(crate) fn dir() -> PathBuf {
    let dir = std::env::var_os("VIEWSYNTH_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data")));
    assert!(
        dir.is_dir(),
        "test data missing: {} (fetch it with `python3 ci/fetch-data.py`, or set VIEWSYNTH_DATA_DIR)",
        dir.display()
    );
    dir
}
