//! One way in for every command: read a log of either format, hand its warnings to the
//! caller, and put it on the regular grid ([`load`] whole, [`stream`] slot by slot).

use crate::{
    metadata_rate_hz, place, read_ahead, CsvRows, GridOptions, LogError, LogFormat, LogInfo,
    LogOptions, McapRows, Quality, RegularLog, Slot, SlotSink, MAX_HELD_SLOTS,
};
use std::path::Path;

/// Read the log at `path` and place it on the grid (through [`stream`], so its rows are
/// never all held). Warnings go to `warn`, one line each, before the log is returned. A
/// grid of more than [`MAX_HELD_SLOTS`] slots is refused with the number it would need.
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
    let mut collect = Collect::default();
    let quality = stream(path, options, grid, &mut collect, warn)?;
    if collect.over_limit {
        return Err(LogError::TooLarge {
            path: path.to_path_buf(),
            what: format!(
                "the log on the grid at {} Hz, held whole, would need",
                crate::hz(quality.sample_rate_hz)
            ),
            samples: quality.slots as f64,
            limit: MAX_HELD_SLOTS,
        });
    }
    Ok(RegularLog {
        slots: collect.slots,
        sample_rate_hz: quality.sample_rate_hz,
        has_reference: collect.has_reference,
        has_temperature: collect.has_temperature,
        quality,
    })
}

/// The slots of a log, kept, up to [`MAX_HELD_SLOTS`]: beyond, they are dropped (and the
/// rest only counted), so that the error can say how many the log needs.
#[derive(Default)]
struct Collect {
    slots: Vec<Slot>,
    over_limit: bool,
    has_reference: bool,
    has_temperature: bool,
}

impl SlotSink for Collect {
    fn columns(&mut self, has_reference: bool, has_temperature: bool) {
        self.has_reference = has_reference;
        self.has_temperature = has_temperature;
    }
    fn start(&mut self, _sample_rate_hz: f64) {}
    fn slot(&mut self, slot: &Slot) {
        if self.over_limit {
            return;
        }
        if self.slots.len() as u64 >= MAX_HELD_SLOTS {
            self.over_limit = true;
            self.slots = Vec::new();
            return;
        }
        self.slots.push(*slot);
    }
}

/// What [`load`] does, without holding the log: each slot goes to `sink` as soon as it is
/// final. Either format is read on a second thread (CSV row by row, MCAP chunk by chunk)
/// while this one places the rows. Warnings (MCAP damage read around, a given rate a
/// little off the stamps') go to `warn` once the rows are read. Returns what was irregular.
pub fn stream<S: SlotSink + ?Sized>(
    path: &Path,
    options: &LogOptions,
    grid: &GridOptions,
    sink: &mut S,
    warn: &mut dyn FnMut(&str),
) -> Result<Quality, LogError> {
    match options.format_of(path)? {
        LogFormat::Csv => {
            let rows = CsvRows::open(path, &options.columns)?;
            let info = LogInfo {
                path,
                metadata_rate_hz: metadata_rate_hz(rows.metadata()),
                has_reference: rows.has_reference(),
                has_temperature: rows.has_temperature(),
            };
            // Parsing on a second thread, the grid and the sink on this one.
            let quality = read_ahead(rows, |rows| place(&info, rows, grid, sink))?;
            quality.warnings.iter().for_each(|w| warn(w));
            Ok(quality)
        }
        LogFormat::Mcap => {
            let mut rows = McapRows::open(path, &options.mcap)?;
            // The columns are decided by the rows placing holds back anyway.
            rows.prime();
            let info = LogInfo {
                path,
                metadata_rate_hz: rows.metadata_rate_hz(),
                has_reference: rows.has_reference(),
                has_temperature: rows.has_temperature(),
            };
            let placed = read_ahead(&mut rows, |rows| place(&info, rows, grid, sink));
            for warning in rows.warnings() {
                warn(&warning);
            }
            let quality = placed?;
            quality.warnings.iter().for_each(|w| warn(w));
            Ok(quality)
        }
    }
}
