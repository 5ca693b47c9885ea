//! A rate random walk is named on the evidence of its own test replicated on the
//! held-out runs, and its posterior check reads the fitted parameter's interval.
//!
//! The self-test's random-walk case (0.02 °/s/√s over 5 + 5 simulated CRM100 bench runs of
//! 60 s), as `gyro-cli diagnose --self-test --seed 104 --only rate_random_walk` runs it.
//! A random walk is one draw per run: the held-out likelihood rests on the one or two runs
//! that wandered most (with the self-test's ensembles, `bootstrap_p` 0.06 here, and
//! without the wander's held-out test `bias_instability` is named instead), and the runs
//! that wandered less than the fitted value predicts would fail a check made with that
//! value alone. The Allan-variance excess of the held-out runs replicates the training
//! test.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::seed::derive_seed;
use gyro_diagnose::selftest::{case_runs, magnitudes};
use gyro_diagnose::{diagnose, Options, Silent};

#[test]
fn a_random_walk_is_named_on_its_replicated_allan_excess() {
    let magnitudes = magnitudes();
    let k = magnitudes
        .iter()
        .position(|e| e.id() == "rate_random_walk")
        .unwrap();
    let truth = magnitudes[k];
    let case_seed = derive_seed(104, "self-test case", k as u64);
    let (train, holdout) = case_runs(&[truth], case_seed);
    // Small ensembles keep it quick (the self-test's are 50 and 20 members).
    let options = Options {
        seed: derive_seed(case_seed, "diagnosis", 0),
        members: 12,
        candidate_members: 6,
        bootstrap: 300,
        ..Options::default()
    };
    let d = diagnose(&train, &holdout, &options, &Silent).unwrap();
    let walk = d
        .effects
        .iter()
        .find(|e| e.id == "rate_random_walk")
        .unwrap();
    let holdout_z = walk.holdout_z.unwrap();
    assert!(holdout_z >= 2.0, "held-out z {holdout_z}");
    assert!(walk.z.is_some_and(|z| z >= 4.0), "z {:?}", walk.z);
    assert!(walk.significant, "{walk:?}");
    assert_eq!(d.verdict.unmodelled, vec!["rate_random_walk"]);
    let [lo, hi] = walk.ci95["k_dps_per_rt_s"];
    assert!(
        lo.unwrap() <= 0.02 && 0.02 <= hi.unwrap(),
        "{:?}",
        walk.ci95
    );
    let check = walk.posterior_check.as_ref().unwrap();
    assert!(check.passes, "{check:?}");
}
