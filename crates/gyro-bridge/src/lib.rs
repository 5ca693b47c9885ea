//! The CRM100 serial bridge on the host: an [`emulator`] that plays samples as a bridge
//! would send them (with seeded faults), and [`record`](mod@record) that reads a bridge into an MCAP or
//! CSV log with every loss counted. Both sit on `crm100-driver`'s framing
//! ([`crm100_driver::bridge`]) and its host reader ([`crm100_driver::BridgeReader`]).
//!
//! ```
//! use gyro_bridge::{simulated_samples, stream, Emulator, EmulatorConfig, FaultSpec, Pacing};
//! use gyro_sim::SensorModel;
//! // Ten seconds of a simulated run as bridge frames with the typical faults, into a buffer
//! // (a serial port or a pseudo-terminal in `gyro-cli emulate`).
//! let samples = simulated_samples(&SensorModel::default(), 10.0, 3)?;
//! let config = EmulatorConfig {
//!     rate_hz: Some(1000.0),
//!     faults: FaultSpec::parse("typical,seed=7")?,
//!     ..EmulatorConfig::default()
//! };
//! let mut wire = Vec::new();
//! let report = stream(Emulator::new(samples.into_iter(), config), &mut wire, Pacing::AsFastAsPossible, None, None, None)?;
//! assert!(report.intact > 9_000 && !wire.is_empty());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod emulator;
pub mod record;

pub use emulator::{
    simulated_samples, stream, Emulator, EmulatorConfig, EmulatorReport, FaultSpec, FaultSpecError,
    Pacing, PlannedFrame, Sample, SensorFault, WireFault,
};
pub use record::{
    record, CsvSink, DecodedFrame, LiveStatus, McapSink, RecordEvent, RecordOptions, RecordSink,
    RecordStats, RecordSummary, StopReason, EVENTS_TOPIC, STATS_TOPIC,
};

use crm100_driver::Range;

/// Why a range ([`parse_range`]) was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RangeError {
    /// Not a whole number of °/s.
    #[error("`{text}` is not a range in °/s (75, 150, 300 or 900)")]
    NotANumber {
        /// The text as written.
        text: String,
    },
    /// A full scale the CRM100 does not have.
    #[error("no CRM100 range of ±{dps} °/s (75, 150, 300 or 900)")]
    NoSuchRange {
        /// The full scale asked for (°/s).
        dps: u16,
    },
}

/// The CRM100 range with this full scale (°/s): 75, 150, 300 or 900, optionally after `±`.
pub fn parse_range(text: &str) -> Result<Range, RangeError> {
    let dps: u16 = text
        .trim()
        .trim_start_matches('±')
        .parse()
        .map_err(|_| RangeError::NotANumber { text: text.into() })?;
    Range::ALL
        .into_iter()
        .find(|r| r.full_scale_dps() == dps)
        .ok_or(RangeError::NoSuchRange { dps })
}
