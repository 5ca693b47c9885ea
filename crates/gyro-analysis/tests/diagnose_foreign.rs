//! `diagnose` on runs that never rest, made by a generator that is not the project's own
//! (`fixtures/diagnose/make_foreign_runs.py`, numpy): a gyro with a 12 ms latency, a +0.6%
//! scale error, a 0.3 deg/s bias and white noise of 3.0 deg/√h (ten times the CRM100
//! prior's), on continuous back-and-forth motion; trained on four 60 s windows, held out on
//! four of motion twice as fast.
//!
//! Without a rest the baseline's white noise comes from the training runs' moving
//! residual: it must be the generator's, the injected effects must be named with intervals
//! covering them, nothing else named, the written model must not make the held-out angles
//! worse, and the held-out gap must close. Small ensembles keep it quick.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::diagnose::{diagnose, split, Options, RealRun, Silent};
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

#[test]
fn a_moving_sensor_from_another_generator_gets_its_own_noise_and_effects() {
    let (train, holdout) = (windows("foreign_train.csv"), windows("foreign_holdout.csv"));
    assert_eq!((train.len(), holdout.len()), (4, 4));
    let options = Options {
        members: 12,
        candidate_members: 6,
        bootstrap: 300,
        ..Options::default()
    };
    let d = diagnose(&train, &holdout, &options, &Silent).unwrap();

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
    let covers = |id: &str, key: &str, truth: f64| {
        let e = d.effects.iter().find(|e| e.id == id).unwrap();
        let [lo, hi] = e.ci95[key];
        assert!(
            lo.unwrap() <= truth && truth <= hi.unwrap(),
            "{id}: {:?} {:?}",
            e.params,
            e.ci95
        );
    };
    covers("latency", "delay_s", 0.012);
    covers("scale_factor", "k", 0.006);

    // Most of the held-out gap closes, and what is written does not hurt.
    assert!(d.verdict.fraction_closed_holdout > 0.8, "{:?}", d.verdict);
    let c = d.compensation.as_ref().unwrap();
    assert!(c.corrected.contains(&"latency"), "{:?}", c.corrected);
    let total = |f: &dyn Fn(&gyro_analysis::diagnose::CompensationRun) -> f64| -> f64 {
        c.runs.iter().map(f).sum()
    };
    let (before, after) = (
        total(&|r| r.max_abs_error_before_deg),
        total(&|r| r.max_abs_error_after_deg),
    );
    assert!(after < before, "{before} -> {after}");
}
