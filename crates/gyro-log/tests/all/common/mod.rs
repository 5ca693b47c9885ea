//! Helpers shared by the integration tests: the workspace and temporary files.
#![allow(dead_code, clippy::unwrap_used)] // a failed unwrap fails the test

use std::path::{Path, PathBuf};

/// The workspace root (fixtures live there).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh folder for one test, named after it; removed with everything in it when the
/// returned guard is dropped, so that test runs leave nothing in the temporary folder.
pub fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gyro-log-test-{name}-"))
        .tempdir()
        .unwrap()
}

/// Longest error message the fuzz tests accept: a message quotes at most ~80 characters of
/// the offending field, plus the file and what was expected.
pub const MAX_ERROR_CHARS: usize = 400;

/// An error (or warning) message: not empty, one line, not longer than
/// [`MAX_ERROR_CHARS`] beyond the path, naming `path` if given.
pub fn assert_error(message: &str, path: Option<&Path>) {
    assert!(!message.trim().is_empty(), "empty message");
    assert!(
        !message.contains('\n'),
        "message on more than one line: {message:?}"
    );
    let path_len = path.map_or(0, |p| p.as_os_str().len());
    assert!(
        message.chars().count() <= MAX_ERROR_CHARS + path_len,
        "message of {} characters: {message:?}",
        message.chars().count()
    );
    if let Some(path) = path {
        assert!(
            message.contains(&*path.to_string_lossy()),
            "message does not name {}: {message:?}",
            path.display()
        );
    }
}

/// One change to a byte string; positions are taken modulo its length.
#[derive(Clone, Debug)]
pub enum ByteMutation {
    /// Flip one bit.
    Flip { at: usize, bit: u8 },
    /// Cut the file.
    Truncate { at: usize },
    /// Insert bytes.
    Insert { at: usize, bytes: Vec<u8> },
    /// Copy a stretch elsewhere.
    Duplicate { from: usize, len: usize, at: usize },
    /// Remove a stretch.
    Delete { from: usize, len: usize },
    /// Overwrite 8 bytes with a little-endian number (a length or a time in MCAP).
    Overwrite { at: usize, value: u64 },
}

impl ByteMutation {
    /// Apply the change.
    pub fn apply(&self, bytes: &mut Vec<u8>) {
        let n = bytes.len();
        if n == 0 {
            if let ByteMutation::Insert { bytes: new, .. } = self {
                bytes.extend_from_slice(new);
            }
            return;
        }
        match self {
            ByteMutation::Flip { at, bit } => bytes[at % n] ^= 1 << (bit % 8),
            ByteMutation::Truncate { at } => bytes.truncate(at % n),
            ByteMutation::Insert { at, bytes: new } => {
                let at = at % (n + 1);
                bytes.splice(at..at, new.iter().copied());
            }
            ByteMutation::Duplicate { from, len, at } => {
                let from = from % n;
                let piece = bytes[from..(from + len).min(n)].to_vec();
                let at = at % (n + 1);
                bytes.splice(at..at, piece);
            }
            ByteMutation::Delete { from, len } => {
                let from = from % n;
                bytes.drain(from..(from + len).min(n));
            }
            ByteMutation::Overwrite { at, value } => {
                let at = at % n;
                let end = (at + 8).min(n);
                bytes[at..end].copy_from_slice(&value.to_le_bytes()[..end - at]);
            }
        }
    }
}

/// Byte mutations, flips most often.
pub fn byte_mutation() -> impl proptest::strategy::Strategy<Value = ByteMutation> {
    use proptest::prelude::*;
    let value = prop_oneof![
        Just(0_u64),
        Just(u64::MAX),
        Just(u32::MAX as u64),
        Just(1_u64 << 40),
        any::<u64>(),
    ];
    prop_oneof![
        4 => (any::<usize>(), 0u8..8).prop_map(|(at, bit)| ByteMutation::Flip { at, bit }),
        1 => any::<usize>().prop_map(|at| ByteMutation::Truncate { at }),
        2 => (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..40))
            .prop_map(|(at, bytes)| ByteMutation::Insert { at, bytes }),
        2 => (any::<usize>(), 1usize..200, any::<usize>())
            .prop_map(|(from, len, at)| ByteMutation::Duplicate { from, len, at }),
        2 => (any::<usize>(), 1usize..200)
            .prop_map(|(from, len)| ByteMutation::Delete { from, len }),
        2 => (any::<usize>(), value).prop_map(|(at, value)| ByteMutation::Overwrite { at, value }),
    ]
}

/// Load `bytes` (written to `path`) with `options` and `grid`: no panic, a one-line error
/// naming the file, or a non-empty log of finite slots at a positive rate.
pub fn check_load(
    path: &Path,
    bytes: &[u8],
    options: &gyro_log::LogOptions,
    grid: &gyro_log::GridOptions,
) -> Result<(), proptest::test_runner::TestCaseError> {
    use proptest::prop_assert;
    std::fs::write(path, bytes).unwrap();
    let mut warn = |w: &str| assert_error(w, None);
    match gyro_log::load(path, options, grid, &mut warn) {
        Ok(log) => {
            prop_assert!(!log.slots.is_empty());
            prop_assert!(log.sample_rate_hz.is_finite() && log.sample_rate_hz > 0.0);
            for slot in &log.slots {
                prop_assert!(
                    slot.time_s.is_finite() && slot.rate_dps.is_finite(),
                    "{slot:?}"
                );
            }
        }
        Err(error) => assert_error(&error.to_string(), Some(path)),
    }
    Ok(())
}
