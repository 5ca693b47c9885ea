//! The `/gyro` and `/reference` messages as written: ROS 2 message definitions (schema
//! encoding `ros2msg`) in CDR (message encoding `cdr`), fixed size, little-endian. Foxglove
//! plots their fields as it does any ROS 2 message; the reader decodes them with a few
//! loads, no text to parse. A missing value is NaN; an unknown status is −1.

/// Schema name of `/gyro` messages.
pub const SAMPLE_SCHEMA_NAME: &str = "gyro_msgs/msg/Sample";
/// Schema name of `/reference` messages.
pub const REFERENCE_SCHEMA_NAME: &str = "gyro_msgs/msg/Reference";
/// The schema encoding of both.
pub(super) const SCHEMA_ENCODING: &str = "ros2msg";
/// The message encoding of both.
pub(super) const MESSAGE_ENCODING: &str = "cdr";

/// Channel metadata key on `/gyro`: `"true"` if the log has a temperature column.
pub const HAS_TEMPERATURE_KEY: &str = "has_temperature";

/// The `/gyro` message definition.
pub(super) const SAMPLE_DEFINITION: &str = "\
# One gyro sample; the message's log_time is the sample time (ns). NaN: missing.
float64 rate_dps       # angular rate (deg/s)
float64 temperature_c  # sensor temperature (degC)
int64 status           # raw sensor status word; -1: unknown
";

/// The `/reference` message definition.
pub(super) const REFERENCE_DEFINITION: &str = "\
# Reference (encoder) angle; the message's log_time is the sample time (ns).
float64 angle_deg      # reference angle (deg); NaN: missing
";

/// The definition written for schema `name` (the sample's for any name but the
/// reference's).
pub(super) fn definition(name: &str) -> &'static str {
    if name == REFERENCE_SCHEMA_NAME {
        REFERENCE_DEFINITION
    } else {
        SAMPLE_DEFINITION
    }
}

/// The fields a `ros2msg` definition declares, `type name` each, in order: comments,
/// blank lines and constants (`type NAME=value`) left out, up to the `===` line before
/// any nested definition.
pub(super) fn declared_fields(definition: &str) -> Vec<String> {
    definition
        .lines()
        .take_while(|line| !line.starts_with("==="))
        .map(|line| line.split('#').next().unwrap_or_default())
        .filter(|line| !line.contains('='))
        .map(|line| line.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|line| !line.is_empty())
        .collect()
}

/// CDR encapsulation header, little-endian (what is written).
const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];
/// Bytes of a `/gyro` message: the header and three 8-byte fields.
pub const SAMPLE_LEN: usize = 4 + 3 * 8;
/// Bytes of a `/reference` message: the header and one 8-byte field.
pub const REFERENCE_LEN: usize = 4 + 8;

/// A decoded `/gyro` message (non-finite values are `None`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroSample {
    /// Angular rate (deg/s).
    pub rate_dps: Option<f64>,
    /// Sensor temperature (°C).
    pub temperature_c: Option<f64>,
    /// Raw sensor status word (written by `record`).
    pub status: Option<u32>,
}

/// Encode a `/gyro` message (`None` or non-finite: NaN; no status: −1).
pub fn encode_sample(sample: &GyroSample) -> [u8; SAMPLE_LEN] {
    let mut out = [0_u8; SAMPLE_LEN];
    out[..4].copy_from_slice(&CDR_LE);
    out[4..12].copy_from_slice(&value(sample.rate_dps).to_le_bytes());
    out[12..20].copy_from_slice(&value(sample.temperature_c).to_le_bytes());
    let status = sample.status.map_or(-1, i64::from);
    out[20..28].copy_from_slice(&status.to_le_bytes());
    out
}

/// Encode a `/reference` message.
pub fn encode_reference(angle_deg: Option<f64>) -> [u8; REFERENCE_LEN] {
    let mut out = [0_u8; REFERENCE_LEN];
    out[..4].copy_from_slice(&CDR_LE);
    out[4..12].copy_from_slice(&value(angle_deg).to_le_bytes());
    out
}

/// Decode a `/gyro` message (either byte order; bytes after the fields are ignored, as CDR
/// readers do).
pub fn decode_sample(data: &[u8]) -> Result<GyroSample, String> {
    let little = byte_order(data, SAMPLE_LEN, SAMPLE_SCHEMA_NAME)?;
    let status = i64_at(data, 20, little);
    let status = match status {
        -1 => None,
        s => Some(u32::try_from(s).map_err(|_| format!("status {s} is not a u32 or -1"))?),
    };
    Ok(GyroSample {
        rate_dps: finite(f64_at(data, 4, little)),
        temperature_c: finite(f64_at(data, 12, little)),
        status,
    })
}

/// Decode a `/reference` message.
pub fn decode_reference(data: &[u8]) -> Result<Option<f64>, String> {
    let little = byte_order(data, REFERENCE_LEN, REFERENCE_SCHEMA_NAME)?;
    Ok(finite(f64_at(data, 4, little)))
}

fn value(x: Option<f64>) -> f64 {
    x.filter(|x| x.is_finite()).unwrap_or(f64::NAN)
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// True for little-endian CDR; an error if `data` is shorter than `len` or not plain CDR.
fn byte_order(data: &[u8], len: usize, name: &str) -> Result<bool, String> {
    if data.len() < len {
        return Err(format!(
            "{} bytes, a {name} message in CDR has {len}",
            data.len()
        ));
    }
    match [data[0], data[1]] {
        [0, 1] => Ok(true),
        [0, 0] => Ok(false),
        [a, b] => Err(format!(
            "CDR encapsulation {a:#04x}{b:02x} (only plain CDR, 0x0000 or 0x0001, is read)"
        )),
    }
}

fn bytes8(data: &[u8], at: usize) -> [u8; 8] {
    let mut b = [0_u8; 8];
    b.copy_from_slice(&data[at..at + 8]);
    b
}

fn f64_at(data: &[u8], at: usize, little: bool) -> f64 {
    let b = bytes8(data, at);
    if little {
        f64::from_le_bytes(b)
    } else {
        f64::from_be_bytes(b)
    }
}

fn i64_at(data: &[u8], at: usize, little: bool) -> i64 {
    let b = bytes8(data, at);
    if little {
        i64::from_le_bytes(b)
    } else {
        i64::from_be_bytes(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_round_trip_bit_for_bit() {
        for sample in [
            GyroSample {
                rate_dps: Some(-0.123_456_789_012_345_6),
                temperature_c: Some(25.0),
                status: Some(0x80),
            },
            GyroSample {
                rate_dps: None,
                temperature_c: None,
                status: None,
            },
            GyroSample {
                rate_dps: Some(f64::MIN_POSITIVE),
                temperature_c: None,
                status: Some(u32::MAX),
            },
        ] {
            assert_eq!(decode_sample(&encode_sample(&sample)), Ok(sample));
        }
        assert_eq!(
            decode_reference(&encode_reference(Some(1e-300))),
            Ok(Some(1e-300))
        );
        assert_eq!(decode_reference(&encode_reference(None)), Ok(None));
        assert_eq!(
            decode_reference(&encode_reference(Some(f64::INFINITY))),
            Ok(None)
        );
    }

    #[test]
    fn the_layout_is_cdr_as_ros_2_writes_it() {
        let bytes = encode_sample(&GyroSample {
            rate_dps: Some(1.5),
            temperature_c: None,
            status: Some(7),
        });
        assert_eq!(bytes[..4], [0, 1, 0, 0]);
        assert_eq!(bytes[4..12], 1.5_f64.to_le_bytes());
        assert!(f64::from_le_bytes(bytes[12..20].try_into().unwrap()).is_nan());
        assert_eq!(bytes[20..28], 7_i64.to_le_bytes());
        // Big-endian CDR reads the same.
        let mut big = vec![0, 0, 0, 0];
        big.extend_from_slice(&2.5_f64.to_be_bytes());
        big.extend_from_slice(&f64::NAN.to_be_bytes());
        big.extend_from_slice(&(-1_i64).to_be_bytes());
        let sample = decode_sample(&big).unwrap();
        assert_eq!((sample.rate_dps, sample.status), (Some(2.5), None));
    }

    #[test]
    fn the_declared_fields_are_read_from_a_definition() {
        assert_eq!(
            declared_fields(SAMPLE_DEFINITION),
            ["float64 rate_dps", "float64 temperature_c", "int64 status"]
        );
        assert_eq!(declared_fields(REFERENCE_DEFINITION), ["float64 angle_deg"]);
        let other = "# c\nint8 OK=0\n  float64   angle_deg  # x\n\n===\nMSG: a/b\nint8 y\n";
        assert_eq!(declared_fields(other), ["float64 angle_deg"]);
    }

    #[test]
    fn bad_messages_say_what_is_wrong() {
        assert!(decode_sample(&[0, 1, 0, 0, 1, 2])
            .unwrap_err()
            .contains("6 bytes, a gyro_msgs/msg/Sample message in CDR has 28"));
        let mut bytes = encode_sample(&GyroSample {
            rate_dps: Some(1.0),
            temperature_c: None,
            status: None,
        });
        bytes[1] = 3;
        assert!(decode_sample(&bytes)
            .unwrap_err()
            .contains("encapsulation 0x0003"));
        bytes[1] = 1;
        bytes[20..28].copy_from_slice(&(-2_i64).to_le_bytes());
        assert!(decode_sample(&bytes).unwrap_err().contains("status -2"));
    }
}
