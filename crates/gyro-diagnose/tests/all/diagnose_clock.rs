//! A sensor clock percents off its nominal rate, its rows stamped by its own sample count
//! (the common case for a MEMS gyro with an internal oscillator, specified to ±1–3%): the
//! lag behind the reference grows through the run to a second and more. The diagnosis
//! names the clock first, its interval covers it, nothing of the look-alikes (a latency,
//! a scale) is named, and the model it writes takes the held-out angle error from tens of
//! degrees to a fraction of one.
//!
//! The self-test's runs (5 + 5 simulated CRM100 bench runs of 60 s, `case_runs`) with the
//! clock at −2.5% and +2%, development seeds 71 and 72.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_diagnose::selftest::case_runs;
use gyro_diagnose::{diagnose, Options, Silent};
use gyro_sim::Effect;

fn check(ppm: f64, seed: u64) -> gyro_diagnose::Diagnosis {
    let (train, holdout) = case_runs(&[Effect::ClockErrorCountStamped { ppm }], seed);
    // Small ensembles keep it quick (the self-test's are 50 and 20 members).
    let options = Options {
        seed,
        members: 12,
        candidate_members: 6,
        bootstrap: 300,
        ..Options::default()
    };
    let d = diagnose(&train, &holdout, &options, &Silent).unwrap();
    let named: Vec<&str> = d
        .effects
        .iter()
        .filter(|e| e.significant)
        .map(|e| e.id)
        .collect();
    assert_eq!(
        named.first(),
        Some(&"clock_error_count_stamped"),
        "{ppm}: {named:?}"
    );
    for look_alike in ["latency", "bandwidth", "scale_factor", "temperature_scale"] {
        assert!(!named.contains(&look_alike), "{ppm}: {named:?}");
    }
    let clock = &d.effects[0];
    let [lo, hi] = clock.ci95["ppm"];
    assert!(
        lo.unwrap() <= ppm && ppm <= hi.unwrap(),
        "{ppm}: {:?}",
        clock.ci95
    );
    let c = d.compensation.as_ref().unwrap();
    assert!(c.corrected.contains(&"clock_error_count_stamped"), "{c:?}");
    let median = |f: &dyn Fn(&gyro_diagnose::CompensationRun) -> f64| {
        let mut v: Vec<f64> = c.runs.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let before = median(&|r| r.max_abs_error_before_deg);
    let after = median(&|r| r.max_abs_error_after_deg);
    assert!(
        before > 10.0 && after < 1.0,
        "{ppm}: {before} -> {after} deg; {:?} {:?}",
        c.runs,
        d.effects
            .iter()
            .filter(|e| e.significant)
            .map(|e| (e.id, &e.params))
            .collect::<Vec<_>>()
    );
    let model = d.corrected_model.as_ref().unwrap();
    assert!(
        (model.count_clock_ppm - clock.params["ppm"]).abs() < 1e-6,
        "{model:?}"
    );
    d
}

#[test]
fn a_slow_clock_of_2_5_percent_is_named_and_corrected() {
    let d = check(-25_000.0, 71);
    // Its rows past the reference's end left out, the kept ones re-simulated from the whole
    // run's motion, as their gyro read it: held-out G 14.8 (715 nominal); from the kept
    // rows' reference alone, 72.5.
    assert!(d.gap.holdout_after < 30.0, "{:?}", d.gap);
}

#[test]
fn a_fast_clock_of_2_percent_is_named_and_corrected() {
    check(20_000.0, 72);
}
