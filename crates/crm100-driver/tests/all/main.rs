//! crm100-driver's integration tests in one test binary, a module per file of this folder:
//! the crate and its dependencies link once instead of once per file, and the tests of
//! every file run in parallel on the harness's threads (cargo runs test binaries one
//! after another). One file's tests: `cargo test -p crm100-driver --test all bridge::`.

mod common;

mod bridge;
mod driver;
mod frame;
#[cfg(feature = "std")]
mod fuzz_bridge;
#[cfg(feature = "std")]
mod reader;
#[cfg(all(feature = "serial", unix))]
mod serial;
