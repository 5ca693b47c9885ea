//! The CRM100 serial bridge on the host: an [`emulator`] that plays samples as a bridge
//! would send them (with seeded faults), and [`record`](mod@record) that reads a bridge into an MCAP or
//! CSV log with every loss counted. Both sit on `crm100-driver`'s framing
//! ([`crm100_driver::bridge`]) and its host reader ([`crm100_driver::BridgeReader`]).

pub mod emulator;
pub mod record;

pub use emulator::{
    simulated_samples, stream, Emulator, EmulatorConfig, EmulatorReport, FaultSpec, Pacing,
    PlannedFrame, Sample, SensorFault, WireFault,
};
pub use record::{
    record, CsvSink, DecodedFrame, LiveStatus, McapSink, RecordEvent, RecordOptions, RecordSink,
    RecordStats, RecordSummary, StopReason, EVENTS_TOPIC, STATS_TOPIC,
};

use crm100_driver::Range;

/// The range with this full scale (°/s): 75, 150, 300 or 900; for `--range`.
pub fn parse_range(text: &str) -> Result<Range, String> {
    let dps: u16 = text
        .trim()
        .trim_start_matches('±')
        .parse()
        .map_err(|_| format!("`{text}` is not a range in °/s (75, 150, 300 or 900)"))?;
    Range::ALL
        .into_iter()
        .find(|r| r.full_scale_dps() == dps)
        .ok_or_else(|| format!("no CRM100 range of ±{dps} °/s (75, 150, 300 or 900)"))
}
