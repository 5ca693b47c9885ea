//! Where the shared real recordings are, for the tests that read them: `../shared/data/real`
//! beside the workspace, or the folder `GYRO_REAL_DATA` names. A test whose recordings are
//! missing calls [`skipped`], which says so on the terminal even when the test passes
//! (the test harness captures `eprintln!` of passing tests; this writes past it), and
//! fails instead when `GYRO_REQUIRE_REAL_DATA=1`.

use std::io::Write;
use std::path::PathBuf;

/// The folder of the shared real recordings (it may not exist).
pub fn dir() -> PathBuf {
    std::env::var_os("GYRO_REAL_DATA").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/real"),
        PathBuf::from,
    )
}

/// `relative` (to [`dir`]) when it exists, else `None` after saying the running test is
/// skipped ([`skipped`]).
pub fn path(relative: &str) -> Option<PathBuf> {
    let path = dir().join(relative);
    if path.exists() {
        Some(path)
    } else {
        skipped(&path.display().to_string());
        None
    }
}

/// The CSV files in the folder `relative` (to [`dir`]), sorted; empty after saying the
/// running test is skipped ([`skipped`]) when there are none.
pub fn csv_files(relative: &str) -> Vec<PathBuf> {
    let folder = dir().join(relative);
    let mut found: Vec<PathBuf> = std::fs::read_dir(&folder)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "csv"))
                .collect()
        })
        .unwrap_or_default();
    found.sort();
    if found.is_empty() {
        skipped(&format!("CSV files in {}", folder.display()));
    }
    found
}

/// Say on the terminal that the running test (its thread's name, which the test harness
/// sets) is skipped because `missing` is not there; panics instead when the environment
/// variable `GYRO_REQUIRE_REAL_DATA` is `1`.
///
/// # Panics
/// When `GYRO_REQUIRE_REAL_DATA=1`: the recordings were required.
pub fn skipped(missing: &str) {
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("a test");
    let line = format!(
        "SKIPPED {test}: {missing} not found (the shared real recordings; set GYRO_REAL_DATA to their folder)"
    );
    assert!(
        std::env::var("GYRO_REQUIRE_REAL_DATA").as_deref() != Ok("1"),
        "{line}, and GYRO_REQUIRE_REAL_DATA=1"
    );
    // Written to the process's stderr, not through `eprintln!`, which a passing test's
    // harness swallows.
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}
