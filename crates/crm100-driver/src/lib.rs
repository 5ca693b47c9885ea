//! # crm100-driver
//!
//! Silicon Sensing PinPoint CRM100 single-axis gyroscope: SPI frame codec. `no_std`, no
//! allocation, no panics on any input bytes.
//!
//! - [`frame`]: the 6-byte SPI frame. [`command_frame`] encodes `[CMD, 0, 0, 0, 0, CHK]`,
//!   [`decode`] turns `[STATUS, RATE_H, RATE_L, TEMP_H, TEMP_L, CHK]` into a [`Measurement`]
//!   (°/s, °C, raw status), with switchable [`Checks`].
//!
//! The CRM100 datasheet was not available. Protocol facts come from public working code;
//! what could not be confirmed is a setting, not a constant (e.g. the response checksum,
//! [`Checks::verify_checksum`], default on, assuming the master's rule).
#![cfg_attr(not(any(test, feature = "std")), no_std)]

mod error;
pub mod frame;
mod types;

pub use error::{Error, FrameError};
pub use frame::{
    checksum, command_frame, decode, decode_slice, verify_checksum, Response, FRAME_LEN,
};
pub use types::{
    temperature_c_to_word, temperature_word_to_c, Checks, Measurement, PollCommand, Range,
    ResponseTiming, Status, FULL_SCALE_COUNTS, TEMPERATURE_LSB_PER_C, TEMPERATURE_OFFSET_WORD,
};
