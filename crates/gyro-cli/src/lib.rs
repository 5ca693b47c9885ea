//! Host side of gyro: read logs, put them on a regular grid, replay them through exactly
//! the `gyro-core` pipeline the firmware runs, and report.
//!
//! ```no_run
//! use gyro_host::{log, replay};
//! let raw = log::read_csv("fixtures/logs/bench_run.csv".as_ref(), &log::ColumnOptions::default())?;
//! let regular = log::regularize(&raw, &log::GridOptions::default())?;
//! let report = replay::replay(&regular, &gyro_core::Config::default())?;
//! println!("max abs error: {:?} deg", report.summary.max_abs_error_deg);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod bridge;
pub mod calibrate;
pub mod diagnose;
pub mod log;
pub mod model;
pub mod nelder_mead;
pub mod noise;
pub mod plot;
pub mod replay;
pub mod report;
pub mod sim;
