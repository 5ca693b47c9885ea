//! A CRM100 serial bridge in software: samples (from a log or the simulator) become CRM100
//! responses, bridge frames and bytes on a port, with seeded, counted faults.
//!
//! Each sample becomes one [`Response`] (rate word in the range's LSB, rounded and limited
//! to the ±7200-count full scale; temperature word; status 0), then one [`BridgeFrame`]
//! (sequence +1 per sample, µs timestamp from the sample time, the range's command byte),
//! then [`BRIDGE_FRAME_LEN`] bytes. [`Emulator`] is an iterator of [`PlannedFrame`]s, each
//! with the faults drawn for it, so a test knows exactly what was sent; [`stream`] writes
//! them to any [`Write`] (a pseudo-terminal, a serial port) at real-time pace or as fast
//! as the reader takes them, and counts what it did in an [`EmulatorReport`].
//!
//! # Faults ([`FaultSpec`], probabilities per frame, one seeded random stream)
//! | fault | on the wire | what a receiver sees |
//! |---|---|---|
//! | `drop` | the frame is not sent; its sequence number is used | a sequence gap |
//! | `byte_loss` | one byte of the 24 is left out | a CRC error or skipped bytes; a gap |
//! | `bit_flip` | one bit of the 24 bytes is inverted | a CRC error or skipped bytes; a gap |
//! | `checksum` | the CRM100 response checksum byte is wrong (bridge CRC good) | a frame whose response fails the CRM100 checksum |
//! | `status` | the CRM100 status byte is non-zero (checksum valid) | a frame flagged with a status fault |
//! | `stall` | the bridge pauses `stall_ms` before the frame | read timeouts, then a burst |
//!
//! At most one wire fault (`drop`, `byte_loss`, `bit_flip`, tried in that order) and one
//! sensor fault (`checksum`, `status`) per frame; a stall can come with either. Every frame
//! draws the same number of random values, so the faults of one kind do not move when the
//! probability of another changes.

use crm100_driver::{
    temperature_c_to_word, BridgeFrame, Range, Response, Status, BRIDGE_FRAME_LEN,
    FULL_SCALE_COUNTS,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use std::io::{self, ErrorKind, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Temperature sent when a sample has none (°C).
pub const DEFAULT_TEMPERATURE_C: f64 = 25.0;

/// One sample to emulate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Sample time (s).
    pub time_s: f64,
    /// Angular rate (°/s); `None`: missing in the source (no frame is sent, the sequence
    /// number is used, and it is counted as a source gap).
    pub rate_dps: Option<f64>,
    /// Temperature (°C); `None`: [`DEFAULT_TEMPERATURE_C`] is sent.
    pub temperature_c: Option<f64>,
}

/// Samples of a simulated bench run: bench-like rotations (seeded) seen by `sensor`, with
/// no extra effects — what `emulate` plays when it is given no log. A run of more than
/// [`gyro_sim::MAX_SAMPLES`] samples is refused before it is made.
pub fn simulated_samples(
    sensor: &gyro_sim::SensorModel,
    duration_s: f64,
    seed: u64,
) -> Result<Vec<Sample>, gyro_sim::TooManySamples> {
    use gyro_sim::{simulate, BenchProfile, Motion, SimOptions};
    let motion = Motion::bench(
        &BenchProfile {
            duration_s,
            ..BenchProfile::default()
        },
        seed,
    );
    let options = SimOptions {
        seed,
        ..SimOptions::default()
    };
    gyro_sim::check_size(sensor, &motion)?;
    Ok(simulate(sensor, &[], &motion, &options)
        .rows
        .iter()
        .map(Sample::from)
        .collect())
}

impl From<&gyro_log::Row> for Sample {
    fn from(row: &gyro_log::Row) -> Self {
        Sample {
            time_s: row.time_s,
            rate_dps: row.rate_dps,
            temperature_c: row.temperature_c,
        }
    }
}

/// Fault probabilities (per frame) and their seed; parse one from a `--faults` string with
/// [`FaultSpec::parse`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FaultSpec {
    /// Frame not sent (sequence gap).
    pub drop: f64,
    /// One byte of the frame lost.
    pub byte_loss: f64,
    /// One bit of the frame flipped.
    pub bit_flip: f64,
    /// CRM100 response checksum wrong.
    pub checksum: f64,
    /// CRM100 status byte non-zero.
    pub status: f64,
    /// Bridge pauses before the frame.
    pub stall: f64,
    /// Length of a stall (ms).
    pub stall_ms: u64,
    /// Seed of the fault stream.
    pub seed: u64,
}

impl Default for FaultSpec {
    fn default() -> Self {
        FaultSpec::NONE
    }
}

impl FaultSpec {
    /// No faults.
    pub const NONE: FaultSpec = FaultSpec {
        drop: 0.0,
        byte_loss: 0.0,
        bit_flip: 0.0,
        checksum: 0.0,
        status: 0.0,
        stall: 0.0,
        stall_ms: 50,
        seed: 1,
    };

    /// The preset `typical`: about one fault of each kind per second at 1 kHz, and a
    /// 50 ms stall every 20 s.
    pub const TYPICAL: FaultSpec = FaultSpec {
        drop: 1e-3,
        byte_loss: 1e-3,
        bit_flip: 1e-3,
        checksum: 1e-3,
        status: 1e-3,
        stall: 5e-5,
        stall_ms: 50,
        seed: 1,
    };

    /// Parses `none`, `typical`, or comma-separated `key=value` pairs, optionally after a
    /// preset: `typical,seed=7`, `drop=0.001,bit_flip=1e-4,stall=1e-4,stall_ms=80`. Keys:
    /// `drop`, `byte_loss`, `bit_flip`, `checksum`, `status`, `stall` (probabilities per
    /// frame, 0..=1), `stall_ms`, `seed`.
    pub fn parse(spec: &str) -> Result<FaultSpec, FaultSpecError> {
        let mut faults = FaultSpec::NONE;
        for (i, item) in spec.split(',').map(str::trim).enumerate() {
            match item {
                "" => continue,
                "none" if i == 0 => continue,
                "typical" if i == 0 => {
                    faults = FaultSpec::TYPICAL;
                    continue;
                }
                _ => {}
            }
            let (key, value) = item
                .split_once('=')
                .ok_or_else(|| FaultSpecError::NotKeyValue { item: item.into() })?;
            let (key, value) = (key.trim(), value.trim());
            let probability = || -> Result<f64, FaultSpecError> {
                value
                    .parse::<f64>()
                    .ok()
                    .filter(|p| (0.0..=1.0).contains(p))
                    .ok_or_else(|| FaultSpecError::NotProbability {
                        key: key.into(),
                        value: value.into(),
                    })
            };
            let integer = || -> Result<u64, FaultSpecError> {
                value
                    .parse::<u64>()
                    .map_err(|_| FaultSpecError::NotWholeNumber {
                        key: key.into(),
                        value: value.into(),
                    })
            };
            match key {
                "drop" => faults.drop = probability()?,
                "byte_loss" => faults.byte_loss = probability()?,
                "bit_flip" => faults.bit_flip = probability()?,
                "checksum" => faults.checksum = probability()?,
                "status" => faults.status = probability()?,
                "stall" => faults.stall = probability()?,
                "stall_ms" => faults.stall_ms = integer()?,
                "seed" => faults.seed = integer()?,
                _ => return Err(FaultSpecError::UnknownKey { key: key.into() }),
            }
        }
        Ok(faults)
    }
}

/// Why a fault specification ([`FaultSpec::parse`]) was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FaultSpecError {
    /// An item is not `key=value`.
    #[error("fault `{item}`: expected key=value")]
    NotKeyValue {
        /// The item as written.
        item: String,
    },
    /// A probability outside [0, 1] or not a number.
    #[error("fault `{key}`: `{value}` is not a probability in [0, 1]")]
    NotProbability {
        /// The key.
        key: String,
        /// The value as written.
        value: String,
    },
    /// A count that is not a whole number.
    #[error("fault `{key}`: `{value}` is not a whole number")]
    NotWholeNumber {
        /// The key.
        key: String,
        /// The value as written.
        value: String,
    },
    /// A key that names no fault.
    #[error("unknown fault `{key}` (known: drop, byte_loss, bit_flip, checksum, status, stall, stall_ms, seed)")]
    UnknownKey {
        /// The key.
        key: String,
    },
}

/// What happens to a frame on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WireFault {
    /// Sent as encoded.
    None,
    /// Not sent.
    Dropped,
    /// The byte at this index (0..24) is left out.
    ByteLost {
        /// Index of the byte left out.
        index: u8,
    },
    /// This bit (0..192, byte × 8 + bit) is inverted.
    BitFlip {
        /// Bit inverted.
        bit: u8,
    },
}

/// What the emulated sensor got wrong in the response.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SensorFault {
    /// A good response.
    None,
    /// The checksum byte is XORed with this non-zero value.
    Checksum {
        /// Value XORed into the checksum byte.
        xor: u8,
    },
    /// The status byte is this non-zero value (checksum valid).
    Status {
        /// The status byte sent.
        status: u8,
    },
}

/// One frame the emulator sends (or means to, if it is dropped), with its faults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlannedFrame {
    /// The frame as encoded (response bytes include the sensor fault).
    pub frame: BridgeFrame,
    /// The words before any sensor fault: what a correct sensor would have said.
    pub intended: Response,
    /// Index of the source sample.
    pub source_index: usize,
    /// Fault on the wire.
    pub wire: WireFault,
    /// Fault in the response.
    pub sensor: SensorFault,
    /// Pause before the frame (ms; 0: none).
    pub stall_ms: u64,
    /// The rate was beyond full scale and was limited to ±7200 counts.
    pub clipped: bool,
}

impl PlannedFrame {
    /// `true` if the frame's bytes reach the receiver unchanged.
    pub fn arrives_intact(&self) -> bool {
        self.wire == WireFault::None
    }

    /// Appends the bytes sent for this frame (none if dropped).
    pub fn extend_wire(&self, out: &mut Vec<u8>) {
        let bytes = self.frame.to_bytes();
        match self.wire {
            WireFault::None => out.extend_from_slice(&bytes),
            WireFault::Dropped => {}
            WireFault::ByteLost { index } => {
                let index = usize::from(index);
                out.extend_from_slice(&bytes[..index]);
                out.extend_from_slice(&bytes[index + 1..]);
            }
            WireFault::BitFlip { bit } => {
                let mut bytes = bytes;
                bytes[usize::from(bit / 8)] ^= 1 << (bit % 8);
                out.extend_from_slice(&bytes);
            }
        }
    }
}

/// How the emulator numbers and times its frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmulatorConfig {
    /// Range whose LSB scales the rate word, and whose command byte the frames carry.
    pub range: Range,
    /// Frame rate (Hz): `Some`: sample *i* gets timestamp `i / rate`; `None`: the
    /// samples' own times.
    pub rate_hz: Option<f64>,
    /// Faults to inject.
    pub faults: FaultSpec,
    /// Sequence number of the first sample.
    pub first_sequence: u32,
    /// Bridge timestamp of the first sample (µs).
    pub first_timestamp_us: u64,
}

impl Default for EmulatorConfig {
    fn default() -> Self {
        EmulatorConfig {
            range: Range::Dps300,
            rate_hz: None,
            faults: FaultSpec::NONE,
            first_sequence: 0,
            first_timestamp_us: 0,
        }
    }
}

/// Turns samples into [`PlannedFrame`]s: an iterator, so hours of samples need no plan in
/// memory. Samples without a rate produce no frame but use a sequence number (a real
/// bridge would have sent something; the receiver reports the gap) and are counted in
/// [`Emulator::source_gaps`].
#[derive(Clone, Debug)]
pub struct Emulator<I> {
    samples: I,
    config: EmulatorConfig,
    rng: ChaCha8Rng,
    index: usize,
    sequence: u32,
    first_time_s: Option<f64>,
    source_gaps: u64,
}

impl<I: Iterator<Item = Sample>> Emulator<I> {
    /// An emulator over `samples`.
    pub fn new(samples: I, config: EmulatorConfig) -> Self {
        Emulator {
            samples,
            rng: ChaCha8Rng::seed_from_u64(config.faults.seed),
            sequence: config.first_sequence,
            config,
            index: 0,
            first_time_s: None,
            source_gaps: 0,
        }
    }

    /// Samples without a rate so far (their sequence numbers were skipped).
    pub fn source_gaps(&self) -> u64 {
        self.source_gaps
    }

    fn timestamp_us(&mut self, sample: &Sample) -> u64 {
        let offset_s = match self.config.rate_hz {
            Some(rate) => self.index as f64 / rate,
            None => sample.time_s - *self.first_time_s.get_or_insert(sample.time_s),
        };
        let offset_us = (offset_s * 1e6).round().max(0.0) as u64;
        self.config.first_timestamp_us.saturating_add(offset_us)
    }
}

impl<I: Iterator<Item = Sample>> Iterator for Emulator<I> {
    type Item = PlannedFrame;

    fn next(&mut self) -> Option<PlannedFrame> {
        loop {
            let sample = self.samples.next()?;
            let timestamp_us = self.timestamp_us(&sample);
            let index = self.index;
            self.index += 1;
            let sequence = self.sequence;
            self.sequence = self.sequence.wrapping_add(1);
            // Every sample draws the same random values, used or not.
            let f = self.config.faults;
            let draws: [f64; 6] = std::array::from_fn(|_| self.rng.random::<f64>());
            let byte_index = self.rng.random_range(0..BRIDGE_FRAME_LEN as u8);
            let bit = self.rng.random_range(0..(BRIDGE_FRAME_LEN * 8) as u8);
            let nonzero = self.rng.random_range(1..=u8::MAX);

            let Some(rate_dps) = sample.rate_dps else {
                self.source_gaps += 1;
                continue;
            };
            let range = self.config.range;
            let counts = range.dps_to_counts(rate_dps as f32);
            let limited = counts.clamp(-FULL_SCALE_COUNTS, FULL_SCALE_COUNTS);
            let temperature_c = sample.temperature_c.unwrap_or(DEFAULT_TEMPERATURE_C);
            let intended = Response {
                status: Status(0),
                rate_counts: limited,
                temperature_word: temperature_c_to_word(temperature_c as f32),
            };
            let wire = if draws[0] < f.drop {
                WireFault::Dropped
            } else if draws[1] < f.byte_loss {
                WireFault::ByteLost { index: byte_index }
            } else if draws[2] < f.bit_flip {
                WireFault::BitFlip { bit }
            } else {
                WireFault::None
            };
            let sensor = if draws[3] < f.checksum {
                SensorFault::Checksum { xor: nonzero }
            } else if draws[4] < f.status {
                SensorFault::Status { status: nonzero }
            } else {
                SensorFault::None
            };
            let mut response = intended;
            if let SensorFault::Status { status } = sensor {
                response.status = Status(status);
            }
            let mut bytes = response.to_bytes();
            if let SensorFault::Checksum { xor } = sensor {
                bytes[5] ^= xor;
            }
            return Some(PlannedFrame {
                frame: BridgeFrame {
                    sequence,
                    timestamp_us,
                    command: range.command(),
                    response: bytes,
                },
                intended,
                source_index: index,
                wire,
                sensor,
                stall_ms: if draws[5] < f.stall { f.stall_ms } else { 0 },
                clipped: limited != counts,
            });
        }
    }
}

/// Pace of [`stream`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pacing {
    /// Each frame leaves at its timestamp (relative to the first frame), as a bridge
    /// would send it.
    RealTime,
    /// As fast as the receiver takes the bytes (the port's buffer pushes back).
    AsFastAsPossible,
}

/// What [`stream`] did: the emulator's own fault log, to compare a receiver against.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EmulatorReport {
    /// Frames planned (sequence numbers used by samples with a rate).
    pub frames: u64,
    /// Frames whose bytes went out unchanged.
    pub intact: u64,
    /// Frames not sent.
    pub dropped: u64,
    /// Frames sent with a byte left out.
    pub byte_loss: u64,
    /// Frames sent with a bit flipped.
    pub bit_flips: u64,
    /// Frames with a wrong CRM100 checksum.
    pub bad_checksums: u64,
    /// Frames with a non-zero status byte.
    pub status_faults: u64,
    /// Stalls, and their total length (ms).
    pub stalls: u64,
    /// Total stall time (ms).
    pub stall_ms: u64,
    /// Samples whose rate was limited to full scale.
    pub clipped: u64,
    /// Bytes written.
    pub bytes: u64,
    /// Sequence numbers of frames that did not arrive intact (dropped, byte lost, bit
    /// flipped), in order.
    pub lost_sequences: Vec<u32>,
    /// Wall time spent (s).
    pub elapsed_s: f64,
    /// `true` if the stop flag ended streaming early.
    pub stopped: bool,
}

impl EmulatorReport {
    /// Counts one planned frame (as [`stream`] does when it sends it).
    pub fn count(&mut self, planned: &PlannedFrame) {
        self.frames += 1;
        match planned.wire {
            WireFault::None => self.intact += 1,
            WireFault::Dropped => self.dropped += 1,
            WireFault::ByteLost { .. } => self.byte_loss += 1,
            WireFault::BitFlip { .. } => self.bit_flips += 1,
        }
        if !planned.arrives_intact() {
            self.lost_sequences.push(planned.frame.sequence);
        }
        match planned.sensor {
            SensorFault::None => {}
            SensorFault::Checksum { .. } => self.bad_checksums += 1,
            SensorFault::Status { .. } => self.status_faults += 1,
        }
        if planned.stall_ms > 0 {
            self.stalls += 1;
            self.stall_ms += planned.stall_ms;
        }
        self.clipped += u64::from(planned.clipped);
    }
}

/// Frames batched into one write when not pacing (about 12 kB).
const BATCH_FRAMES: usize = 512;

/// Writes the frames to `out` at `pacing`, and returns the fault log.
///
/// Writes that time out or are interrupted (a serial port or pseudo-terminal whose reader
/// is slow) are retried until `write_timeout` passes without a byte taken (`None`: for
/// ever), then it is an error of kind `TimedOut`; `stop` (e.g. set by a signal handler)
/// ends streaming early, and
/// `sent` (if given) is updated with the number of frames handed to `out` so far, for a
/// test or a progress display. When `stop` ends a blocked write, the frames of that last
/// batch are counted in the report but may be partly unsent.
pub fn stream<W: Write + ?Sized>(
    frames: impl IntoIterator<Item = PlannedFrame>,
    out: &mut W,
    pacing: Pacing,
    stop: Option<&AtomicBool>,
    sent: Option<&AtomicU64>,
    write_timeout: Option<Duration>,
) -> io::Result<EmulatorReport> {
    let start = Instant::now();
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let mut report = EmulatorReport::default();
    let mut batch = Vec::with_capacity(BATCH_FRAMES * BRIDGE_FRAME_LEN);
    let mut batch_frames = 0_u64;
    let mut first_timestamp_us = None;
    let mut clock = start;
    for planned in frames {
        if stopped() {
            report.stopped = true;
            break;
        }
        let offset = match pacing {
            Pacing::RealTime => {
                let first = *first_timestamp_us.get_or_insert(planned.frame.timestamp_us);
                Some(Duration::from_micros(
                    planned.frame.timestamp_us.saturating_sub(first),
                ))
            }
            Pacing::AsFastAsPossible => None,
        };
        let early = offset.is_some_and(|offset| clock + offset > Instant::now());
        // Send what is batched before waiting (a stall, or the next frame's time).
        if planned.stall_ms > 0 || early {
            write_batch(out, &mut batch, stop, write_timeout)?;
            publish(sent, &mut batch_frames);
        }
        if planned.stall_ms > 0 {
            let pause = Duration::from_millis(planned.stall_ms);
            std::thread::sleep(pause);
            // A stalled bridge sends late; it does not make up for the pause.
            clock += pause;
        }
        if let Some(offset) = offset {
            let due = clock + offset;
            let now = Instant::now();
            if due > now {
                std::thread::sleep(due - now);
            }
        }
        report.count(&planned);
        planned.extend_wire(&mut batch);
        batch_frames += 1;
        if batch.len() >= BATCH_FRAMES * BRIDGE_FRAME_LEN || pacing == Pacing::RealTime {
            write_batch(out, &mut batch, stop, write_timeout)?;
            publish(sent, &mut batch_frames);
        }
    }
    write_batch(out, &mut batch, stop, write_timeout)?;
    publish(sent, &mut batch_frames);
    flush_retrying(out, stop, write_timeout)?;
    report.bytes = report_bytes(&report);
    report.elapsed_s = start.elapsed().as_secs_f64();
    Ok(report)
}

/// Bytes the counted frames put on the wire.
fn report_bytes(report: &EmulatorReport) -> u64 {
    let full = (report.intact + report.bit_flips) * BRIDGE_FRAME_LEN as u64;
    full + report.byte_loss * (BRIDGE_FRAME_LEN as u64 - 1)
}

fn publish(sent: Option<&AtomicU64>, batch_frames: &mut u64) {
    if let Some(sent) = sent {
        sent.fetch_add(*batch_frames, Ordering::Relaxed);
    }
    *batch_frames = 0;
}

/// Writes all of `batch`, retrying writes that time out or are interrupted, unless `stop`
/// is set.
fn write_batch<W: Write + ?Sized>(
    out: &mut W,
    batch: &mut Vec<u8>,
    stop: Option<&AtomicBool>,
    write_timeout: Option<Duration>,
) -> io::Result<()> {
    let mut rest = batch.as_slice();
    let mut progress = Instant::now();
    while !rest.is_empty() {
        match out.write(rest) {
            Ok(0) => {
                return Err(io::Error::new(
                    ErrorKind::WriteZero,
                    "the port took no bytes",
                ))
            }
            Ok(n) => {
                rest = &rest[n..];
                progress = Instant::now();
            }
            Err(e) if retryable(&e) => {
                if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                    break;
                }
                if let Some(limit) = write_timeout.filter(|l| progress.elapsed() >= *l) {
                    return Err(io::Error::new(
                        ErrorKind::TimedOut,
                        format!(
                            "the port took no byte for {} s: is anything reading it?",
                            limit.as_secs_f64()
                        ),
                    ));
                }
            }
            Err(e) => return Err(e),
        }
    }
    batch.clear();
    Ok(())
}

fn flush_retrying<W: Write + ?Sized>(
    out: &mut W,
    stop: Option<&AtomicBool>,
    write_timeout: Option<Duration>,
) -> io::Result<()> {
    let start = Instant::now();
    loop {
        match out.flush() {
            Ok(()) => return Ok(()),
            Err(e) if retryable(&e) && write_timeout.is_some_and(|l| start.elapsed() >= l) => {
                return Err(io::Error::new(
                    ErrorKind::TimedOut,
                    "the port took no byte in time: is anything reading it?",
                ))
            }
            Err(e) if retryable(&e) && !stop.is_some_and(|s| s.load(Ordering::Relaxed)) => {}
            Err(e) if retryable(&e) => return Ok(()),
            Err(e) => return Err(e),
        }
    }
}

fn retryable(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        ErrorKind::TimedOut | ErrorKind::Interrupted | ErrorKind::WouldBlock
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crm100_driver::{BridgeReceiver, Checks};

    fn samples(n: usize) -> Vec<Sample> {
        (0..n)
            .map(|i| Sample {
                time_s: i as f64 * 1e-3,
                rate_dps: Some((i as f64 * 0.37).sin() * 250.0),
                temperature_c: Some(25.0 + i as f64 * 1e-3),
            })
            .collect()
    }

    #[test]
    fn parse_presets_and_pairs() {
        assert_eq!(FaultSpec::parse("").unwrap(), FaultSpec::NONE);
        assert_eq!(FaultSpec::parse("none").unwrap(), FaultSpec::NONE);
        let f = FaultSpec::parse("typical, seed=9, drop=0").unwrap();
        assert_eq!(f.seed, 9);
        assert_eq!(f.drop, 0.0);
        assert_eq!(f.bit_flip, FaultSpec::TYPICAL.bit_flip);
        assert!(FaultSpec::parse("drop=2").is_err());
        assert!(FaultSpec::parse("lightning=0.1").is_err());
        assert!(FaultSpec::parse("drop").is_err());
        assert!(FaultSpec::parse("seed=-1").is_err());
    }

    #[test]
    fn faults_are_seeded_and_independent_of_other_kinds() {
        let config = EmulatorConfig {
            faults: FaultSpec::parse("drop=0.01,status=0.02,seed=3").unwrap(),
            ..EmulatorConfig::default()
        };
        let a: Vec<_> = Emulator::new(samples(5000).into_iter(), config).collect();
        let b: Vec<_> = Emulator::new(samples(5000).into_iter(), config).collect();
        assert_eq!(a, b);
        let mut more = config;
        more.faults.checksum = 0.05;
        let c: Vec<_> = Emulator::new(samples(5000).into_iter(), more).collect();
        let dropped = |v: &[PlannedFrame]| {
            v.iter()
                .filter(|p| p.wire == WireFault::Dropped)
                .map(|p| p.frame.sequence)
                .collect::<Vec<_>>()
        };
        assert_eq!(dropped(&a), dropped(&c));
        assert!(
            (30..80).contains(&dropped(&a).len()),
            "{}",
            dropped(&a).len()
        );
    }

    #[test]
    fn frames_decode_to_the_samples_and_faults_show_as_planned() {
        let config = EmulatorConfig {
            faults: FaultSpec::parse("typical,stall=0,seed=5").unwrap(),
            first_sequence: u32::MAX - 100, // wraps
            ..EmulatorConfig::default()
        };
        let source = samples(3000);
        let planned: Vec<_> = Emulator::new(source.clone().into_iter(), config).collect();
        let mut report = EmulatorReport::default();
        let mut wire = Vec::new();
        for p in &planned {
            report.count(p);
            p.extend_wire(&mut wire);
        }
        let mut out = Vec::new();
        let sent = stream(
            planned.clone(),
            &mut out,
            Pacing::AsFastAsPossible,
            None,
            None,
            None,
        )
        .unwrap();
        assert_eq!(out, wire);
        assert_eq!(sent.bytes, wire.len() as u64);
        assert_eq!(sent.lost_sequences, report.lost_sequences);

        let mut receiver = BridgeReceiver::new();
        let got: Vec<_> = receiver.feed(&wire).flatten().collect();
        let intact: Vec<_> = planned.iter().filter(|p| p.arrives_intact()).collect();
        assert_eq!(got.len(), intact.len());
        assert_eq!(
            receiver.stats().sequence.frames_lost,
            report.lost_sequences.len() as u64
        );
        let lsb = 1.0 / 24.0;
        for (r, p) in got.iter().zip(&intact) {
            assert_eq!(r.frame, p.frame);
            let decoded =
                crm100_driver::decode(&r.frame.response, Range::Dps300, Checks::NONE).unwrap();
            let source_rate = source[p.source_index].rate_dps.unwrap();
            assert!((f64::from(decoded.rate_dps) - source_rate).abs() <= lsb);
            let checked = crm100_driver::decode(&r.frame.response, Range::Dps300, Checks::DEFAULT);
            match p.sensor {
                SensorFault::Checksum { .. } => assert!(checked.is_err()),
                SensorFault::Status { status } => {
                    assert_eq!(checked.unwrap().status.raw(), status)
                }
                SensorFault::None => assert!(!checked.unwrap().status.is_fault()),
            }
        }
    }

    #[test]
    fn missing_rates_use_a_sequence_number_and_rates_beyond_full_scale_are_limited() {
        let mut source = samples(10);
        source[3].rate_dps = None;
        source[5].rate_dps = Some(1000.0);
        let mut emulator = Emulator::new(source.into_iter(), EmulatorConfig::default());
        let planned: Vec<_> = emulator.by_ref().collect();
        assert_eq!(emulator.source_gaps(), 1);
        assert_eq!(planned.len(), 9);
        assert_eq!(planned[3].frame.sequence, 4);
        assert_eq!(planned[4].intended.rate_counts, 7200);
        assert!(planned[4].clipped);
        assert_eq!(planned[4].frame.timestamp_us, 5000);
    }

    #[test]
    fn real_time_pacing_follows_the_timestamps() {
        let config = EmulatorConfig {
            rate_hz: Some(1000.0),
            ..EmulatorConfig::default()
        };
        let planned = Emulator::new(samples(150).into_iter(), config);
        let mut out = Vec::new();
        let report = stream(planned, &mut out, Pacing::RealTime, None, None, None).unwrap();
        assert!(report.elapsed_s >= 0.149, "{}", report.elapsed_s);
        assert_eq!(out.len(), 150 * BRIDGE_FRAME_LEN);
    }
}
