//! Example firmware: CRM100 → `crm100-driver` → `gyro-core`, the way the wrench wires them.
//!
//! Built for `thumbv7em-none-eabihf` (Cortex-M4F), it boots on QEMU's `mps2-an386` board.
//! There is no gyroscope on that board, so the SPI device is [`PlaybackSensor`], which
//! answers the driver's frames with the rate words of the first 20 s of
//! `fixtures/logs/bench_run.csv` (three 90° turns); everything after the SPI device is the
//! code a wrench runs: the driver's `read()` (framing, checksum, scaling by range) and the
//! pipeline's `push_with_temperature()` (the sensor's temperature drives the temperature
//! terms of the model's correction; the default correction is the identity, which gives
//! exactly what `push()` gives). Results go to the host console over semihosting, and the exit
//! status says whether the run was clean. `run-qemu.sh` checks the printed angles against
//! `gyro-cli run` on the host: they must be the same f32 values, bit for bit.
//!
//! Numbers are printed with `{}`, the shortest decimal that parses back to the same value,
//! so two equal printouts mean two equal floats.
#![no_std]
#![no_main]

mod playback;

use core::mem::size_of;

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use crm100_driver::{
    temperature_c_to_word, Crm100, Error, FrameError, Range, Settings, DEFAULT_CS_LEAD_NS,
};
use gyro_core::{Compensation, Config, Event, Output, Pipeline};
use panic_semihosting as _; // a panic prints its message and exits QEMU with a failure

use crate::playback::PlaybackSensor;

/// The recorded rate words: big-endian i16 counts at 1 kHz in the ±300 °/s range
/// (made by `fixtures/firmware/make_rate_words.py`).
static RATE_WORDS: &[u8] = include_bytes!("../../../fixtures/firmware/bench_run_20s.i16be");

/// The range the recording was made in. A hand-turned wrench can exceed 150 °/s.
const RANGE: Range = Range::Dps300;

/// Both compensations run side by side, so the host check covers both; a wrench runs one.
const COMPENSATIONS: [(&str, Compensation); 2] = [
    ("paper", Compensation::Paper),
    ("kalman", Compensation::Kalman),
];

#[entry]
fn main() -> ! {
    let status = if run() {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    };
    // Under QEMU (or a debugger with semihosting) this ends the run with `status`.
    debug::exit(status);
    loop {
        cortex_m::asm::wfi();
    }
}

/// One pipeline and what we report about it.
struct Channel {
    name: &'static str,
    pipeline: Pipeline,
    movements: u32,
    outputs: u32,
    last: Option<Output>,
}

impl Channel {
    /// Feeds one input sample with the sensor's temperature; prints movement events as they
    /// are confirmed.
    fn push(&mut self, time_s: f64, rate_dps: f32, temperature_c: f32) {
        // Returns `Some` once per decimation block (every 20th sample: 50 Hz). A NaN
        // temperature (none read yet) leaves the temperature terms as they were.
        let Some(output) = self
            .pipeline
            .push_with_temperature(time_s, rate_dps, temperature_c)
        else {
            return;
        };
        self.outputs += 1;
        match output.event {
            Some(Event::MovementStarted { start_time_s, .. }) => {
                // Confirmed 60 ms or so after it began; the start is back-dated.
                hprintln!(
                    "started  compensation={} index={} start_time_s={} confirmed_at_s={}",
                    self.name,
                    self.movements + 1,
                    start_time_s,
                    output.time_s
                );
            }
            Some(Event::MovementEnded(movement)) => {
                self.movements += 1;
                // On the wrench: this is where the turned angle goes to the tightening logic.
                // A saturated movement's angle is a lower bound: not a tightening to accept.
                hprintln!(
                    "movement compensation={} index={} start_time_s={} end_time_s={} angle_deg={} raw_angle_deg={} saturated={}",
                    self.name,
                    self.movements,
                    movement.start_time_s,
                    movement.end_time_s,
                    movement.angle_deg,
                    movement.raw_angle_deg,
                    u8::from(movement.saturated)
                );
            }
            None => {}
        }
        self.last = Some(output);
    }

    /// Prints the summary line; `true` if the pipeline ran clean.
    fn report(&self, samples: u32) -> bool {
        let (angle_deg, raw_angle_deg) = self
            .last
            .map_or((0.0, 0.0), |o| (o.angle_deg, o.raw_angle_deg));
        let rejected = self.pipeline.rejected_samples();
        let finite = self.pipeline.is_finite();
        hprintln!(
            "summary  compensation={} samples={} outputs={} rejected_samples={} movements={} final_angle_deg={} final_raw_angle_deg={} finite={}",
            self.name,
            samples,
            self.outputs,
            rejected,
            self.movements,
            angle_deg,
            raw_angle_deg,
            finite
        );
        if let Some(std_deg) = self.last.and_then(|o| o.angle_std_deg) {
            hprintln!(
                "         compensation={} final_angle_std_deg={}",
                self.name,
                std_deg
            );
        }
        rejected == 0 && finite && self.movements > 0
    }
}

/// The whole run; `true` if it was clean.
fn run() -> bool {
    // 1 kHz in, 50 Hz out; on the wrench: the calibrated model. The range is the one the
    // driver commands: a movement whose readings reach it is flagged saturated.
    let config = Config {
        range_dps: Some(f32::from(RANGE.full_scale_dps())),
        ..Config::default()
    };
    let mut channels = COMPENSATIONS.map(|(name, compensation)| {
        let config = Config {
            compensation,
            ..config
        };
        Pipeline::try_new(&config).map(|pipeline| Channel {
            name,
            pipeline,
            movements: 0,
            outputs: 0,
            last: None,
        })
    });
    if let Some(Err(error)) = channels.iter().find(|c| c.is_err()) {
        hprintln!("error: pipeline configuration: {}", error);
        return false;
    }

    // On the wrench: `ExclusiveDevice::new(spi, cs, delay)` over the MCU's SPI peripheral in
    // mode 0 at 1 MHz (see playback.rs). Start-up: power the sensor, wait its start-up time;
    // the driver's first read does the priming transfer by itself.
    let sensor = PlaybackSensor::new(
        RATE_WORDS,
        RANGE,
        temperature_c_to_word(25.0),
        DEFAULT_CS_LEAD_NS,
    );
    let samples = sensor.remaining() as u32;
    let mut gyro = Crm100::new(sensor, Settings::new(RANGE)); // CS lead 25 µs, checksum on

    hprintln!(
        "gyro firmware example: CRM100 ({}, playback of {} samples) -> gyro-core at {} Hz in, {} Hz out; pipeline state {} bytes",
        RANGE,
        samples,
        config.sample_rate_hz,
        config.output_rate_hz,
        size_of::<Pipeline>()
    );

    let (mut read_errors, mut status_faults, mut temperature_c) = (0_u32, 0_u32, f32::NAN);
    let mut beyond_full_scale = 0_u32;
    for n in 0..samples {
        // One iteration per sample clock tick. On the wrench a timer fires at 1 kHz and this
        // body runs in its interrupt handler (or in the main loop after `wfi()` wakes on it):
        // a 6-byte SPI frame (~75 µs at 1 MHz with the CS lead time), a few dozen float
        // operations, every 20th sample the 50 Hz step. Here it runs flat out.
        //
        // Time is the sample count over the nominal rate, as the host grid uses: the pipeline
        // integrates with the nominal output period, so time only labels the events.
        let time_s = f64::from(n) / f64::from(config.sample_rate_hz);
        let rate_dps = match gyro.read() {
            Ok(measurement) => {
                status_faults += u32::from(measurement.status.is_fault());
                temperature_c = measurement.temperature_c;
                measurement.rate_dps
            }
            // A rate word beyond full scale: the sensor is saturated. Its reading is the
            // range (a lower bound of the rate), which flags the movement.
            Err(Error::Frame(FrameError::Saturated { counts })) => {
                beyond_full_scale += 1;
                let range_dps = f32::from(RANGE.full_scale_dps());
                if counts < 0 {
                    -range_dps
                } else {
                    range_dps
                }
            }
            Err(error) => {
                // Never skip a tick: a NaN keeps the timing, and the pipeline replaces it by
                // the last valid rate and counts it (`rejected_samples`).
                read_errors += 1;
                if read_errors <= 3 {
                    hprintln!("read error at sample {}: {:?}", n, error);
                }
                f32::NAN
            }
        };
        for channel in channels.iter_mut().flatten() {
            channel.push(time_s, rate_dps, temperature_c);
        }
    }

    let sensor = gyro.release();
    hprintln!(
        "sensor   transactions={} left={} read_errors={} status_faults={} beyond_full_scale={} temperature_c={}",
        sensor.transactions(),
        sensor.remaining(),
        read_errors,
        status_faults,
        beyond_full_scale,
        temperature_c
    );
    let mut clean = read_errors == 0 && status_faults == 0 && sensor.remaining() == 0;
    for channel in channels.iter().flatten() {
        clean &= channel.report(samples);
    }
    hprintln!("result   {}", if clean { "ok" } else { "FAILED" });
    clean
}
