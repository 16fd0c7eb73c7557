//! Shared helpers of the integration tests.

use std::path::PathBuf;

/// The real scans of `../shared/data` (see its SOURCES.md): beside the
/// repository, or where `MESHTRIM_SHARED_DATA` points, or at the workplace's
/// `/work/shared/data` when the repository is a clone elsewhere. The data is
/// part of the test set, so not finding it is a failure, not a skip.
pub fn shared_data(rel: &str) -> PathBuf {
    let beside = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"));
    let candidates: Vec<PathBuf> = std::env::var_os("MESHTRIM_SHARED_DATA")
        .map(PathBuf::from)
        .into_iter()
        .chain([beside, PathBuf::from("/work/shared/data")])
        .collect();
    let root = candidates.iter().find(|c| c.is_dir()).unwrap_or_else(|| {
        panic!("the real test data is missing: looked in {candidates:?} (set MESHTRIM_SHARED_DATA)")
    });
    root.join(rel)
}
