//! Errors: [`FrameError`] for the bytes of one SPI frame, [`Error`] for the driver.

use core::fmt;

use crate::frame::FRAME_LEN;

/// Why a 6-byte CRM100 response frame was refused.
///
/// Small and `Copy`, so it travels through firmware without allocation. Every check that can
/// produce one of these can be switched off in [`crate::Checks`], except [`FrameError::Length`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FrameError {
    /// The slice handed to the decoder was not [`FRAME_LEN`] (6) bytes long.
    Length {
        /// Number of bytes actually given.
        found: usize,
    },
    /// The checksum byte does not match `!(b0 + b1 + b2 + b3 + b4)`.
    Checksum {
        /// Checksum computed from bytes 0..5.
        expected: u8,
        /// Checksum byte received (byte 5).
        found: u8,
    },
    /// The status byte is non-zero (its bits are not documented publicly; kept raw).
    StatusFault(u8),
    /// The rate word lies beyond the ±7200-count full scale of every range.
    Saturated {
        /// The rate word as received.
        counts: i16,
    },
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrameError::Length { found } => {
                write!(f, "CRM100 frame must be {FRAME_LEN} bytes, got {found}")
            }
            FrameError::Checksum { expected, found } => write!(
                f,
                "CRM100 frame checksum mismatch: expected {expected:#04x}, found {found:#04x}"
            ),
            FrameError::StatusFault(status) => {
                write!(f, "CRM100 status byte reports a fault: {status:#04x}")
            }
            FrameError::Saturated { counts } => write!(
                f,
                "CRM100 rate word {counts} is beyond full scale (±{})",
                crate::FULL_SCALE_COUNTS
            ),
        }
    }
}

impl core::error::Error for FrameError {}

/// Driver error, generic over the SPI device's error type (eldruin's `Error<CommE>` pattern).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error<CommE> {
    /// The SPI transfer failed. The driver forgets which command is in flight, so the next
    /// read starts again with a priming transfer.
    Comm(CommE),
    /// The transfer succeeded but the response was refused.
    Frame(FrameError),
}

impl<CommE> From<FrameError> for Error<CommE> {
    fn from(error: FrameError) -> Self {
        Error::Frame(error)
    }
}

impl<CommE: fmt::Debug> fmt::Display for Error<CommE> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Comm(error) => write!(f, "SPI error talking to the CRM100: {error:?}"),
            Error::Frame(error) => write!(f, "{error}"),
        }
    }
}

impl<CommE: fmt::Debug> core::error::Error for Error<CommE> {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Error::Comm(_) => None,
            Error::Frame(error) => Some(error),
        }
    }
}
