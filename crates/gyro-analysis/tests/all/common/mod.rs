//! The real recordings (../shared/data/real beside the workspace): loaded when present,
//! skipped with a note when not.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_log::{load, GridOptions, LogOptions, RegularLog};

/// `relative` (to ../shared/data/real) placed on the grid `grid` says, or `None` (and a
/// note) when the recordings are not beside the workspace.
pub fn real_log(relative: &str, grid: &GridOptions) -> Option<RegularLog> {
    let path = gyro_log::real_data::path(relative)?;
    Some(load(&path, &LogOptions::default(), grid, &mut |_| {}).unwrap())
}
