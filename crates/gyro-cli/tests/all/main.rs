//! gyro-cli's integration tests in one test binary, a module per file of this folder:
//! the crate and its dependencies link once instead of once per file, and the tests of
//! every file run in parallel on the harness's threads (cargo runs test binaries one
//! after another). One file's tests: `cargo test -p gyro-cli --test all cli_run::`.

mod common;

mod bad_input_cli;
mod calibrate_cli;
mod cli_run;
mod compression_cli;
mod decision_cli;
mod diagnose_cli;
mod diagnose_report;
mod doc_links;
mod findings_cli;
mod mcap_cli;
mod model_correction;
mod noise_cli;
mod noise_yaml_cli;
mod offline_cli;
mod overwrite_cli;
mod plots;
#[cfg(unix)]
mod record_cli;
mod saturation_cli;
mod streaming;
mod unix_behaviour;
