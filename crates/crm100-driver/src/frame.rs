//! The 6-byte CRM100 SPI frame: command encoder and response decoder.
//!
//! | byte | master → CRM100 (MOSI) | CRM100 → master (MISO) |
//! |------|------------------------|------------------------|
//! | 0    | command                | status (raw)           |
//! | 1    | `0x00`                 | rate, high byte        |
//! | 2    | `0x00`                 | rate, low byte         |
//! | 3    | `0x00`                 | temperature, high byte |
//! | 4    | `0x00`                 | temperature, low byte  |
//! | 5    | checksum               | checksum (assumed)     |
//!
//! Checksum: `!(b0 + b1 + b2 + b3 + b4)`, the ones' complement of the 8-bit wrapping sum.
//! The rate word is an `i16`, big-endian; the temperature word a `u16`, big-endian.
//!
//! What the checksum catches (tested in `tests/all/frame.rs`): a single flipped bit changes the
//! sum by ±2^k (k < 8), never 0 mod 256, so **every single-bit error is detected**, as are
//! all-zero and all-`0xFF` frames (a stuck MISO line). Two flipped bits are **not** always
//! detected: bit 7 flipped in two bytes changes the sum by ±256 ≡ 0, and the same bit going
//! 0→1 in one byte and 1→0 in another cancels. Treat it as a framing check, not as a CRC.
//!
//! No function here panics, whatever the bytes.

use crate::error::FrameError;
use crate::types::{temperature_word_to_c, Checks, Measurement, Range, Status, FULL_SCALE_COUNTS};

/// Length of every CRM100 SPI frame, in both directions.
pub const FRAME_LEN: usize = 6;

/// The checksum byte for the first five bytes of a frame: `!(b0 + b1 + b2 + b3 + b4)`.
///
/// ```
/// assert_eq!(crm100_driver::checksum([0x38, 0, 0, 0, 0]), 0xC7);
/// ```
pub const fn checksum(bytes: [u8; 5]) -> u8 {
    let mut sum = 0u8;
    let mut i = 0;
    while i < 5 {
        sum = sum.wrapping_add(bytes[i]);
        i += 1;
    }
    !sum
}

/// The master frame `[command, 0, 0, 0, 0, checksum]`.
///
/// ```
/// use crm100_driver::{command_frame, Range};
/// assert_eq!(command_frame(Range::Dps75.command()), [0x38, 0, 0, 0, 0, 0xC7]);
/// ```
pub const fn command_frame(command: u8) -> [u8; FRAME_LEN] {
    [command, 0, 0, 0, 0, checksum([command, 0, 0, 0, 0])]
}

/// Checks byte 5 of any 6-byte frame against the checksum of bytes 0..5.
pub const fn verify_checksum(frame: &[u8; FRAME_LEN]) -> Result<(), FrameError> {
    let expected = checksum([frame[0], frame[1], frame[2], frame[3], frame[4]]);
    if expected == frame[5] {
        Ok(())
    } else {
        Err(FrameError::Checksum {
            expected,
            found: frame[5],
        })
    }
}

/// The raw words of a response frame (what the sensor said, before any scaling).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Response {
    /// Status byte (byte 0), raw.
    pub status: Status,
    /// Rate word (bytes 1–2, big-endian), in counts.
    pub rate_counts: i16,
    /// Temperature word (bytes 3–4, big-endian).
    pub temperature_word: u16,
}

impl Response {
    /// Splits a 6-byte response into its words, verifying the checksum if asked to.
    /// Status and saturation are not judged here (see [`Response::measurement`]).
    pub const fn from_bytes(bytes: &[u8; FRAME_LEN], verify: bool) -> Result<Response, FrameError> {
        if verify {
            if let Err(error) = verify_checksum(bytes) {
                return Err(error);
            }
        }
        Ok(Response {
            status: Status(bytes[0]),
            rate_counts: i16::from_be_bytes([bytes[1], bytes[2]]),
            temperature_word: u16::from_be_bytes([bytes[3], bytes[4]]),
        })
    }

    /// As [`Response::from_bytes`], from a slice of any length ([`FrameError::Length`] unless
    /// it is exactly 6 bytes).
    pub fn from_slice(bytes: &[u8], verify: bool) -> Result<Response, FrameError> {
        let bytes: &[u8; FRAME_LEN] = bytes
            .try_into()
            .map_err(|_| FrameError::Length { found: bytes.len() })?;
        Response::from_bytes(bytes, verify)
    }

    /// The 6 bytes a CRM100 would send for these words, with a valid checksum (for
    /// emulators and tests).
    pub const fn to_bytes(&self) -> [u8; FRAME_LEN] {
        let [rate_h, rate_l] = self.rate_counts.to_be_bytes();
        let [temp_h, temp_l] = self.temperature_word.to_be_bytes();
        let head = [self.status.0, rate_h, rate_l, temp_h, temp_l];
        [head[0], head[1], head[2], head[3], head[4], checksum(head)]
    }

    /// `true` when the rate word lies beyond ±[`FULL_SCALE_COUNTS`].
    pub const fn is_saturated(&self) -> bool {
        self.rate_counts > FULL_SCALE_COUNTS || self.rate_counts < -FULL_SCALE_COUNTS
    }

    /// Rate in °/s when the sensor was in `range`.
    pub fn rate_dps(&self, range: Range) -> f32 {
        range.counts_to_dps(self.rate_counts)
    }

    /// Temperature in °C.
    pub fn temperature_c(&self) -> f32 {
        temperature_word_to_c(self.temperature_word)
    }

    /// Scales the words into a [`Measurement`], applying the status and saturation checks
    /// of `checks` (the checksum is judged when the bytes are parsed).
    pub fn measurement(&self, range: Range, checks: Checks) -> Result<Measurement, FrameError> {
        if checks.reject_status_fault && self.status.is_fault() {
            return Err(FrameError::StatusFault(self.status.0));
        }
        if checks.reject_saturated && self.is_saturated() {
            return Err(FrameError::Saturated {
                counts: self.rate_counts,
            });
        }
        Ok(Measurement {
            rate_dps: self.rate_dps(range),
            temperature_c: self.temperature_c(),
            status: self.status,
            range,
            raw: *self,
        })
    }
}

/// Decodes a 6-byte response taken while the sensor was in `range`. Checks run in this
/// order: checksum, status, saturation (each switchable in `checks`).
///
/// ```
/// use crm100_driver::{decode, Checks, Range, Response, Status};
///
/// let bytes = Response { status: Status(0), rate_counts: -960, temperature_word: 600 }.to_bytes();
/// let m = decode(&bytes, Range::Dps75, Checks::DEFAULT)?;
/// assert_eq!(m.rate_dps, -10.0);
/// assert!((m.temperature_c - 25.09).abs() < 0.01);
/// assert!(!m.status.is_fault());
/// # Ok::<(), crm100_driver::FrameError>(())
/// ```
pub fn decode(
    bytes: &[u8; FRAME_LEN],
    range: Range,
    checks: Checks,
) -> Result<Measurement, FrameError> {
    Response::from_bytes(bytes, checks.verify_checksum)?.measurement(range, checks)
}

/// As [`decode`], from a slice of any length.
pub fn decode_slice(bytes: &[u8], range: Range, checks: Checks) -> Result<Measurement, FrameError> {
    Response::from_slice(bytes, checks.verify_checksum)?.measurement(range, checks)
}
