//! Analysis of gyro logs: replay through exactly the `gyro-core` pipeline the firmware runs,
//! the model file, noise characterisation and calibration on bench runs. The sim-to-real
//! diagnosis builds on it in `gyro-diagnose`.
//!
//! ```no_run
//! use gyro_analysis::replay;
//! let raw = gyro_log::read_csv("fixtures/logs/bench_run.csv".as_ref(), &gyro_log::ColumnOptions::default())?;
//! let regular = gyro_log::regularize(&raw, &gyro_log::GridOptions::default())?;
//! let report = replay::replay(&regular, &gyro_core::Config::default())?;
//! println!("max abs error: {:?} deg", report.summary.max_abs_error_deg);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod bias_path;
pub mod calibrate;
pub mod findings;
mod golden;
pub mod lag;
pub mod model;
pub mod noise;
pub mod replay;
pub mod rest_mean;
pub mod seed;
pub mod xcorr;

/// The median of `values` as the upper of the two middle values for an even count (an
/// observed value, never an average of two); `None` when empty. Callers drop what they
/// do not want counted (NaN sorts last).
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied()
}
