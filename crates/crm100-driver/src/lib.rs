//! # crm100-driver
//!
//! Silicon Sensing PinPoint CRM100 single-axis gyroscope: SPI frame codec, embedded-hal 1.0
//! driver, and the serial-bridge framing that carries its frames to a host. `no_std`, no
//! allocation, no panics on any input bytes.
//!
//! - [`frame`]: the 6-byte SPI frame. [`command_frame`] encodes `[CMD, 0, 0, 0, 0, CHK]`,
//!   [`decode`] turns `[STATUS, RATE_H, RATE_L, TEMP_H, TEMP_L, CHK]` into a [`Measurement`]
//!   (°/s, °C, raw status), with switchable [`Checks`].
//! - [`driver`]: [`Crm100`] over any [`embedded_hal::spi::SpiDevice`] in SPI [`MODE`] 0.
//! - [`bridge`] and [`sequence`]: the framing a bridge MCU uses to forward raw responses over
//!   UART/USB ([`encode`]), and the host's resynchronising [`BridgeDecoder`], loss-counting
//!   [`SequenceTracker`] and the [`BridgeReceiver`] that combines them.
//! - `reader` (feature `std`): `BridgeReader`, the host reader over any `std::io::Read`
//!   that reports every frame, sequence gap, CRC error, run of skipped bytes and read
//!   timeout as a `ReadEvent`; `serial` (feature `serial`): opening a serial port by name
//!   with a read timeout (the `serialport` crate, re-exported).
//!
//! The CRM100 datasheet was not available. Protocol facts come from public working code;
//! what could not be confirmed is a setting, not a constant: the poll command
//! ([`PollCommand`], default: repeat the range command), the response timing
//! ([`ResponseTiming`], default: pipelined, each transfer returns the answer to the previous
//! command), and the response checksum ([`Checks::verify_checksum`], default on, assuming
//! the master's rule).
//!
//! ```
//! use crm100_driver::{command_frame, Crm100, Range, Response, Settings, Status, MODE};
//! use embedded_hal_mock::eh1::spi::{Mock, Transaction};
//! # assert_eq!(MODE, embedded_hal::spi::MODE_0);
//!
//! let command = command_frame(Range::Dps75.command()).to_vec(); // 38 00 00 00 00 C7
//! let sample = Response { status: Status(0), rate_counts: 4800, temperature_word: 600 };
//! let frame = |response: Vec<u8>| [
//!     Transaction::transaction_start(),
//!     Transaction::delay(25_000), // CS lead time
//!     Transaction::transfer_in_place(command.clone(), response),
//!     Transaction::transaction_end(),
//! ];
//! // Priming transfer (its response is stale and discarded), then the first sample,
//! // which answers the priming command (pipelined).
//! let mut expectations = frame(vec![0xFF; 6]).to_vec();
//! expectations.extend(frame(sample.to_bytes().to_vec()));
//! let spi = Mock::new(&expectations);
//!
//! let mut gyro = Crm100::new(spi, Settings::new(Range::Dps75));
//! let m = gyro.read()?;
//! assert_eq!(m.rate_dps, 50.0); // 4800 counts / 96 LSB per °/s
//! assert!((m.temperature_c - 25.09).abs() < 0.01); // (600 − 531) / 2.75
//! assert!(!m.status.is_fault());
//!
//! gyro.release().done();
//! # Ok::<(), crm100_driver::Error<embedded_hal::spi::ErrorKind>>(())
//! ```
#![cfg_attr(not(any(test, feature = "std")), no_std)]

pub mod bridge;
mod crc16;
pub mod driver;
mod error;
pub mod frame;
#[cfg(feature = "std")]
pub mod reader;
pub mod sequence;
#[cfg(feature = "serial")]
pub mod serial;
mod types;

pub use bridge::{
    encode, encode_to_array, BridgeDecoder, BridgeError, BridgeFrame, DecoderStats, Feed,
    BRIDGE_FRAME_LEN, FORMAT_V1, SYNC,
};
pub use crc16::{crc16_ccitt_false, crc16_ccitt_false_update};
pub use driver::{Crm100, RawSample, Settings, DEFAULT_CS_LEAD_NS, MODE};
pub use error::{Error, FrameError};
pub use frame::{
    checksum, command_frame, decode, decode_slice, verify_checksum, Response, FRAME_LEN,
};
#[cfg(feature = "std")]
pub use reader::{BridgeReader, ReadEvent, ReaderStats, DEFAULT_READ_BUFFER};
pub use sequence::{
    BridgeReceiver, Gap, Received, ReceiverFeed, ReceiverStats, SeqEvent, SequenceStats,
    SequenceTracker, MAX_FORWARD_STEP,
};
pub use types::{
    temperature_c_to_word, temperature_word_to_c, Checks, Measurement, PollCommand, Range,
    ResponseTiming, Status, FULL_SCALE_COUNTS, TEMPERATURE_LSB_PER_C, TEMPERATURE_OFFSET_WORD,
};
