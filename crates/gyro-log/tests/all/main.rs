//! gyro-log's integration tests in one test binary, a module per file of this folder:
//! the crate and its dependencies link once instead of once per file, and the tests of
//! every file run in parallel on the harness's threads (cargo runs test binaries one
//! after another). One file's tests: `cargo test -p gyro-log --test all rasteiro::`.

mod common;

mod fuzz_csv;
mod fuzz_mcap;
mod mcap_compression;
mod mcap_log;
mod mcap_stream;
mod rasteiro;
