//! One way in for every command: read a log of either format, hand its warnings to the
//! caller, and put it on the regular grid ([`load`] whole, [`stream`] slot by slot).

use crate::{
    metadata_rate_hz, place, read_ahead, read_log_with_warnings, read_mcap, regularize, CsvRows,
    GridOptions, LogError, LogFormat, LogInfo, LogOptions, Quality, RegularLog, SlotSink,
};
use std::path::Path;

/// Read the log at `path` and place it on the grid. Warnings (MCAP damage that did not stop
/// reading) go to `warn`, one line each, before anything else is reported.
///
/// ```no_run
/// let regular = gyro_log::load(
///     "fixtures/logs/bench_run.csv".as_ref(),
///     &gyro_log::LogOptions::default(),
///     &gyro_log::GridOptions::default(),
///     &mut |warning| eprintln!("warning: {warning}"),
/// )?;
/// println!("{} samples at {} Hz", regular.slots.len(), regular.sample_rate_hz);
/// # Ok::<(), gyro_log::LogError>(())
/// ```
pub fn load(
    path: &Path,
    options: &LogOptions,
    grid: &GridOptions,
    warn: &mut dyn FnMut(&str),
) -> Result<RegularLog, LogError> {
    let (raw, warnings) = read_log_with_warnings(path, options)?;
    for warning in &warnings {
        warn(warning);
    }
    regularize(&raw, grid)
}

/// What [`load`] does, without holding the log: each slot goes to `sink` as soon as it is
/// final. A CSV log is parsed on a second thread and streamed row by row; an MCAP log is
/// read whole, then streamed from its rows. Returns what was irregular.
pub fn stream<S: SlotSink + ?Sized>(
    path: &Path,
    options: &LogOptions,
    grid: &GridOptions,
    sink: &mut S,
    warn: &mut dyn FnMut(&str),
) -> Result<Quality, LogError> {
    match LogFormat::detect(path) {
        LogFormat::Csv => {
            let rows = CsvRows::open(path, &options.columns)?;
            let info = LogInfo {
                path,
                metadata_rate_hz: metadata_rate_hz(rows.metadata()),
                has_reference: rows.has_reference(),
                has_temperature: rows.has_temperature(),
            };
            // Parsing on a second thread, the grid and the sink on this one.
            read_ahead(rows, |rows| place(&info, rows, grid, sink))
        }
        LogFormat::Mcap => {
            let read = read_mcap(path, &options.mcap)?;
            for warning in &read.warnings {
                warn(warning);
            }
            place(
                &LogInfo::of(&read.log),
                read.log.rows.iter().copied().map(Ok),
                grid,
                sink,
            )
        }
    }
}
