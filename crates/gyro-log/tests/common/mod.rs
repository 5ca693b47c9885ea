//! Helpers shared by the integration tests: the workspace and temporary files.
#![allow(dead_code, clippy::unwrap_used)] // a failed unwrap fails the test

use std::path::{Path, PathBuf};

/// The workspace root (fixtures live there).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh folder for one test (each test binary is its own process: the pid separates them).
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gyro-log-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
