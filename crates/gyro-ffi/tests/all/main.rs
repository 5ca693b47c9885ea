//! gyro-ffi's integration tests in one test binary, a module per file of this folder:
//! the crate and its dependencies link once instead of once per file, and the tests of
//! every file run in parallel on the harness's threads (cargo runs test binaries one
//! after another). One file's tests: `cargo test -p gyro-ffi --test all header::`.

mod c_api;
mod header;
