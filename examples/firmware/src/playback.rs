//! A CRM100 that exists only in software: an [`SpiDevice`] playing back recorded rate words.
//!
//! On the wrench the driver gets a real [`SpiDevice`] instead, typically
//! `embedded_hal_bus::spi::ExclusiveDevice::new(spi_bus, cs_pin, delay)` over the HAL's SPI
//! peripheral (mode 0, 1 MHz), its chip-select GPIO and a delay source (a timer or
//! `cortex_m::delay::Delay` on SysTick). That device lowers CS, performs the driver's
//! `DelayNs(25_000)` (the CRM100's ≥ 25 µs CS lead time), clocks the 6 bytes and raises CS.
//!
//! This one plays the sensor's side of the same exchange, and checks the driver's side:
//! every transaction must be one CS lead delay followed by one 6-byte transfer of the range
//! command (`command_frame(0x28)` for ±300 °/s). Like the real sensor it is pipelined: the
//! first transfer after power-up returns power-up content (here all `0xFF`, which the driver
//! discards), every later transfer returns the next sample, framed by
//! [`Response::to_bytes`] (status 0, big-endian words, checksum).

use core::fmt;

use crm100_driver::{command_frame, Range, Response, Status, FRAME_LEN};
use embedded_hal::spi::{self, ErrorKind, ErrorType, Operation, SpiDevice};

/// Bus errors of the playback device (a real one would report overrun, mode fault, ...).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlaybackError {
    /// No recorded words left.
    Exhausted,
    /// The master sent something other than the expected command frame.
    UnexpectedCommand([u8; FRAME_LEN]),
    /// A transfer came with less CS lead time than the sensor needs.
    CsLeadTooShort {
        /// The delay the transaction put in front of the transfer (ns).
        lead_ns: u32,
    },
    /// An operation the CRM100 exchange never uses (only `DelayNs` + `TransferInPlace`).
    UnexpectedOperation,
}

impl spi::Error for PlaybackError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

impl fmt::Display for PlaybackError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlaybackError::Exhausted => write!(f, "no recorded samples left"),
            PlaybackError::UnexpectedCommand(frame) => write!(f, "unexpected command {frame:02x?}"),
            PlaybackError::CsLeadTooShort { lead_ns } => {
                write!(f, "CS lead time {lead_ns} ns is below 25 us")
            }
            PlaybackError::UnexpectedOperation => write!(f, "unexpected SPI operation"),
        }
    }
}

/// Plays back big-endian i16 rate words as CRM100 response frames.
pub struct PlaybackSensor<'a> {
    /// Remaining rate words, 2 bytes each, big-endian (as in the response frame).
    rate_words: &'a [u8],
    /// The command frame the driver is expected to send on every transfer.
    expected_command: [u8; FRAME_LEN],
    /// Temperature word sent with every sample.
    temperature_word: u16,
    /// Minimum CS lead time accepted (ns).
    min_lead_ns: u32,
    /// `false` until the first (priming) transfer.
    powered_up: bool,
    /// Transactions served.
    transactions: u32,
}

impl<'a> PlaybackSensor<'a> {
    /// A sensor in `range` that will send `rate_words` (big-endian i16 each, an odd trailing
    /// byte is ignored) with a constant `temperature_word`.
    pub fn new(
        rate_words: &'a [u8],
        range: Range,
        temperature_word: u16,
        min_lead_ns: u32,
    ) -> Self {
        PlaybackSensor {
            rate_words,
            expected_command: command_frame(range.command()),
            temperature_word,
            min_lead_ns,
            powered_up: false,
            transactions: 0,
        }
    }

    /// Samples left to play.
    pub fn remaining(&self) -> usize {
        self.rate_words.len() / 2
    }

    /// Transactions served so far (the priming transfer included).
    pub fn transactions(&self) -> u32 {
        self.transactions
    }

    /// The 6 bytes the sensor shifts out in this transfer.
    fn next_response(&mut self) -> Result<[u8; FRAME_LEN], PlaybackError> {
        if !self.powered_up {
            self.powered_up = true;
            return Ok([0xFF; FRAME_LEN]);
        }
        let Some(([high, low], rest)) = self.rate_words.split_first_chunk::<2>() else {
            return Err(PlaybackError::Exhausted);
        };
        self.rate_words = rest;
        Ok(Response {
            status: Status(0),
            rate_counts: i16::from_be_bytes([*high, *low]),
            temperature_word: self.temperature_word,
        }
        .to_bytes())
    }
}

impl ErrorType for PlaybackSensor<'_> {
    type Error = PlaybackError;
}

impl SpiDevice for PlaybackSensor<'_> {
    /// One CS-framed exchange: CS falls, the operations run in order, CS rises.
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), PlaybackError> {
        self.transactions = self.transactions.wrapping_add(1);
        let mut lead_ns = 0_u32;
        for operation in operations {
            match operation {
                Operation::DelayNs(ns) => lead_ns = lead_ns.saturating_add(*ns),
                Operation::TransferInPlace(buffer) => {
                    if lead_ns < self.min_lead_ns {
                        return Err(PlaybackError::CsLeadTooShort { lead_ns });
                    }
                    let received: [u8; FRAME_LEN] = (&**buffer)
                        .try_into()
                        .map_err(|_| PlaybackError::UnexpectedOperation)?;
                    if received != self.expected_command {
                        return Err(PlaybackError::UnexpectedCommand(received));
                    }
                    buffer.copy_from_slice(&self.next_response()?);
                }
                _ => return Err(PlaybackError::UnexpectedOperation),
            }
        }
        Ok(())
    }
}
