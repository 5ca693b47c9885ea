//! Logs for the unit tests: a regular grid of gyro and reference samples, as a reader
//! makes of a clean log.

use gyro_log::{Quality, RegularLog, Slot};

/// A regular log at `fs` Hz of `(time_s, rate_dps, reference_deg)` samples: every slot
/// read from the log (none filled), no temperature, a clean input report.
pub fn with_reference(fs: f64, samples: impl IntoIterator<Item = (f64, f64, f64)>) -> RegularLog {
    let slots = samples
        .into_iter()
        .enumerate()
        .map(|(i, (time_s, rate_dps, reference_deg))| Slot {
            time_s,
            rate_dps,
            reference_deg: Some(reference_deg),
            temperature_c: None,
            line: i as u64 + 2,
            filled: false,
        })
        .collect();
    RegularLog {
        slots,
        sample_rate_hz: fs,
        has_reference: true,
        has_temperature: false,
        quality: Quality::default(),
    }
}
