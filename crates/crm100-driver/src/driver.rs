//! embedded-hal 1.0 driver over an [`SpiDevice`].
//!
//! # Bus
//! SPI [`MODE`] 0 (CPOL = 0, CPHA = 0), 8-bit words, MSB first, 0.1–8 MHz (1 MHz typical).
//! Chip select belongs to the [`SpiDevice`]; the driver never touches it. Each 6-byte frame is
//! one [`SpiDevice::transaction`], so CS frames every frame. The CRM100 wants at least
//! 25 µs between CS falling and the first clock edge: the driver puts an
//! [`Operation::DelayNs`] of [`Settings::cs_lead_ns`] (default [`DEFAULT_CS_LEAD_NS`] =
//! 25 µs) in front of the transfer, inside the transaction. Devices built without a delay
//! source (e.g. `embedded-hal-bus`'s `ExclusiveDevice::new_no_delay`) panic on a delay
//! operation: set `cs_lead_ns` to 0 there and guarantee the lead time another way.
//!
//! # Start-up sequence implemented
//! 1. Power-up, or a pulse on the sensor's RESET pin, is the caller's business (the driver
//!    owns only the SPI device); wait the sensor's start-up time before the first transfer.
//!    After a hardware reset, call [`Crm100::resync`].
//! 2. Priming transfer: the first [`Crm100::read`] (or an explicit [`Crm100::start`]) sends
//!    the configured range command and **discards** the response, which answers a command the
//!    driver did not send (or is power-up content).
//! 3. Every further transfer sends the poll command ([`PollCommand`], by default the range
//!    command again) and decodes the response.
//!
//! After an SPI error the driver no longer knows what the sensor received, so it goes back to
//! step 2 on the next read.
//!
//! # Pipelining
//! By default ([`ResponseTiming::Pipelined`]) transfer *n* is assumed to carry the response
//! to command *n − 1*. The driver therefore remembers the range the sensor is in after each
//! command and scales each response by the range in force for *that* response: after
//! [`Crm100::set_range`] the first sample is still scaled by the old range, the next by the
//! new one, and no sample is lost or mis-scaled. [`ResponseTiming::Immediate`] switches to the
//! other model; nothing else changes.

use embedded_hal::spi::{Mode, Operation, SpiDevice, MODE_0};

use crate::error::Error;
use crate::frame::{command_frame, Response, FRAME_LEN};
use crate::types::{Checks, Measurement, PollCommand, Range, ResponseTiming};

/// SPI mode of the CRM100: mode 0 (CPOL = 0, CPHA = 0), MSB first.
pub const MODE: Mode = MODE_0;

/// Default chip-select lead time: ≥ 25 µs from CS low to the first clock edge.
pub const DEFAULT_CS_LEAD_NS: u32 = 25_000;

/// Driver settings. The unknown protocol details are switches here, not constants.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Settings {
    /// Measurement range. Default ±300 °/s: a hand-turned wrench can exceed 150 °/s, and
    /// 1/24 °/s resolution is far below the noise that matters for the angle.
    pub range: Range,
    /// Command sent to fetch a sample (default: repeat the range command).
    pub poll: PollCommand,
    /// Which command a response answers (default: the previous one).
    pub timing: ResponseTiming,
    /// Response checks (default: checksum and saturation refused, status flagged).
    pub checks: Checks,
    /// Delay between CS low and the first clock, in ns, issued as a
    /// [`Operation::DelayNs`] inside the transaction; 0 omits it. Default 25 000.
    pub cs_lead_ns: u32,
}

impl Settings {
    /// Defaults with the given range.
    pub const fn new(range: Range) -> Self {
        Settings {
            range,
            poll: PollCommand::RepeatRange,
            timing: ResponseTiming::Pipelined,
            checks: Checks::DEFAULT,
            cs_lead_ns: DEFAULT_CS_LEAD_NS,
        }
    }

    /// With another poll command.
    pub const fn with_poll(mut self, poll: PollCommand) -> Self {
        self.poll = poll;
        self
    }

    /// With another response timing.
    pub const fn with_timing(mut self, timing: ResponseTiming) -> Self {
        self.timing = timing;
        self
    }

    /// With other response checks.
    pub const fn with_checks(mut self, checks: Checks) -> Self {
        self.checks = checks;
        self
    }

    /// With another CS lead time (ns; 0 for none).
    pub const fn with_cs_lead_ns(mut self, cs_lead_ns: u32) -> Self {
        self.cs_lead_ns = cs_lead_ns;
        self
    }
}

impl Default for Settings {
    fn default() -> Self {
        Settings::new(Range::Dps300)
    }
}

/// One undecoded exchange: what a serial bridge forwards.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RawSample {
    /// Command byte sent in the transfer that clocked in `response`.
    pub command: u8,
    /// The 6 bytes received, unchecked.
    pub response: [u8; FRAME_LEN],
    /// The range in force for this response under the configured [`ResponseTiming`].
    pub range: Range,
}

/// CRM100 driver over an embedded-hal 1.0 [`SpiDevice`].
#[derive(Debug)]
pub struct Crm100<SPI> {
    spi: SPI,
    settings: Settings,
    /// The range the sensor is in after the last command sent; `None` before the priming
    /// transfer, after [`Crm100::resync`] and after an SPI error.
    sensor_range: Option<Range>,
    /// A [`Crm100::set_range`] whose range command has not gone out yet.
    range_pending: bool,
}

impl<SPI: SpiDevice> Crm100<SPI> {
    /// Takes the SPI device. No bus traffic: the priming transfer happens on the first read
    /// (or [`Crm100::start`]).
    pub fn new(spi: SPI, settings: Settings) -> Self {
        Crm100 {
            spi,
            settings,
            sensor_range: None,
            range_pending: false,
        }
    }

    /// Gives the SPI device back.
    pub fn release(self) -> SPI {
        self.spi
    }

    /// Current settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Configured range (the one the next command selects).
    pub fn range(&self) -> Range {
        self.settings.range
    }

    /// Changes the range. No bus traffic: the range command goes out with the next transfer,
    /// and each response is scaled by the range actually in force for it (see the module docs
    /// on pipelining), so the switch costs no sample.
    pub fn set_range(&mut self, range: Range) {
        self.settings.range = range;
        self.range_pending = true;
    }

    /// Changes the response checks.
    pub fn set_checks(&mut self, checks: Checks) {
        self.settings.checks = checks;
    }

    /// `true` once the priming transfer is done and the command in flight is known.
    pub fn is_started(&self) -> bool {
        self.sensor_range.is_some()
    }

    /// Forgets the command in flight, so the next read primes again. Call after a hardware
    /// reset or power cycle of the sensor.
    pub fn resync(&mut self) {
        self.sensor_range = None;
    }

    /// The priming transfer: sends the range command and discards the response.
    pub fn start(&mut self) -> Result<(), Error<SPI::Error>> {
        self.exchange(self.settings.range.command()).map(|_| ())
    }

    /// One full-duplex frame with an arbitrary command byte (checksum appended); returns the
    /// 6 bytes received, unchecked. Low level, for exploring the protocol: the driver still
    /// tracks the range the command selects.
    pub fn exchange(&mut self, command: u8) -> Result<[u8; FRAME_LEN], Error<SPI::Error>> {
        let mut buffer = command_frame(command);
        let lead = self.settings.cs_lead_ns;
        let result = if lead > 0 {
            self.spi.transaction(&mut [
                Operation::DelayNs(lead),
                Operation::TransferInPlace(&mut buffer),
            ])
        } else {
            self.spi
                .transaction(&mut [Operation::TransferInPlace(&mut buffer)])
        };
        match result {
            Ok(()) => {
                self.sensor_range = Range::from_command(command).or(self.sensor_range);
                if command == self.settings.range.command() {
                    self.range_pending = false;
                }
                Ok(buffer)
            }
            Err(error) => {
                self.sensor_range = None;
                Err(Error::Comm(error))
            }
        }
    }

    /// One poll, undecoded: primes first if needed, then sends the poll command and returns
    /// the response with the range in force for it. Never fails on the content of the bytes,
    /// which is what a serial bridge wants.
    pub fn read_raw(&mut self) -> Result<RawSample, Error<SPI::Error>> {
        let before = match self.sensor_range {
            Some(range) => range,
            None => {
                self.start()?;
                self.settings.range
            }
        };
        let command = self.next_command();
        let response = self.exchange(command)?;
        let after = Range::from_command(command).unwrap_or(before);
        let range = match self.settings.timing {
            ResponseTiming::Pipelined => before,
            ResponseTiming::Immediate => after,
        };
        Ok(RawSample {
            command,
            response,
            range,
        })
    }

    /// One poll, decoded: rate (°/s), temperature (°C) and raw status, checked as
    /// [`Settings::checks`] says.
    pub fn read(&mut self) -> Result<Measurement, Error<SPI::Error>> {
        let sample = self.read_raw()?;
        let checks = self.settings.checks;
        let response = Response::from_bytes(&sample.response, checks.verify_checksum)?;
        Ok(response.measurement(sample.range, checks)?)
    }

    /// The command for the next poll transfer.
    fn next_command(&self) -> u8 {
        match self.settings.poll {
            PollCommand::RepeatRange => self.settings.range.command(),
            // A pending range change goes out first, once.
            PollCommand::Fixed(_) if self.range_pending => self.settings.range.command(),
            PollCommand::Fixed(command) => command,
        }
    }
}
