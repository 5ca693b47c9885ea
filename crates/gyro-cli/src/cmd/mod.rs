//! One module per `gyro-cli` subcommand: its arguments (`Args`) and `run`.

pub mod calibrate;
pub mod convert;
pub mod diagnose;
pub mod emulate;
pub mod noise;
pub mod record;
pub mod run;
pub mod simulate;

use anyhow::{Context, Result};
use gyro_log::{GridOptions, Log, LogOptions, RegularLog};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Print a warning about the input on stderr.
pub fn warn(warning: &str) {
    eprintln!("warning: {warning}");
}

/// Read a log, warnings printed ([`gyro_log::read_log_with_warnings`]).
pub fn read(path: &Path, options: &LogOptions) -> Result<Log> {
    let (log, warnings) = gyro_log::read_log_with_warnings(path, options)?;
    warnings.iter().for_each(|w| warn(w));
    Ok(log)
}

/// Read a log and place it on the grid, warnings printed ([`gyro_log::load`]).
pub fn load(path: &Path, options: &LogOptions, grid: &GridOptions) -> Result<RegularLog> {
    Ok(gyro_log::load(path, options, grid, &mut warn)?)
}

/// A flag set by SIGINT or SIGTERM, for loops that must finish their output cleanly
/// (signal-hook: an atomic store in the handler, no extra thread); a second signal while
/// the first is being handled exits at once with status 1.
pub fn stop_flag() -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(signal, 1, Arc::clone(&stop))
            .context("cannot install the signal handler")?;
        signal_hook::flag::register(signal, Arc::clone(&stop))
            .context("cannot install the signal handler")?;
    }
    Ok(stop)
}
