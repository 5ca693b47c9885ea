//! MCAP logs (docs/log-formats.md, "MCAP"): the samples as ROS 2 messages in CDR, which
//! Foxglove plots, written incrementally in small zstd (or lz4, or uncompressed) chunks,
//! read chunk by chunk in constant memory; earlier files with JSON samples, and ROS 2 bags
//! (`sensor_msgs/msg/Imu` in CDR), are read too.
//!
//! # Layout written
//!
//! | channel | schema | message |
//! |---|---|---|
//! | `/gyro` | `gyro_msgs/msg/Sample` (`ros2msg`) | CDR: `float64 rate_dps`, `float64 temperature_c`, `int64 status` |
//! | `/reference` | `gyro_msgs/msg/Reference` (`ros2msg`) | CDR: `float64 angle_deg` |
//! | `/crm100/raw` (from `record`) | `gyro.RawFrame` (`jsonschema`) | JSON `{"hex": "..."}` or any JSON object |
//!
//! A message's `log_time` and `publish_time` are both the sample time in ns. NaN marks a
//! missing value (an empty CSV field), −1 an unknown status; `/gyro`'s channel metadata
//! `has_temperature` says whether the log has a temperature column. The log's
//! `# key: value` metadata is one MCAP metadata record named `gyro`.
//!
//! Chunks are compressed as [`McapCompression`] says (zstd unless asked otherwise) and
//! closed every 0.5 s of log time (see [`McapWriteOptions`]), with message indexes
//! (Foxglove's indexed reader needs them; uncompressed, they are most of a zstd file:
//! 32 bytes per 1 kHz sample with a reference, 115 MB per hour, against 126 MB of CSV).
//!
//! Times are whole nanoseconds (u64): a CSV time with up to 9 decimals survives the trip
//! exactly; values are f64 and come back bit for bit.

mod attach;
mod binary;
mod json;
mod layout;
mod lz4;
mod read;
mod ros2;
mod unit;
mod write;

pub use binary::{
    decode_reference, decode_sample, encode_reference, encode_sample, GyroSample,
    HAS_TEMPERATURE_KEY, REFERENCE_LEN, REFERENCE_SCHEMA_NAME, SAMPLE_LEN, SAMPLE_SCHEMA_NAME,
};
pub use read::{read_mcap, McapOptions, McapRead, McapRows, REFERENCE_MAX_SPAN_S, TIME_ORIGIN_KEY};
pub use ros2::{Axis, TimeSource, IMU_SCHEMA_NAME};
pub use write::{
    write_mcap, write_mcap_with, JsonChannel, McapCompression, McapLogWriter, McapWriteOptions,
};

/// Channel of the gyro samples.
pub const GYRO_TOPIC: &str = "/gyro";
/// Channel of the reference (encoder) angle.
pub const REFERENCE_TOPIC: &str = "/reference";
/// Channel of raw sensor frames written by `record`.
pub const RAW_TOPIC: &str = "/crm100/raw";
/// Name of the metadata record holding the log's `key: value` metadata.
pub const METADATA_NAME: &str = "gyro";
/// The 8 bytes every MCAP file starts and ends with.
pub const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Largest time (s) an MCAP log time (u64 ns) holds, with margin: about 584 years.
const MAX_TIME_S: f64 = 1.8e10;

/// Time (s) to whole nanoseconds, rounded; `None` if negative, not finite or too large.
///
/// Whole seconds and the fraction are converted separately, so the result is within half a
/// nanosecond of `time_s` even for epoch-scale times, and [`ns_to_seconds`] gives back the
/// same `f64` whenever `time_s` has at most 9 decimals.
pub fn seconds_to_ns(time_s: f64) -> Option<u64> {
    if !(time_s.is_finite() && (0.0..MAX_TIME_S).contains(&time_s)) {
        return None;
    }
    let whole = time_s.floor();
    let frac_ns = ((time_s - whole) * 1e9).round() as u64;
    Some(whole as u64 * 1_000_000_000 + frac_ns)
}

/// Nanoseconds to seconds: the `f64` nearest to `ns / 1e9`, so a time printed with up to
/// 9 decimals and converted with [`seconds_to_ns`] comes back bit for bit.
pub fn ns_to_seconds(ns: u64) -> f64 {
    const EXACT_LIMIT: u64 = 1 << 53; // below this, `ns as f64` is exact (about 104 days)
    if ns < EXACT_LIMIT {
        // One correctly rounded division of two exact values.
        ns as f64 / 1e9
    } else {
        // Epoch-scale: let the (correctly rounding) decimal parser do it.
        let text = format!("{}.{:09}", ns / 1_000_000_000, ns % 1_000_000_000);
        text.parse().unwrap_or(f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_conversion_round_trips_printed_times() {
        for text in [
            "0",
            "0.001",
            "0.123456",
            "12345.678901",
            "3599.999",
            "1700000000.123456789",
        ] {
            let t: f64 = text.parse().unwrap();
            let ns = seconds_to_ns(t).unwrap();
            assert_eq!(ns_to_seconds(ns), t, "{text}");
        }
        for i in 0..3_600_000_u64 {
            let t = i as f64 / 1000.0;
            assert_eq!(ns_to_seconds(seconds_to_ns(t).unwrap()), t, "{i}");
        }
        assert_eq!(seconds_to_ns(-1e-9), None);
        assert_eq!(seconds_to_ns(f64::NAN), None);
        assert_eq!(seconds_to_ns(1e300), None);
        assert_eq!(seconds_to_ns(1.5), Some(1_500_000_000));
    }
}
