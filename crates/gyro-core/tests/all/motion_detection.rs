//! Motion detection on bench-like synthetic runs: rests of 3–15 s, 90° swings of 0.8–4 s
//! with smooth rate profiles, CRM100-like rest noise and bias, fixed seeds.

use crate::common::{run, BenchSpec, Profile, Rng};
use gyro_core::{Compensation, Config, MotionState};

/// Largest errors seen over some runs.
#[derive(Debug, Default)]
struct Errors {
    runs: usize,
    movements: usize,
    /// Detected minus true start / end (s): most negative and most positive.
    start_s: (f64, f64),
    end_s: (f64, f64),
    /// |movement angle − true angle| with the measured bias's share taken out (deg).
    angle_deg: f64,
}

/// One 90 s run at 1 kHz with a constant `bias_dps` and white noise `noise_dps` rms.
fn check_run(seed: u64, bias_dps: f64, noise_dps: f64, errors: &mut Errors) {
    let mut rng = Rng::new(seed);
    let profile = Profile::bench(&mut rng, &BenchSpec::default());
    let samples = profile.samples(1000.0, bias_dps, noise_dps, &mut rng);
    let config = Config {
        compensation: Compensation::None,
        ..Config::default()
    };
    let run = run(&config, &samples, 1000.0);
    let context = format!("seed {seed}, bias {bias_dps:.3} deg/s, noise {noise_dps:.3} deg/s");

    // Every movement found, and nothing else: no chatter.
    assert_eq!(run.starts.len(), profile.swings.len(), "{context}");
    assert_eq!(run.movements.len(), profile.swings.len(), "{context}");
    for (((_, start_time_s), (_, movement)), swing) in
        run.starts.iter().zip(&run.movements).zip(&profile.swings)
    {
        assert_eq!(*start_time_s, movement.start_time_s);
        let start_error_s = movement.start_time_s - swing.start_s;
        let end_error_s = movement.end_time_s - swing.end_s();
        assert!(
            start_error_s.abs() <= 0.060 && end_error_s.abs() <= 0.060,
            "{context}: swing {swing:?}: start {start_error_s:+.3} s, end {end_error_s:+.3} s"
        );
        // The raw angle also integrates the bias over the movement; what is left is the
        // error of detection, filtering and integration.
        let duration_s = movement.end_time_s - movement.start_time_s;
        let angle_error_deg =
            f64::from(movement.raw_angle_deg) - bias_dps * duration_s - swing.angle_deg;
        assert!(
            angle_error_deg.abs() < 0.05,
            "{context}: swing {swing:?}: angle error {angle_error_deg:+.4}°"
        );
        errors.start_s.0 = errors.start_s.0.min(start_error_s);
        errors.start_s.1 = errors.start_s.1.max(start_error_s);
        errors.end_s.0 = errors.end_s.0.min(end_error_s);
        errors.end_s.1 = errors.end_s.1.max(end_error_s);
        errors.angle_deg = errors.angle_deg.max(angle_error_deg.abs());
        errors.movements += 1;
    }

    // Static throughout every rest (away from the swings' ends by the dwell times and the
    // filter's settling), dynamic in the middle of every swing.
    let delay_s = run.pipeline.filter_delay_s();
    for out in &run.outputs {
        let t = out.time_s - delay_s;
        let near_swing = profile
            .swings
            .iter()
            .any(|s| t > s.start_s - 0.1 && t < s.end_s() + 0.5);
        let inside_swing = profile
            .swings
            .iter()
            .any(|s| t > s.start_s + 0.2 * s.duration_s && t < s.end_s() - 0.2 * s.duration_s);
        if !near_swing && t > 0.5 {
            assert_eq!(out.motion, MotionState::Static, "{context}: t = {t:.3} s");
        }
        if inside_swing {
            assert_eq!(out.motion, MotionState::Dynamic, "{context}: t = {t:.3} s");
        }
    }
    errors.runs += 1;
}

#[test]
fn bench_runs_with_crm100_noise() {
    let mut errors = Errors::default();
    let mut rng = Rng::new(0x5EED);
    for seed in 0..12 {
        let bias_dps = rng.range(-1.0, 1.0);
        let noise_dps = rng.range(0.05, 0.1);
        check_run(seed, bias_dps, noise_dps, &mut errors);
    }
    eprintln!("{errors:?}");
}

/// The bias at the ends of its range, before any rest has measured it: the detector must
/// not take it for a movement (which, never quiet again, would never end).
#[test]
fn bench_runs_with_extreme_bias() {
    let mut errors = Errors::default();
    for (seed, bias_dps) in [(100, 1.0), (101, -1.0), (102, 1.5), (103, -1.5)] {
        check_run(seed, bias_dps, 0.1, &mut errors);
    }
    eprintln!("{errors:?}");
}

/// Without noise or bias, the only errors are those of the method.
#[test]
fn bench_runs_noise_free() {
    let mut errors = Errors::default();
    for seed in 200..204 {
        check_run(seed, 0.0, 0.0, &mut errors);
    }
    eprintln!("{errors:?}");
}
