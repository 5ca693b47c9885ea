//! gyro-core's integration tests in one test binary, a module per file of this folder:
//! the crate and its dependencies link once instead of once per file, and the tests of
//! every file run in parallel on the harness's threads (cargo runs test binaries one
//! after another). One file's tests: `cargo test -p gyro-core --test all block::`.
//!
//! `tests/no_alloc.rs` stays a test binary of its own: its counting `#[global_allocator]`
//! would be the allocator of every test in this one.
//!
//! proptest keeps the failing cases of these files in `../proptest-regressions/<file>.txt`,
//! not beside them: its default (`FileFailurePersistence::SourceParallel`) goes up to the
//! first folder with a `main.rs` (this one) and puts them in `proptest-regressions/` beside it.

mod common;

mod accuracy;
mod block;
mod compensation;
mod correction;
mod filter_golden;
mod filter_props;
mod motion_detection;
mod movement_indices;
mod output_bits;
mod pipeline_props;
mod saturation;
