//! Gyro logs: the shared CSV contract (DESIGN.md "Log formats"), read into rows, then put
//! on a regular time grid with every irregularity counted.

mod csv_log;
mod regular;

pub use csv_log::{read_csv, write_csv, ColumnOptions, RateUnit, TimeUnit};
pub use regular::{regularize, GridOptions, Quality, RegularLog, Slot};

use std::collections::BTreeMap;
use std::path::PathBuf;

/// One row of a log as recorded (units converted to s, deg/s, deg, °C).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// 1-based line number in the file.
    pub line: u64,
    /// Time stamp (s).
    pub time_s: f64,
    /// Angular rate (deg/s); `None` if the field is empty or NaN.
    pub rate_dps: Option<f64>,
    /// Reference (encoder) angle (deg), if the log has one and the field is present.
    pub reference_deg: Option<f64>,
    /// Sensor temperature (°C), if present.
    pub temperature_c: Option<f64>,
}

/// A log read into memory.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Log {
    /// Where it came from.
    pub path: PathBuf,
    /// `# key: value` metadata lines before the header.
    pub metadata: BTreeMap<String, String>,
    /// True if the log has a reference column.
    pub has_reference: bool,
    /// True if the log has a temperature column.
    pub has_temperature: bool,
    /// The rows in file order.
    pub rows: Vec<Row>,
}

impl Log {
    /// The `sample_rate_hz` metadata value, if present and a positive number.
    pub fn metadata_rate_hz(&self) -> Option<f64> {
        self.metadata
            .get("sample_rate_hz")
            .and_then(|v| v.trim().parse::<f64>().ok())
            .filter(|v| v.is_finite() && *v > 0.0)
    }
}

/// Why a log could not be read. Every variant names the file; row-level ones the line.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// The file could not be opened or read.
    #[error("{path}: {cause}")]
    Io {
        /// File.
        path: PathBuf,
        /// Cause (in the message, not chained: it would print twice).
        cause: std::io::Error,
    },
    /// The CSV structure is broken (e.g. a row with the wrong number of fields).
    #[error("{path}:{line}: {message}")]
    Csv {
        /// File.
        path: PathBuf,
        /// Line (1-based).
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// No header line.
    #[error("{path}: no header line (expected e.g. `time_s,rate_dps,reference_deg`)")]
    NoHeader {
        /// File.
        path: PathBuf,
    },
    /// A required column is missing.
    #[error("{path}:{line}: no column `{column}` in the header (columns: {available})")]
    MissingColumn {
        /// File.
        path: PathBuf,
        /// Header line.
        line: u64,
        /// The column looked for.
        column: String,
        /// The header's columns.
        available: String,
    },
    /// A field is not a number.
    #[error("{path}:{line}: column `{column}`: `{value}` is not a number")]
    NotANumber {
        /// File.
        path: PathBuf,
        /// Line.
        line: u64,
        /// Column name.
        column: String,
        /// The field as written.
        value: String,
    },
    /// A time stamp is missing or not finite.
    #[error("{path}:{line}: missing or non-finite time stamp in column `{column}`")]
    BadTime {
        /// File.
        path: PathBuf,
        /// Line.
        line: u64,
        /// Column name.
        column: String,
    },
    /// No data rows (or none with a usable rate).
    #[error("{path}: {what}")]
    NoData {
        /// File.
        path: PathBuf,
        /// What is missing.
        what: String,
    },
    /// The sample rate could not be determined or is invalid.
    #[error("{path}: {message}")]
    SampleRate {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Time runs backwards by more than the tolerated amount.
    #[error(
        "{path}:{line}: time goes back by {back_s:.6} s (from {previous_s:.6} s at line {previous_line} to {time_s:.6} s); concatenated or corrupt log?"
    )]
    TimeBackwards {
        /// File.
        path: PathBuf,
        /// Line.
        line: u64,
        /// Line of the previous kept row.
        previous_line: u64,
        /// Previous time (s).
        previous_s: f64,
        /// This row's time (s).
        time_s: f64,
        /// How far back (s).
        back_s: f64,
    },
    /// A gap in time longer than the longest one bridged by interpolation.
    #[error(
        "{path}:{line}: gap of {gap_s:.3} s in the data (after line {previous_line}) exceeds --max-gap-s {max_gap_s} s; the rotation during it cannot be recovered"
    )]
    Gap {
        /// File.
        path: PathBuf,
        /// Line after the gap.
        line: u64,
        /// Line before the gap.
        previous_line: u64,
        /// Gap length (s).
        gap_s: f64,
        /// The limit (s).
        max_gap_s: f64,
    },
}
