//! Renderers of gyro's results: the text, JSON and CSV of `run` ([`run`]), the input-quality
//! report every command shows ([`input`]), the noise table ([`noise`]), the calibration table ([`calibrate`]), the diagnosis report in HTML ([`diagnose`]) and every plot ([`plot`]).
//! Renderers take what the analysis computed and lay it out.
//!
//! ```
//! let log = gyro_log::load(
//!     "../../fixtures/logs/bench_run.csv".as_ref(),
//!     &gyro_log::LogOptions::default(),
//!     &gyro_log::GridOptions::default(),
//!     &mut |_| {},
//! )?;
//! let report = gyro_analysis::replay::replay(&log, &gyro_core::Config::default())?;
//! let findings = gyro_analysis::findings::of_run(&report, &[]);
//! let text = gyro_report::run::table("bench_run.csv", &report, &findings);
//! assert!(text.contains("bench_run.csv"));
//! let json = gyro_report::run::json("bench_run.csv", &report, &findings)?;
//! assert!(json.contains("max_abs_error_deg"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod calibrate;
pub mod diagnose;
pub mod input;
pub mod noise;
pub mod plot;
pub mod run;
