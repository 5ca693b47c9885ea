//! The embedded-hal 1.0 driver against `embedded-hal-mock` SPI transaction expectations.

use crate::common::*;
use crm100_driver::{
    Checks, Crm100, Error, FrameError, PollCommand, Range, ResponseTiming, Settings, Status,
    DEFAULT_CS_LEAD_NS, MODE,
};
use embedded_hal::spi::{ErrorKind, Phase, Polarity};
use embedded_hal_mock::eh1::spi::Mock;

#[test]
fn mode_is_spi_mode_0() {
    assert_eq!(MODE.polarity, Polarity::IdleLow);
    assert_eq!(MODE.phase, Phase::CaptureOnFirstTransition);
    assert_eq!(DEFAULT_CS_LEAD_NS, 25_000);
}

#[test]
fn new_does_not_touch_the_bus_and_release_gives_it_back() {
    let driver = new_driver(&[], Settings::default());
    assert!(!driver.is_started());
    assert_eq!(driver.range(), Range::Dps300);
    destroy(driver);
}

#[test]
fn first_read_primes_then_decodes_the_answer_to_the_priming_command() {
    let c75 = cmd(Range::Dps75.command());
    let expectations = script(vec![
        priming(Range::Dps75),
        frame(c75.clone(), response(0, 960, 600)),
        frame(c75, response(0, -7200, 531)),
    ]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps75));
    let m = driver.read().unwrap();
    assert!(driver.is_started());
    assert_eq!(m.rate_dps, 10.0);
    assert_eq!(m.range, Range::Dps75);
    assert_eq!(m.status, Status(0));
    assert!((m.temperature_c - 69.0 / 2.75).abs() < 1e-6);
    let m = driver.read().unwrap();
    assert_eq!(m.rate_dps, -75.0);
    assert_eq!(m.temperature_c, 0.0);
    destroy(driver);
}

#[test]
fn explicit_start_is_the_priming_transfer() {
    let c = cmd(Range::Dps900.command());
    let expectations = script(vec![priming(Range::Dps900), frame(c, response(0, 8, 600))]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps900));
    driver.start().unwrap();
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    destroy(driver);
}

/// Pipelined: the transfer that carries the new range command still returns a sample in the
/// old range; the next one is in the new range. No sample lost, none mis-scaled.
#[test]
fn set_range_takes_effect_with_the_pipeline() {
    let c75 = cmd(Range::Dps75.command());
    let c900 = cmd(Range::Dps900.command());
    let expectations = script(vec![
        priming(Range::Dps75),
        frame(c75.clone(), response(0, 96, 600)),
        frame(c900.clone(), response(0, 192, 600)), // answers a 0x38: ±75
        frame(c900, response(0, 192, 600)),         // answers the 0x20: ±900
    ]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps75));
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    driver.set_range(Range::Dps900);
    assert_eq!(driver.range(), Range::Dps900);
    let m = driver.read().unwrap();
    assert_eq!((m.rate_dps, m.range), (2.0, Range::Dps75));
    let m = driver.read().unwrap();
    assert_eq!((m.rate_dps, m.range), (24.0, Range::Dps900));
    destroy(driver);
}

/// Immediate: each response is scaled by the range its own transfer selects.
#[test]
fn immediate_timing_scales_by_the_same_transfer_command() {
    let c75 = cmd(Range::Dps75.command());
    let c150 = cmd(Range::Dps150.command());
    let expectations = script(vec![
        priming(Range::Dps75),
        frame(c75, response(0, 96, 600)),
        frame(c150, response(0, 96, 600)),
    ]);
    let settings = Settings::new(Range::Dps75).with_timing(ResponseTiming::Immediate);
    let mut driver = new_driver(&expectations, settings);
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    driver.set_range(Range::Dps150);
    let m = driver.read().unwrap();
    assert_eq!((m.rate_dps, m.range), (2.0, Range::Dps150));
    destroy(driver);
}

/// A fixed poll byte: the range command goes out at start-up and once after `set_range`.
#[test]
fn fixed_poll_command_sends_range_only_when_needed() {
    let poll = cmd(0x00);
    let expectations = script(vec![
        priming(Range::Dps300),
        frame(poll.clone(), response(0, 24, 600)),
        frame(poll.clone(), response(0, 48, 600)),
        frame(cmd(Range::Dps150.command()), response(0, 48, 600)), // answers 0x00: ±300
        frame(poll.clone(), response(0, 48, 600)),                 // answers 0x30: ±150
        frame(poll, response(0, 48, 600)),
    ]);
    let settings = Settings::new(Range::Dps300).with_poll(PollCommand::Fixed(0x00));
    let mut driver = new_driver(&expectations, settings);
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    assert_eq!(driver.read().unwrap().rate_dps, 2.0);
    driver.set_range(Range::Dps150);
    assert_eq!(driver.read().unwrap().rate_dps, 2.0);
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    destroy(driver);
}

#[test]
fn read_raw_returns_bytes_command_and_range_without_judging() {
    let c = cmd(Range::Dps150.command());
    let garbage = vec![0xDE, 0xAD, 0xBE, 0xEF, 0x00, 0x00];
    let expectations = script(vec![priming(Range::Dps150), frame(c, garbage.clone())]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps150));
    let raw = driver.read_raw().unwrap();
    assert_eq!(raw.command, 0x30);
    assert_eq!(raw.response.to_vec(), garbage);
    assert_eq!(raw.range, Range::Dps150);
    destroy(driver);
}

#[test]
fn bad_checksum_is_a_frame_error_and_keeps_the_pipeline() {
    let c = cmd(Range::Dps75.command());
    let mut corrupt = response(0, 96, 600);
    corrupt[2] ^= 0x04;
    let expectations = script(vec![
        priming(Range::Dps75),
        frame(c.clone(), corrupt),
        frame(c, response(0, 96, 600)),
    ]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps75));
    assert!(matches!(
        driver.read(),
        Err(Error::Frame(FrameError::Checksum { .. }))
    ));
    assert!(driver.is_started()); // no re-priming for a bad response
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    destroy(driver);
}

#[test]
fn status_fault_is_flagged_by_default_and_refused_when_strict() {
    let c = cmd(Range::Dps75.command());
    let expectations = script(vec![
        priming(Range::Dps75),
        frame(c.clone(), response(0x81, 96, 600)),
        frame(c, response(0x81, 96, 600)),
    ]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps75));
    let m = driver.read().unwrap();
    assert!(m.status.is_fault());
    assert_eq!(m.status.raw(), 0x81);
    driver.set_checks(Checks::STRICT);
    assert_eq!(
        driver.read(),
        Err(Error::Frame(FrameError::StatusFault(0x81)))
    );
    destroy(driver);
}

#[test]
fn beyond_full_scale_is_refused_by_default() {
    let c = cmd(Range::Dps75.command());
    let expectations = script(vec![
        priming(Range::Dps75),
        frame(c.clone(), response(0, 7201, 600)),
        frame(c, response(0, -7201, 600)),
    ]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps75));
    assert_eq!(
        driver.read(),
        Err(Error::Frame(FrameError::Saturated { counts: 7201 }))
    );
    driver.set_checks(Checks::NONE);
    let m = driver.read().unwrap();
    assert!(m.is_saturated());
    destroy(driver);
}

#[test]
fn zero_cs_lead_omits_the_delay_operation() {
    let c = cmd(Range::Dps75.command());
    let expectations = script(vec![
        frame_with_lead(0, c.clone(), stale()),
        frame_with_lead(0, c, response(0, 0, 600)),
    ]);
    let settings = Settings::new(Range::Dps75).with_cs_lead_ns(0);
    let mut driver = new_driver(&expectations, settings);
    assert_eq!(driver.read().unwrap().rate_dps, 0.0);
    destroy(driver);
}

#[test]
fn exchange_sends_any_command_and_tracks_range_commands() {
    let expectations = script(vec![
        frame(cmd(0x04), response(0, 0, 0)),
        frame(cmd(Range::Dps900.command()), response(0, 0, 0)),
        frame(cmd(Range::Dps75.command()), response(0, 80, 600)),
    ]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps75));
    let rx = driver.exchange(0x04).unwrap();
    assert_eq!(rx.to_vec(), response(0, 0, 0));
    assert!(!driver.is_started()); // 0x04 selects no known range
    driver.exchange(Range::Dps900.command()).unwrap();
    assert!(driver.is_started());
    // Sensor is in ±900 now; the next read answers that command.
    let m = driver.read().unwrap();
    assert_eq!((m.rate_dps, m.range), (10.0, Range::Dps900));
    destroy(driver);
}

#[test]
fn spi_error_is_reported_and_the_next_read_primes_again() {
    let c = cmd(Range::Dps75.command());
    let expectations = script(vec![
        priming(Range::Dps75),                  // transaction 0
        frame(c.clone(), response(0, 96, 600)), // 1
        // 2 fails before reaching the mock
        priming(Range::Dps75), // 3: the pipeline is unknown, prime again
        frame(c, response(0, 192, 600)), // 4
    ]);
    let mut driver = Crm100::new(
        Flaky::new(Mock::new(&expectations), vec![2]),
        Settings::new(Range::Dps75),
    );
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    assert_eq!(driver.read(), Err(Error::Comm(ErrorKind::Other)));
    assert!(!driver.is_started());
    assert_eq!(driver.read().unwrap().rate_dps, 2.0);
    driver.release().inner.done();
}

#[test]
fn failed_priming_transfer_is_reported_and_retried() {
    let c = cmd(Range::Dps75.command());
    let expectations = script(vec![
        // 0 fails
        priming(Range::Dps75),          // 1
        frame(c, response(0, 96, 600)), // 2
    ]);
    let mut driver = Crm100::new(
        Flaky::new(Mock::new(&expectations), vec![0]),
        Settings::new(Range::Dps75),
    );
    assert_eq!(driver.read(), Err(Error::Comm(ErrorKind::Other)));
    assert!(!driver.is_started());
    assert_eq!(driver.read().unwrap().rate_dps, 1.0);
    driver.release().inner.done();
}

#[test]
fn resync_primes_again_after_a_hardware_reset() {
    let c = cmd(Range::Dps75.command());
    let expectations = script(vec![
        priming(Range::Dps75),
        frame(c.clone(), response(0, 96, 600)),
        priming(Range::Dps75),
        frame(c, response(0, 96, 600)),
    ]);
    let mut driver = new_driver(&expectations, Settings::new(Range::Dps75));
    driver.read().unwrap();
    driver.resync();
    assert!(!driver.is_started());
    driver.read().unwrap();
    destroy(driver);
}

#[test]
fn driver_errors_display() {
    let comm: Error<ErrorKind> = Error::Comm(ErrorKind::Other);
    let frame: Error<ErrorKind> = FrameError::StatusFault(1).into();
    assert!(comm.to_string().contains("SPI"));
    assert!(frame.to_string().contains("status"));
    let as_error: &dyn core::error::Error = &frame;
    assert!(as_error.source().is_some());
}
