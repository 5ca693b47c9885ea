//! ROS 2 `sensor_msgs/msg/Imu` in CDR, as rosbag2 writes it into MCAP (schema encoding
//! `ros2msg`, message encoding `cdr`).
//!
//! The rate is one component of `angular_velocity` (rad/s, converted to deg/s), chosen
//! with [`Axis`] and optionally negated (a sensor mounted upside down). The time stamp is
//! the message header's `stamp` by default (when the sensor sampled), or the MCAP log time
//! (when the recorder received it, which adds transport jitter) — see [`TimeSource`].

use serde::Deserialize;

/// Schema name rosbag2 gives the IMU message.
pub const IMU_SCHEMA_NAME: &str = "sensor_msgs/msg/Imu";

/// Component of `angular_velocity` used as the rate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Axis {
    /// `angular_velocity.x`.
    X,
    /// `angular_velocity.y`.
    Y,
    /// `angular_velocity.z`.
    #[default]
    Z,
}

/// Where a ROS 2 sample's time stamp comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum TimeSource {
    /// The message's `header.stamp` (sampling time); a zero stamp is an error.
    #[default]
    Header,
    /// The MCAP log time (when the recorder received the message).
    LogTime,
}

#[derive(Deserialize)]
struct Time {
    sec: i32,
    nanosec: u32,
}

#[derive(Deserialize)]
struct Header {
    stamp: Time,
    #[allow(dead_code)] // read to move past it
    frame_id: String,
}

#[derive(Deserialize)]
#[allow(dead_code)] // read to move past it
struct Quaternion {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

#[derive(Deserialize)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

/// `sensor_msgs/msg/Imu`; fields after `angular_velocity` are not needed and not read.
#[derive(Deserialize)]
#[allow(dead_code)] // read to move past it
struct Imu {
    header: Header,
    orientation: Quaternion,
    orientation_covariance: [f64; 9],
    angular_velocity: Vector3,
}

/// What one IMU message gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct ImuSample {
    /// Header stamp (ns since the epoch), `None` if zero (unset).
    pub stamp_ns: Option<u64>,
    /// The chosen, possibly negated component (deg/s); `None` if not finite.
    pub rate_dps: Option<f64>,
}

/// Decode a CDR `sensor_msgs/msg/Imu` (with its 4-byte encapsulation header).
pub(super) fn decode_imu(data: &[u8], axis: Axis, flip: bool) -> Result<ImuSample, String> {
    let imu: Imu = cdr::deserialize(data).map_err(|e| format!("not a CDR Imu message: {e}"))?;
    let stamp = &imu.header.stamp;
    if stamp.sec < 0 {
        return Err(format!("negative header stamp ({} s)", stamp.sec));
    }
    let stamp_ns = u64::from(stamp.sec.unsigned_abs()) * 1_000_000_000 + u64::from(stamp.nanosec);
    let w = &imu.angular_velocity;
    let rad_s = match axis {
        Axis::X => w.x,
        Axis::Y => w.y,
        Axis::Z => w.z,
    };
    let sign = if flip { -1.0 } else { 1.0 };
    Ok(ImuSample {
        stamp_ns: (stamp_ns != 0).then_some(stamp_ns),
        rate_dps: rad_s.is_finite().then(|| sign * rad_s.to_degrees()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-built CDR Imu: little-endian encapsulation, then XCDR1 with 8-byte alignment
    /// counted from after the 4-byte encapsulation header.
    fn imu_bytes(sec: i32, nanosec: u32, frame: &str, w: [f64; 3]) -> Vec<u8> {
        let mut b = vec![0x00, 0x01, 0x00, 0x00];
        b.extend(sec.to_le_bytes());
        b.extend(nanosec.to_le_bytes());
        b.extend((frame.len() as u32 + 1).to_le_bytes());
        b.extend(frame.as_bytes());
        b.push(0);
        while (b.len() - 4) % 8 != 0 {
            b.push(0);
        }
        let f = |b: &mut Vec<u8>, v: f64| b.extend(v.to_le_bytes());
        for v in [0.0, 0.0, 0.0, 1.0] {
            f(&mut b, v);
        }
        for _ in 0..9 {
            f(&mut b, 0.0);
        }
        for v in w {
            f(&mut b, v);
        }
        for _ in 0..(9 + 3 + 9) {
            f(&mut b, 0.0);
        }
        b
    }

    #[test]
    fn picks_axis_converts_and_flips() {
        let data = imu_bytes(12, 500, "imu_link", [0.1, -0.2, 1.0]);
        let s = decode_imu(&data, Axis::Z, false).unwrap();
        assert_eq!(s.stamp_ns, Some(12_000_000_500));
        assert_eq!(s.rate_dps, Some(1.0_f64.to_degrees()));
        let s = decode_imu(&data, Axis::Y, true).unwrap();
        assert_eq!(s.rate_dps, Some(0.2_f64.to_degrees()));
        let s = decode_imu(&data, Axis::X, false).unwrap();
        assert_eq!(s.rate_dps, Some(0.1_f64.to_degrees()));
        // frame ids of every length exercise the padding before the doubles
        for frame in ["", "a", "abc", "abcdefg", "abcdefgh"] {
            let data = imu_bytes(0, 0, frame, [0.0, 0.0, -0.5]);
            let s = decode_imu(&data, Axis::Z, false).unwrap();
            assert_eq!(s.stamp_ns, None);
            assert_eq!(s.rate_dps, Some((-0.5_f64).to_degrees()), "{frame:?}");
        }
    }

    #[test]
    fn rejects_garbage() {
        assert!(decode_imu(&[0, 1, 0, 0, 1, 2], Axis::Z, false).is_err());
        assert!(decode_imu(&[], Axis::Z, false).is_err());
        let data = imu_bytes(-1, 0, "x", [0.0; 3]);
        assert!(decode_imu(&data, Axis::Z, false)
            .unwrap_err()
            .contains("negative"));
    }
}
