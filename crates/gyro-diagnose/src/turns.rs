//! Turn-level evidence, for runs that rest, turn and rest again (a wrench, a robot, a
//! turntable): what the per-sample statistics cannot see when the reference is a pose
//! reported late and coarsely, or when the board's other axes turn.
//!
//! The per-sample residual of gyro minus reference rate is only as good as the reference's
//! timing: a pose sent over its own path 100 ms behind the gyro, at 15 Hz, makes every
//! turn's residual the rate times the lag, far beyond the first-order regressors and the
//! ±50 ms cross-correlation statistic. The totals of each movement, read where both are
//! still (the middle of the rests around it, [`scale::rest_to_rest`]), do not depend on
//! the reference's timing at all. From them, on top of the model the diagnosis wrote:
//! - **lag**: each run's gyro–reference cross-correlation peak searched within
//!   ±[`gyro_analysis::lag::SEARCH_S`] ([`gyro_analysis::lag::log_lag_s`]), median over the training runs;
//! - **scale**: the least-squares slope of the training turns' errors on their reference
//!   turns ([`scale::fit`]), named when it is `tests.z_critical` ([`crate::Settings`]) standard errors from zero, at
//!   least `turns.min_k`, and the held-out runs' own turns show it too (their slope, before
//!   and after the correction: at most half of it left);
//! - **untracked**: movements the gyro makes and the reference does not follow (a turn
//!   about another axis seen through a mount off the reference's axes, or motion the
//!   reference misses): no effect of the vocabulary expresses them, so they are listed.
//!
//! A scale is written into the model file only if it lowers the held-out turns' RMS error,
//! paired over the held-out runs (bootstrap P < `tests.p_value` ([`crate::Settings`])); a lag beyond the
//! per-sample statistic's reach only if, as the model's `reference_delay_s`, it lowers the
//! held-out runs' max abs angle error alike.

use super::compensate::{max_abs_errors, paired_gains};
use super::ensemble::RealRun;
use super::fit::t95;
use super::score::bootstrap_p;
use gyro_analysis::calibrate::scale::{self, MovementTotal};
use gyro_analysis::model::ModelFile;
use gyro_analysis::replay::{replay_with, ReplayOptions, RunReport};
use rayon::prelude::*;
use serde::Serialize;

/// The rule for a movement the reference does not follow is `run`'s too: one home.
pub use gyro_analysis::findings::{not_followed, UNTRACKED_FRACTION, UNTRACKED_MIN_DEG};

/// The turn-level evidence of a diagnosis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TurnEvidence {
    /// Turns (reference turns of at least [`scale::MIN_TURN_DEG`], rest to rest) in the
    /// training runs.
    pub train_turns: usize,
    /// The same in the held-out runs.
    pub holdout_turns: usize,
    /// The gyro–reference lag searched wide.
    pub lag: Option<WideLag>,
    /// The scale the turns show.
    pub scale: Option<TurnScale>,
    /// Movements the reference does not follow, training and held-out runs.
    pub untracked: Vec<Untracked>,
}

/// The gyro's lag behind the reference, each run's cross-correlation peak within
/// ±[`gyro_analysis::lag::SEARCH_S`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WideLag {
    /// Median over the training runs (s; positive: the gyro lags).
    pub median_s: f64,
    /// Smallest and largest over the training runs (s).
    pub train_range_s: (f64, f64),
    /// Median over the held-out runs (s), if any has a peak.
    pub holdout_median_s: Option<f64>,
    /// The lag lies beyond the per-sample statistic's search (±`statistics.max_lag_s`): the
    /// `latency` and `bandwidth` effects cannot be fitted or checked on it.
    pub beyond_statistic: bool,
    /// Median over the held-out runs of the max abs angle error without and with the lag
    /// as the model's `reference_delay_s` (deg), when it was tried.
    pub holdout_max_abs_error_deg: Option<(f64, f64)>,
    /// Bootstrap P over held-out runs of no improvement, when it was tried.
    pub bootstrap_p: Option<f64>,
    /// Written as the model's `reference_delay_s`.
    pub written: bool,
}

/// The scale the turns show, rest to rest.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TurnScale {
    /// Scale error fitted on the training turns on top of the model's (1 = 100%; the
    /// gyro reads `(1 + k)` times the reference's turn).
    pub k: f64,
    /// Its standard error from the turns' scatter about the line.
    pub standard_error: f64,
    /// 95% interval (Student's t on the turns less one).
    pub ci95: (f64, f64),
    /// k over its standard error.
    pub z: f64,
    /// The held-out turns' own slope (the same fit on them), without and with the
    /// correction: what the check reads.
    pub holdout_k: (f64, f64),
    /// RMS error of the held-out turns without and with the correction (deg).
    pub holdout_turn_rms_deg: (f64, f64),
    /// Held-out runs with turns whose turn RMS is lower with it, of those runs.
    pub holdout_runs_better: (usize, usize),
    /// Bootstrap P over held-out runs that the correction does not lower their turn RMS.
    pub bootstrap_p: f64,
    /// Named: `|z| ≥ tests.z_critical`, `|k| ≥` `turns.min_k`, and the held-out turns keep at
    /// most half of their slope with it.
    pub named: bool,
    /// Written into the model file's `config.correction.scale_k`: named, and it lowers
    /// the held-out turns' RMS (bootstrap P < `tests.p_value` ([`crate::Settings`])).
    pub written: bool,
}

/// A movement the reference does not follow.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Untracked {
    /// Run name.
    pub run: String,
    /// The gyro's angle over the movement, rest to rest (deg).
    pub gyro_deg: f64,
    /// The reference's (deg).
    pub reference_deg: f64,
}

/// Each run's movements, rest to rest, replayed with `model` (empty when a run cannot be
/// replayed).
fn totals(runs: &[RealRun], model: &ModelFile) -> Vec<Vec<MovementTotal>> {
    runs.par_iter()
        .map(|run| {
            replay(run, model)
                .map(|r| scale::rest_to_rest(&r))
                .unwrap_or_default()
        })
        .collect()
}

fn replay(run: &RealRun, model: &ModelFile) -> Option<RunReport> {
    replay_with(&run.log, &model.config, &ReplayOptions::from_model(model)).ok()
}

/// The finite median of `values`, if any.
fn median(values: &[f64]) -> Option<f64> {
    Some(super::compensate::median(values)).filter(|m| m.is_finite())
}

/// The turn evidence of `train` against `holdout`, on top of `model` (the model the
/// diagnosis writes, or its starting one). Returns the evidence (`None` when the
/// training runs have no turn and no lag) and the model with what it writes, if it
/// writes anything.
pub(crate) fn turn_evidence(
    train: &[RealRun],
    train_lags_s: &[f64],
    growing: bool,
    holdout: &[RealRun],
    model: &ModelFile,
    options: &super::Options,
) -> (Option<TurnEvidence>, Option<ModelFile>) {
    let mut written = model.clone();
    let mut changed = false;

    let lag = wide_lag(
        train_lags_s,
        growing,
        holdout,
        &mut written,
        &mut changed,
        options,
    );

    // The totals with the model as it stands after the lag (read at mid-rest, they barely
    // depend on it, but every figure below is then of one model).
    let train_totals = totals(train, &written);
    let holdout_totals = totals(holdout, &written);
    let train_turns: usize = train_totals.iter().map(|t| scale::turns(t)).sum();
    let holdout_turns: usize = holdout_totals.iter().map(|t| scale::turns(t)).sum();

    let scale = (train_turns >= 2 && holdout_turns >= 1)
        .then(|| {
            let all: Vec<MovementTotal> = train_totals.iter().flatten().copied().collect();
            turn_scale(&all, holdout, &holdout_totals, &mut written, options)
        })
        .flatten();
    if scale.as_ref().is_some_and(|s| s.written) {
        changed = true;
    }

    let untracked = untracked(train, &train_totals)
        .chain(untracked(holdout, &holdout_totals))
        .collect();

    if train_turns == 0 && lag.is_none() {
        return (None, None);
    }
    let evidence = TurnEvidence {
        train_turns,
        holdout_turns,
        lag,
        scale,
        untracked,
    };
    (Some(evidence), changed.then_some(written))
}

/// Each run's gyro–reference lag searched wide (s), where it is measured
/// ([`gyro_analysis::lag::log_lag_s`]). Beside a count-stamped clock (`growing`, named by
/// the diagnosis) the lag grows through the run by the clock's doing: each run's lag is
/// then its lag line's start ([`crate::lag_line`]), the delay the clock does not explain.
pub(crate) fn run_lags_s(runs: &[RealRun], growing: bool, settings: &crate::Settings) -> Vec<f64> {
    runs.par_iter()
        .filter_map(|r| {
            if growing {
                crate::lag_line::of_log(&r.log, &settings.statistics).map(|l| l.intercept_s)
            } else {
                gyro_analysis::lag::log_lag_s(&r.log)
            }
        })
        .collect()
}

/// Whether the median of the training runs' lags `lags_s` lies beyond the per-sample
/// statistic's reach: the per-sample residual during turns is then the rate times the lag,
/// which a fit of the residual on the rate reads as a scale, and the turns' totals, rest
/// to rest, measure the scale instead.
pub(crate) fn lag_beyond_statistic(lags_s: &[f64], max_lag_s: f64) -> bool {
    median(lags_s).is_some_and(|m| m.abs() > max_lag_s)
}

/// The lag searched wide; written into `model` (and `changed` set) when it lies beyond
/// the per-sample statistic, `model` has no reference delay yet, and it lowers the
/// held-out runs' max abs angle error.
fn wide_lag(
    lags: &[f64],
    growing: bool,
    holdout: &[RealRun],
    model: &mut ModelFile,
    changed: &mut bool,
    options: &super::Options,
) -> Option<WideLag> {
    let median_s = median(lags)?;
    let lo = lags.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = lags.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let held = run_lags_s(holdout, growing, &options.settings);
    let beyond_statistic = lag_beyond_statistic(lags, options.settings.statistics.max_lag_s);
    let mut out = WideLag {
        median_s,
        train_range_s: (lo, hi),
        holdout_median_s: median(&held),
        beyond_statistic,
        holdout_max_abs_error_deg: None,
        bootstrap_p: None,
        written: false,
    };
    if beyond_statistic && model.reference_delay_s == 0.0 {
        let mut trial = model.clone();
        trial.reference_delay_s = median_s;
        let before = max_abs_errors(holdout, model);
        let after = max_abs_errors(holdout, &trial);
        let paired = paired_gains(&before, &after);
        let seed = gyro_analysis::seed::derive_seed(options.seed, "turns-lag", 0);
        let p = bootstrap_p(&paired, options.bootstrap.max(1), seed);
        out.holdout_max_abs_error_deg = median(&before).zip(median(&after));
        out.bootstrap_p = Some(p);
        if !paired.is_empty() && p < options.settings.tests.p_value {
            *model = trial;
            *changed = true;
            out.written = true;
        }
    }
    Some(out)
}

/// The scale of the training turns `train`, checked and tried on the held-out runs;
/// written into `model` when it helps. `None` when no scale can be fitted.
fn turn_scale(
    train: &[MovementTotal],
    holdout: &[RealRun],
    holdout_totals: &[Vec<MovementTotal>],
    model: &mut ModelFile,
    options: &super::Options,
) -> Option<TurnScale> {
    let (k, se) = scale::fit(train)?;
    let se = se.filter(|s| s.is_finite() && *s > 0.0)?;
    let n = scale::turns(train);
    let half = t95(n.saturating_sub(1)) * se;
    let mut trial = model.clone();
    trial.config = scale::with_scale(&model.config, k)?;
    let after_totals = totals(holdout, &trial);

    let all_before: Vec<MovementTotal> = holdout_totals.iter().flatten().copied().collect();
    let all_after: Vec<MovementTotal> = after_totals.iter().flatten().copied().collect();
    let k_before = scale::fit(&all_before).map_or(f64::NAN, |f| f.0);
    let k_after = scale::fit(&all_after).map_or(f64::NAN, |f| f.0);
    let rms_before = scale::turn_rms(&all_before).unwrap_or(f64::NAN);
    let rms_after = scale::turn_rms(&all_after).unwrap_or(f64::NAN);

    // Per held-out run with turns: its turn RMS without and with.
    let paired: Vec<f64> = holdout_totals
        .iter()
        .zip(&after_totals)
        .filter_map(|(b, a)| Some(scale::turn_rms(b)? - scale::turn_rms(a)?))
        .filter(|d| d.is_finite())
        .collect();
    let better = paired.iter().filter(|d| **d > 0.0).count();
    let seed = gyro_analysis::seed::derive_seed(options.seed, "turns-scale", 0);
    let p = bootstrap_p(&paired, options.bootstrap.max(1), seed);

    let z = k / se;
    let tests = &options.settings.tests;
    let named = z.abs() >= tests.z_critical
        && k.abs() >= options.settings.turns.min_k
        && k_after.abs() <= 0.5 * k_before.abs();
    let written = named && !paired.is_empty() && p < tests.p_value && rms_after < rms_before;
    if written {
        *model = trial;
    }
    Some(TurnScale {
        k,
        standard_error: se,
        ci95: (k - half, k + half),
        z,
        holdout_k: (k_before, k_after),
        holdout_turn_rms_deg: (rms_before, rms_after),
        holdout_runs_better: (better, paired.len()),
        bootstrap_p: p,
        named,
        written,
    })
}

/// The movements of `runs` the reference does not follow.
fn untracked<'a>(
    runs: &'a [RealRun],
    totals: &'a [Vec<MovementTotal>],
) -> impl Iterator<Item = Untracked> + 'a {
    runs.iter().zip(totals).flat_map(|(run, moves)| {
        moves.iter().filter_map(move |m| {
            let gyro_deg = m.reference_deg + m.error_deg;
            not_followed(gyro_deg, m.reference_deg).then(|| Untracked {
                run: run.name.clone(),
                gyro_deg,
                reference_deg: m.reference_deg,
            })
        })
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
    use super::*;

    /// Rest, +120° about the reference's axis, rest, a 5° turn the reference does not see,
    /// rest, −90°, rest: the gyro reads `(1 + k)` times the turns, `lag_s` late, with a
    /// small bias and a little deterministic wobble, at 100 Hz.
    fn run(k: f64, lag_s: f64, bias_dps: f64, name: &str) -> RealRun {
        let fs = 100.0;
        let ramp = |t: f64, t0: f64, d: f64, deg: f64| {
            deg * (0.5 - 0.5 * (std::f64::consts::PI * ((t - t0) / d).clamp(0.0, 1.0)).cos())
        };
        let seen = |t: f64| ramp(t, 2.0, 1.5, 120.0) + ramp(t, 8.0, 1.2, -90.0);
        let unseen = |t: f64| ramp(t, 5.0, 0.8, 5.0);
        let n = (11.0 * fs) as usize;
        let log = gyro_log::RegularLog::with_reference(
            fs,
            (0..n).map(|i| {
                let t = i as f64 / fs;
                let u = t - lag_s;
                let d = |f: &dyn Fn(f64) -> f64| (f(u + 0.5 / fs) - f(u - 0.5 / fs)) * fs;
                let wobble = 0.01 * (37.0 * t).sin();
                let rate_dps = (1.0 + k) * d(&seen) + d(&unseen) + bias_dps + wobble;
                (t, rate_dps, seen(t))
            }),
        );
        RealRun::prepare(name.into(), log).unwrap()
    }

    fn runs(k: f64, lag_s: f64) -> (Vec<RealRun>, Vec<RealRun>) {
        let make = |b: &[f64], tag: &str| -> Vec<RealRun> {
            b.iter()
                .enumerate()
                .map(|(i, bias)| run(k, lag_s, *bias, &format!("{tag}{i}")))
                .collect()
        };
        (make(&[0.2, -0.1], "train"), make(&[0.05, -0.25], "held"))
    }

    /// The turn evidence of `train` and `holdout` on top of `base`, default options.
    fn evidence_of(
        train: &[RealRun],
        holdout: &[RealRun],
        base: &ModelFile,
    ) -> (Option<TurnEvidence>, Option<ModelFile>) {
        let options = super::super::Options::default();
        turn_evidence(
            train,
            &run_lags_s(train, false, &options.settings),
            false,
            holdout,
            base,
            &options,
        )
    }

    #[test]
    fn a_scale_and_a_long_lag_are_found_written_and_checked() {
        let (train, holdout) = runs(0.02, 0.1);
        let base = ModelFile::new(gyro_core::Config::default());
        let (evidence, model) = evidence_of(&train, &holdout, &base);
        let t = evidence.unwrap();
        assert_eq!((t.train_turns, t.holdout_turns), (4, 4));
        let lag = t.lag.unwrap();
        assert!((lag.median_s - 0.1).abs() < 0.01, "{lag:?}");
        assert!(lag.beyond_statistic && lag.written, "{lag:?}");
        let s = t.scale.unwrap();
        assert!((s.k - 0.02).abs() < 0.002, "{s:?}");
        assert!(s.ci95.0 < s.k && s.k < s.ci95.1, "{s:?}");
        assert!(s.named && s.written, "{s:?}");
        assert!(
            s.holdout_turn_rms_deg.1 < 0.2 * s.holdout_turn_rms_deg.0,
            "{s:?}"
        );
        assert!(s.holdout_k.1.abs() < 0.002, "{s:?}");
        let model = model.unwrap();
        assert!((f64::from(model.config.correction.scale_k) - s.k).abs() < 1e-6);
        assert!((model.reference_delay_s - lag.median_s).abs() < 1e-12);
        // The 5° turn the reference does not see, once per run.
        assert_eq!(t.untracked.len(), 4, "{:?}", t.untracked);
        for u in &t.untracked {
            assert!(
                (u.gyro_deg - 5.0).abs() < 0.5 && u.reference_deg.abs() < 0.1,
                "{u:?}"
            );
        }
    }

    #[test]
    fn no_scale_and_no_lag_write_nothing() {
        let (train, holdout) = runs(0.0, 0.0);
        let base = ModelFile::new(gyro_core::Config::default());
        let (evidence, model) = evidence_of(&train, &holdout, &base);
        let t = evidence.unwrap();
        let lag = t.lag.unwrap();
        assert!(lag.median_s.abs() < 0.005 && !lag.beyond_statistic && !lag.written);
        let s = t.scale.unwrap();
        assert!(!s.written, "{s:?}");
        assert!(s.k.abs() < 0.002, "{s:?}");
        assert!(model.is_none());
    }
}
