//! `diagnose` on runs that never rest, made by a generator that is not the project's own
//! (`fixtures/diagnose/make_foreign_runs.py`, numpy): a gyro with a 12 ms latency, a +0.6%
//! scale error, a 0.3 deg/s bias and white noise of 3.0 deg/√h (ten times the CRM100
//! prior's), on continuous back-and-forth motion; trained on four 60 s windows, held out on
//! four of motion twice as fast.
//!
//! Without a rest the baseline's white noise comes from the training runs' moving
//! residual: it must be the generator's, the injected effects must be named with intervals
//! covering them, nothing else named, the written model must not make the held-out angles
//! worse, and the held-out gap must close. Two more cases from the same generator: a
//! nonlinearity of even order (gyro = rate + 2e-5 rate²), and rows stamped by the
//! sensor's own sample count (its clock 500 ppm fast: the lag grows over each window; and
//! 1.5% fast, a lag of up to 0.9 s).
//! And one with rests: a gyro whose digital low-pass filters its noise as well as the
//! rate (the rests' noise coloured), at the noise of the other cases and at the CRM100's.
//! Small ensembles keep it quick.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_diagnose::{diagnose, split, Options, RealRun, Silent};
use gyro_log::{load, GridOptions, LogOptions};
use std::path::PathBuf;

fn windows(name: &str) -> Vec<RealRun> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/diagnose")
        .join(name);
    let log = load(
        &path,
        &LogOptions::default(),
        &GridOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    split(&log, 60.0)
        .into_iter()
        .enumerate()
        .map(|(i, w)| RealRun::prepare(format!("{name}#{}", i + 1), w).unwrap())
        .collect()
}

fn quick() -> Options {
    Options {
        members: 12,
        candidate_members: 6,
        bootstrap: 300,
        ..Options::default()
    }
}

/// The diagnosis trained on `train` and held out on `holdout` (fixture files).
fn diagnosed(train: &str, holdout: &str) -> gyro_diagnose::Diagnosis {
    let (train, holdout) = (windows(train), windows(holdout));
    assert_eq!((train.len(), holdout.len()), (4, 4));
    diagnose(&train, &holdout, &quick(), &Silent).unwrap()
}

/// The effect `id`'s 95% interval of `key` holds `truth`.
fn covers(d: &gyro_diagnose::Diagnosis, id: &str, key: &str, truth: f64) {
    let e = d.effects.iter().find(|e| e.id == id).unwrap();
    let [lo, hi] = e.ci95[key];
    assert!(
        lo.unwrap() <= truth && truth <= hi.unwrap(),
        "{id}: {:?} {:?}",
        e.params,
        e.ci95
    );
}

#[test]
fn a_moving_sensor_from_another_generator_gets_its_own_noise_and_effects() {
    let d = diagnosed("foreign_train.csv", "foreign_holdout.csv");

    // The baseline's white noise is the generator's 3.0 deg/√h, measured on the moving
    // residual (the CRM100 prior's 0.28 would be ten times too small), and says so.
    let arw = d.model.sensor.arw_deg_per_rt_h;
    assert!((2.7..3.4).contains(&arw), "{arw} deg/sqrt(h)");
    let notes = d.model.notes.join("\n");
    assert!(notes.contains("fitted to the moving residual"), "{notes}");
    assert!((d.model.sensor.bias_dps - 0.3).abs() < 0.03, "{notes}");

    // The injected effects, named, their intervals covering the truth; nothing else.
    let mut named = d.verdict.unmodelled.clone();
    named.sort_unstable();
    assert_eq!(named, ["latency", "scale_factor"]);
    covers(&d, "latency", "delay_s", 0.012);
    covers(&d, "scale_factor", "k", 0.006);

    // Most of the held-out gap closes, and what is written does not hurt.
    assert!(d.verdict.fraction_closed_holdout > 0.8, "{:?}", d.verdict);
    let c = d.compensation.as_ref().unwrap();
    assert!(c.corrected.contains(&"latency"), "{:?}", c.corrected);
    let total =
        |f: &dyn Fn(&gyro_diagnose::CompensationRun) -> f64| -> f64 { c.runs.iter().map(f).sum() };
    let (before, after) = (
        total(&|r| r.max_abs_error_before_deg),
        total(&|r| r.max_abs_error_after_deg),
    );
    assert!(after < before, "{before} -> {after}");
}

/// Rows stamped by the sensor's count, its clock 500 ppm fast: the count-stamped clock is
/// named with an interval covering it, and nothing else: no latency for the mean of the
/// growing lag, nor one that takes up the clock's fitting error (an effect whose interval,
/// refitted beside the others, holds its absence is left out).
#[test]
fn a_count_stamped_clock_from_another_generator_is_named_alone() {
    let d = diagnosed("count_train.csv", "count_holdout.csv");
    assert_eq!(d.verdict.unmodelled, ["clock_error_count_stamped"]);
    covers(&d, "clock_error_count_stamped", "ppm", 500.0);
    assert!(d.verdict.fraction_closed_holdout > 0.9, "{:?}", d.verdict);
}

/// The same clock 1.5% fast: the lag grows to 0.9 s over each window. These runs never
/// rest, so their white noise is read from the moving residual, which holds the rate times
/// that lag (about 360 deg/√h read as it stands): the clock, established from the lag lines
/// first, is taken out of it, and the baseline gets the generator's 3.0 deg/√h. The clock
/// is named alone, its interval covering 1.5%, and the selected model explains the runs.
#[test]
fn a_grown_count_stamped_clock_on_runs_that_never_rest_keeps_their_white_noise() {
    let d = diagnosed("grown_train.csv", "grown_holdout.csv");
    assert_eq!(d.verdict.unmodelled, ["clock_error_count_stamped"]);
    covers(&d, "clock_error_count_stamped", "ppm", 15_000.0);
    let arw = d.model.sensor.arw_deg_per_rt_h;
    assert!(
        (2.5..3.6).contains(&arw),
        "white noise {arw} deg/√h for 3.0"
    );
    assert!(d.verdict.model_fits, "{:?}", d.unexplained);
}

/// An even nonlinearity (gyro = rate + 2e-5 rate²): trained on the faster windows, the
/// rate² regression finds it (z ≥ 4, the interval covering 2e-5) and the simulation with
/// it reproduces the curvature the slower held-out windows show; it is not read as a scale
/// asymmetry (an odd, |rate| term), and nothing else is named. Whether it is named sits
/// at the edge of the held-out evidence: at `diagnose`'s default ensemble sizes it is
/// (bootstrap P 0.046; 0.13 while the re-simulation took the reference's two-decimal
/// rounding into its rate), at this test's smaller ones it is not. Trained on the slower
/// windows its z is under 4.
#[test]
fn an_even_nonlinearity_from_another_generator_is_fitted_as_even() {
    let d = diagnosed("even_holdout.csv", "even_train.csv");
    let e = d
        .effects
        .iter()
        .find(|e| e.id == "nonlinearity_even")
        .unwrap();
    assert!(e.z.is_some_and(|z| z >= 4.0), "{e:?}");
    covers(&d, "nonlinearity_even", "k2_per_dps", 2e-5);
    assert!(e.posterior_check.as_ref().unwrap().passes, "{e:?}");
    assert!(
        d.verdict
            .unmodelled
            .iter()
            .all(|id| *id == "nonlinearity_even"),
        "{:?}",
        d.verdict
    );
}

/// A MEMS gyro whose digital low-pass (a causal second-order Butterworth at 20 Hz on
/// 100 Hz samples, as an MPU6050's DLPF) filters rate, bias and noise alike, on a
/// wrench's rest–turn–rest motion. The rests' noise is coloured: their first differences
/// read under half of the 3.0 deg/√h the angle integrates, the whiteness check says so and
/// the baseline's white noise is the 0.05 s blocks' (within 15% of the truth, from the
/// low band the filter leaves alone). The filter's lag (9.74 ms at low frequency, scipy's
/// group delay) is named as a bandwidth near 20 Hz, not as its look-alike latency (the
/// rests' colour tells them apart), and nothing else; what stays unexplained is the rests'
/// colour (the simulated noise stays white) and the shape of the dynamic response, which
/// the residual's jerk coefficient, lag-1 autocorrelation and slope on the rate show
/// (the Butterworth is not the critically damped two poles); the written model does not make the held-out angles worse.
#[test]
fn a_low_passed_gyro_with_rests_gets_its_low_band_noise_and_its_lag() {
    let d = diagnosed("dlpf_train.csv", "dlpf_holdout.csv");
    let w = d.model.rest_noise.clone().unwrap();
    assert!(w.coloured && w.z > 4.0, "{w:?}");
    assert!(w.first_difference_arw_deg_per_rt_h < 1.5, "{w:?}");
    assert!((2.55..3.45).contains(&w.block_arw_deg_per_rt_h), "{w:?}");
    assert_eq!(d.model.sensor.arw_deg_per_rt_h, w.block_arw_deg_per_rt_h);
    let notes = d.model.notes.join("\n");
    assert!(notes.contains("the rest noise is not white"), "{notes}");
    assert!(
        d.warnings
            .iter()
            .any(|w| w.contains("rests' noise is not white")),
        "{:?}",
        d.warnings
    );

    // A low-pass colours the noise it delays: the rests point to `bandwidth`, not to a
    // pure latency, and its cutoff lies near the Butterworth's (the critically damped
    // two poles are not its shape, so not on it).
    assert_eq!(d.verdict.unmodelled, ["bandwidth"], "{:?}", d.verdict);
    let bandwidth = d.effects.iter().find(|e| e.id == "bandwidth").unwrap();
    let cutoff_hz = bandwidth.params["cutoff_hz"];
    assert!((17.0..23.0).contains(&cutoff_hz), "{cutoff_hz}");
    // The response's shape: the Butterworth's jerk term and its gain at the motion's
    // frequencies are not the critically damped two poles'; the noise's 1 s band is the
    // rests' colour again (the simulated noise stays white).
    let response_shape = ["regression_jerk", "lag1_autocorrelation", "slope_vs_rate"];
    assert!(
        d.unexplained.iter().all(|u| u.segment.starts_with("static")
            || (u.segment == "all" && u.statistic == "wander_log10_avar_1s")
            || (u.segment.starts_with("dynamic")
                && response_shape.contains(&u.statistic.as_str()))),
        "{:?}",
        d.unexplained
            .iter()
            .map(|u| (&u.segment, &u.statistic))
            .collect::<Vec<_>>()
    );

    let c = d.compensation.as_ref().unwrap();
    assert!(
        c.runs
            .iter()
            .all(|r| r.max_abs_error_after_deg <= r.max_abs_error_before_deg),
        "{:?}",
        c.runs
    );
}

#[test]
fn a_quiet_low_passed_gyro_keeps_the_bandwidth_its_rests_point_to() {
    // At the CRM100's noise a 10 Hz Butterworth's lag is read so precisely that a
    // `latency` wins the held-out ΔBIC; the rests' coloured noise chooses the `bandwidth`,
    // and no later swap brings the latency in beside it (one delay per model).
    let d = diagnosed("quiet_dlpf_train.csv", "quiet_dlpf_holdout.csv");
    let w = d.model.rest_noise.clone().unwrap();
    assert!(w.coloured && w.z > 4.0, "{w:?}");
    assert_eq!(d.verdict.unmodelled, ["bandwidth"], "{:?}", d.verdict);
}
