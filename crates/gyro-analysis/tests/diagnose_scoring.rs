//! Only the fits whose parameter test passes on the training runs are scored on the
//! held-out runs (one candidate ensemble each); scoring every fit
//! (`Options::score_every_candidate`) adds the others' held-out figures and changes no
//! decision: a fit whose test does not pass can never be named.
//!
//! The self-test's random-walk case, as in `diagnose_wander.rs`, with small ensembles.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::diagnose::selftest::{case_runs, magnitudes};
use gyro_analysis::diagnose::{diagnose, Options, Silent};
use gyro_analysis::seed::derive_seed;

#[test]
fn scoring_every_candidate_changes_no_decision() {
    let magnitudes = magnitudes();
    let k = magnitudes
        .iter()
        .position(|e| e.id() == "rate_random_walk")
        .unwrap();
    let case_seed = derive_seed(104, "self-test case", k as u64);
    let (train, holdout) = case_runs(&[magnitudes[k]], case_seed);
    let options = Options {
        seed: derive_seed(case_seed, "diagnosis", 0),
        members: 12,
        candidate_members: 6,
        bootstrap: 300,
        ..Options::default()
    };
    let gated = diagnose(&train, &holdout, &options, &Silent).unwrap();
    let every = Options {
        score_every_candidate: true,
        ..options
    };
    let all = diagnose(&train, &holdout, &every, &Silent).unwrap();

    assert_eq!(gated.verdict, all.verdict);
    assert_eq!(gated.gap, all.gap);
    assert_eq!(gated.model, all.model);
    assert_eq!(gated.compensation, all.compensation);
    assert_eq!(gated.unexplained, all.unexplained);
    let passes = |t: &str| !t.ends_with("does not pass");
    let mut unscored = 0;
    for e in &gated.effects {
        let a = all.effects.iter().find(|a| a.id == e.id).unwrap();
        assert_eq!(e.params, a.params, "{}", e.id);
        assert_eq!(e.test, a.test, "{}", e.id);
        assert!(
            a.delta_bic.is_some() && a.fraction_closed.is_some(),
            "{a:?}"
        );
        if passes(&e.test) {
            // Scored the same way, on the same seeds.
            assert_eq!(e, a);
        } else {
            unscored += 1;
            assert!(!e.significant, "{e:?}");
            for field in [
                e.delta_bic,
                e.holdout_gap_after,
                e.fraction_closed,
                e.bootstrap_p,
            ] {
                assert!(field.is_none(), "{e:?}");
            }
            assert!(e.posterior_check.is_none(), "{e:?}");
            assert_eq!(e.holdout_gap_before, a.holdout_gap_before, "{}", e.id);
        }
    }
    // The case leaves most of the vocabulary's tests short of passing.
    assert!(
        unscored >= 5,
        "{unscored} unscored of {}",
        gated.effects.len()
    );
}
