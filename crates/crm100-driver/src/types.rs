//! Value types: measurement ranges, status, decoded measurements, and the switches that
//! hold the protocol facts we could not confirm from a datasheet.

use core::fmt;

use crate::frame::Response;

/// Full scale of the rate word in every range: ±7200 counts.
///
/// 75 × 96 = 150 × 48 = 300 × 24 = 900 × 8 = 7200.
pub const FULL_SCALE_COUNTS: i16 = 7200;

/// Temperature word at 0 °C: °C = (word − 531) / 2.75.
pub const TEMPERATURE_OFFSET_WORD: u16 = 531;

/// Temperature sensitivity in LSB per °C: °C = (word − 531) / 2.75.
pub const TEMPERATURE_LSB_PER_C: f32 = 2.75;

/// Measurement range, selected by the command byte of a master frame.
///
/// Command bytes and sensitivities come from public working code (the datasheet was not
/// available): bits 4..3 select the range, bit 5 is set in every range command.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Range {
    /// ±75 °/s, command `0x38`, 96 LSB per °/s.
    Dps75,
    /// ±150 °/s, command `0x30`, 48 LSB per °/s.
    Dps150,
    /// ±300 °/s, command `0x28`, 24 LSB per °/s.
    Dps300,
    /// ±900 °/s, command `0x20`, 8 LSB per °/s.
    Dps900,
}

impl Range {
    /// All ranges, finest first.
    pub const ALL: [Range; 4] = [Range::Dps75, Range::Dps150, Range::Dps300, Range::Dps900];

    /// Command byte that selects this range.
    pub const fn command(self) -> u8 {
        match self {
            Range::Dps75 => 0x38,
            Range::Dps150 => 0x30,
            Range::Dps300 => 0x28,
            Range::Dps900 => 0x20,
        }
    }

    /// The range a command byte selects, `None` if it is not one of the four range commands.
    pub const fn from_command(command: u8) -> Option<Range> {
        match command {
            0x38 => Some(Range::Dps75),
            0x30 => Some(Range::Dps150),
            0x28 => Some(Range::Dps300),
            0x20 => Some(Range::Dps900),
            _ => None,
        }
    }

    /// Sensitivity: counts per °/s (96, 48, 24, 8).
    pub const fn lsb_per_dps(self) -> u16 {
        match self {
            Range::Dps75 => 96,
            Range::Dps150 => 48,
            Range::Dps300 => 24,
            Range::Dps900 => 8,
        }
    }

    /// Full scale in °/s (75, 150, 300, 900); ±[`FULL_SCALE_COUNTS`] counts in every range.
    pub const fn full_scale_dps(self) -> u16 {
        match self {
            Range::Dps75 => 75,
            Range::Dps150 => 150,
            Range::Dps300 => 300,
            Range::Dps900 => 900,
        }
    }

    /// Rate word (counts) → °/s. Exact division of an i16 by a power-of-two multiple of 3,
    /// correctly rounded to f32.
    pub fn counts_to_dps(self, counts: i16) -> f32 {
        f32::from(counts) / f32::from(self.lsb_per_dps())
    }

    /// °/s → rate word, rounded to nearest (ties away from zero) and clamped to the i16
    /// range; NaN maps to 0. The inverse of [`Range::counts_to_dps`] for every i16 (tested
    /// exhaustively). Meant for emulators and tests, not for the measurement path.
    pub fn dps_to_counts(self, rate_dps: f32) -> i16 {
        round_to_i16(rate_dps * f32::from(self.lsb_per_dps()))
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "±{} °/s", self.full_scale_dps())
    }
}

/// Temperature word → °C: (word − 531) / 2.75. Defined for every u16.
pub fn temperature_word_to_c(word: u16) -> f32 {
    (f32::from(word) - f32::from(TEMPERATURE_OFFSET_WORD)) / TEMPERATURE_LSB_PER_C
}

/// °C → temperature word, rounded to nearest and clamped to u16; NaN maps to 0.
/// The inverse of [`temperature_word_to_c`] for every u16 (tested exhaustively).
pub fn temperature_c_to_word(temperature_c: f32) -> u16 {
    let x = temperature_c * TEMPERATURE_LSB_PER_C + f32::from(TEMPERATURE_OFFSET_WORD);
    let rounded = round_clamped(x, 0.0, f32::from(u16::MAX));
    // In range by construction; `as` saturates anyway.
    rounded as u16
}

fn round_to_i16(x: f32) -> i16 {
    round_clamped(x, f32::from(i16::MIN), f32::from(i16::MAX)) as i16
}

/// Round to nearest, ties away from zero, after clamping into `[min, max]` (both integers
/// well inside ±2²³, so truncation and the fractional part are exact). NaN → 0.
fn round_clamped(x: f32, min: f32, max: f32) -> f32 {
    if x.is_nan() {
        return 0.0;
    }
    let x = x.clamp(min, max);
    let truncated = x as i32;
    let fraction = x - truncated as f32;
    let rounded = if fraction >= 0.5 {
        truncated + 1
    } else if fraction <= -0.5 {
        truncated - 1
    } else {
        truncated
    };
    (rounded as f32).clamp(min, max)
}

/// The raw status byte of a response. Its bits are not publicly documented, so it is kept
/// raw; any non-zero value is flagged as a fault.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Status(pub u8);

impl Status {
    /// The byte as received.
    pub const fn raw(self) -> u8 {
        self.0
    }

    /// `true` when the status byte is non-zero.
    pub const fn is_fault(self) -> bool {
        self.0 != 0
    }
}

/// Which response checks the decoder applies. The response checksum rule is an assumption
/// (the same rule as the master's), so it can be switched off.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Checks {
    /// Verify byte 5 against `!(b0 + … + b4)`. Default `true`.
    pub verify_checksum: bool,
    /// Refuse a non-zero status byte with [`crate::FrameError::StatusFault`]. Default
    /// `false`: the measurement is returned and [`Measurement::status`] flags the fault.
    pub reject_status_fault: bool,
    /// Refuse a rate word beyond ±[`FULL_SCALE_COUNTS`] with
    /// [`crate::FrameError::Saturated`]. Default `true`: such a value is outside the
    /// specified range and must not be integrated as if it were a rate.
    pub reject_saturated: bool,
}

impl Checks {
    /// Checksum verified, saturation refused, status flagged (not refused).
    pub const DEFAULT: Checks = Checks {
        verify_checksum: true,
        reject_status_fault: false,
        reject_saturated: true,
    };

    /// Everything refused: checksum, status fault and saturation.
    pub const STRICT: Checks = Checks {
        verify_checksum: true,
        reject_status_fault: true,
        reject_saturated: true,
    };

    /// No check at all: every 6-byte frame decodes (raw logging, protocol exploration).
    pub const NONE: Checks = Checks {
        verify_checksum: false,
        reject_status_fault: false,
        reject_saturated: false,
    };
}

impl Default for Checks {
    fn default() -> Self {
        Checks::DEFAULT
    }
}

/// A decoded response: rate, temperature, raw status, the range used to scale the rate, and
/// the raw words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurement {
    /// Angular rate in °/s.
    pub rate_dps: f32,
    /// Temperature in °C.
    pub temperature_c: f32,
    /// Raw status byte; [`Status::is_fault`] flags non-zero.
    pub status: Status,
    /// The range the rate word was scaled with.
    pub range: Range,
    /// The raw response words.
    pub raw: Response,
}

impl Measurement {
    /// `true` when the rate word lies beyond ±[`FULL_SCALE_COUNTS`] (only possible when
    /// [`Checks::reject_saturated`] is off).
    pub const fn is_saturated(&self) -> bool {
        self.raw.is_saturated()
    }
}

/// Which command byte the driver sends when it only wants the next sample.
///
/// The datasheet was not available. Public working code (an STM32 CRM100/CRM200 test
/// program) sends the range command on every transfer and never anything else, so that is
/// the default here: it is the only poll byte known to work, it re-asserts the range on
/// every frame (idempotent, and a range lost to a sensor reset or a corrupted command comes
/// back by itself), and it avoids guessing what `0x00` or other bytes mean (with bits 4..3
/// as the range field, `0x00` might select ±900 °/s or nothing at all).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PollCommand {
    /// Send the configured range's command on every transfer (default).
    #[default]
    RepeatRange,
    /// Send this byte on every transfer after start-up (the range command is still sent at
    /// start-up and whenever the range changes). If the byte happens to be a range command,
    /// the driver tracks the range it selects.
    Fixed(u8),
}

/// When the response to a command arrives.
///
/// Full-duplex SPI sensors of this kind usually answer each transfer with the response to
/// the *previous* command: while the master is still clocking out the command byte, the
/// slave must already be shifting out its status, so that response cannot depend on it.
/// This is an assumption (no datasheet); it matters only for which range scales the first
/// sample after a range change and whether the very first response is meaningful, so it is
/// one switch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ResponseTiming {
    /// Transfer *n* returns the response to command *n − 1* (default). The response to
    /// the first transfer after start-up answers a command the driver did not send, so the
    /// driver discards it (the priming transfer).
    #[default]
    Pipelined,
    /// Transfer *n* returns the response to command *n*: the rate word is scaled by the
    /// range that command selects.
    Immediate,
}
