//! Opening the bridge's serial port (feature `serial`): the [`serialport`] crate, built
//! without its `libudev` feature (listing ports falls back to sysfs; opening, reading and
//! pseudo-terminal pairs work the same).
//!
//! ```no_run
//! use std::time::Duration;
//! use crm100_driver::{serial, ReadEvent};
//!
//! let mut reader = serial::open_reader("/dev/ttyACM0", 921_600, Duration::from_millis(100))?;
//! while let Some(event) = reader.next_event()? {
//!     if let ReadEvent::Frame(received) = event {
//!         println!("{} at {} µs", received.frame.sequence, received.frame.timestamp_us);
//!     }
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::time::Duration;

pub use serialport;
use serialport::{DataBits, FlowControl, Parity, SerialPort, StopBits};

use crate::reader::BridgeReader;

/// Baud rate the bridge is documented for (24-byte frames at 1 kHz need ≥ 460 800 Bd).
pub const DEFAULT_BAUD: u32 = 921_600;

/// Opens `name` (e.g. `/dev/ttyACM0`, `COM3`, a pseudo-terminal's slave) at `baud_rate`,
/// 8N1, no flow control, with reads that give up after `read_timeout` (they then return
/// [`std::io::ErrorKind::TimedOut`], which [`BridgeReader`] reports as a timeout event).
pub fn open(
    name: &str,
    baud_rate: u32,
    read_timeout: Duration,
) -> serialport::Result<Box<dyn SerialPort>> {
    serialport::new(name, baud_rate)
        .data_bits(DataBits::Eight)
        .parity(Parity::None)
        .stop_bits(StopBits::One)
        .flow_control(FlowControl::None)
        .timeout(read_timeout)
        .open()
}

/// [`open`], wrapped in a [`BridgeReader`].
pub fn open_reader(
    name: &str,
    baud_rate: u32,
    read_timeout: Duration,
) -> serialport::Result<BridgeReader<Box<dyn SerialPort>>> {
    open(name, baud_rate, read_timeout).map(BridgeReader::new)
}
