//! gyro-analysis's integration tests in one test binary, a module per file of this folder:
//! the crate and its dependencies link once instead of once per file, and the tests of
//! every file run in parallel on the harness's threads (cargo runs test binaries one
//! after another). One file's tests: `cargo test -p gyro-analysis --test all calibrate::`.

mod common;

mod bench_kinds;
mod calibrate;
mod calibrate_real;
mod fuzz_model;
mod lag_real;
mod noise_reference;
mod noise_sim;
mod offline;
mod rasteiro_turns;
mod replay_memory;
mod rest_mean;
mod saturation_sim;
mod sim_effects;
