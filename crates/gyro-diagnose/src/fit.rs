//! The nominal model fitted on the training runs, and a fitting procedure per effect.
//!
//! Every estimator is a function of the training runs' [`Features`]; applied to the
//! baseline ensemble (member `j` of every run forms replica `j`) it gives the estimator's
//! distribution when the effect is absent. The parameter test is the real estimate's
//! z-score against those null replicas; the estimate is the real value minus the null
//! mean (what the nominal sensor and the processing alone produce), rescaled by a
//! noise-free simulation of the training runs with the effect where the feature is only
//! proportional to the parameter to first order (the gain correction). Intervals are
//! ±1.96 null standard deviations (deterministic effects), χ² bounds (turn-on bias) or
//! ±1.96 null standard deviations of the variance (wander), mapped to the parameter.

use super::ensemble::{simulate_features, simulate_member, Member, RealRun, StampedClock};
use super::features::{reg, CUBIC_SCALE_DPS, N_REG, WANDER_TAUS_S};
use crate::Settings;
use gyro_analysis::noise::fit::gauss_markov_avar_continuous;
use gyro_analysis::noise::{chi2_quantile, rate_step};
use gyro_sim::{
    Effect, EffectInfo, FitProcedure, Reading, Regressor, SensorModel, WanderShape, EFFECTS,
};
use rayon::prelude::*;

/// The fitted candidate of one effect.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The effect with its fitted parameters.
    pub effect: Effect,
    /// 95% interval of each parameter (`None` bound: unbounded).
    pub ci95: Vec<(Option<f64>, Option<f64>)>,
    /// z-score of the parameter test (NaN where the test is exact, see `passes`).
    pub z: f64,
    /// The parameter test passes.
    pub passes: bool,
    /// What the test was.
    pub test: String,
    /// The effect is seen directly in the raw data (a grid, a plateau, gaps), or is a
    /// between-run effect (turn-on bias): it is significant when the same test also
    /// passes on the held-out runs.
    pub direct: bool,
    /// The parameter test read on the held-out runs, in the direction of the training
    /// test's `z`: a regression effect's coefficient, or a wander's Allan-variance excess,
    /// against their null replicas (`None` for the other fit procedures).
    pub holdout_z: Option<f64>,
    /// A bias wander's shape evidence: the log-likelihood of the residual's Allan
    /// variances at [`WANDER_TAUS_S`], pooled over the training runs and over the
    /// held-out runs, under the wander as fitted ([`wander_shape_loglik`]; `None` for
    /// the other fit procedures and for a wander whose test does not pass). The
    /// look-alike wanders are told apart by it.
    pub shape_loglik: Option<f64>,
}

/// The held-out replication of an effect whose significance is its own test passing
/// again ([`Fit::direct`]): saturation, quantisation and dropouts seen directly in
/// `runs`, and the turn-on bias's between-run spread against their `null` ensembles
/// (each held-out run alone says little about a between-run effect: one run with a large
/// bias cannot carry a bootstrap over runs; the biases less what the `known` effects
/// give them, [`bias_spread`]). False for the other effects.
pub fn direct_evidence(
    effect: &Effect,
    runs: &[&RealRun],
    null: &[Vec<Member>],
    model: &SensorModel,
    known: &[Effect],
    settings: &Settings,
) -> bool {
    match effect.info().fit {
        FitProcedure::BetweenRunSpread => {
            runs.len() >= 3 && bias_spread(runs, null, model, known).0 >= settings.tests.z_critical
        }
        FitProcedure::Plateau => {
            runs.iter()
                .map(|r| r.features.plateau_samples)
                .sum::<usize>()
                >= settings.fit.min_clipped
        }
        FitProcedure::OutputGrid => {
            let values: Vec<f64> = runs
                .iter()
                .flat_map(|r| r.measured_rates_dps.iter().copied())
                .collect();
            rate_step(&values)
                .is_some_and(|s| s >= settings.fit.quant_ratio * model.lsb_dps && s > 0.0)
        }
        FitProcedure::Gaps => runs.iter().map(|r| r.gaps).sum::<u64>() >= settings.fit.min_gaps,
        FitProcedure::SpectralLine => match effect.params().as_slice() {
            [amplitude_dps, frequency_hz] if *amplitude_dps > 0.0 => {
                super::line::at(runs, null, *frequency_hz).is_some_and(|l| {
                    l.z >= settings.tests.z_critical
                        && l.ratio >= settings.statistics.line_min_ratio
                })
            }
            _ => false,
        },
        FitProcedure::Regression { .. } | FitProcedure::StampedClock | FitProcedure::Wander(_) => {
            false
        }
    }
}

/// The output step the training runs' rates show, where it differs from the prior's
/// `prior_lsb_dps` and is not what `quantization` names: the grid the rates lie on
/// ([`rate_step`]) when it is finer than `quant_ratio` (`fit.quant_ratio`) × the prior's (a sensor with its
/// own LSB: an MPU-6050's 1/131 °/s), or none when the rates lie on no grid (a log written
/// as floats), with the note that says so. `None`: the prior's step stands (the runs show
/// it, or a coarser one that `quantization` is fitted to).
fn runs_output_step(
    train: &[&RealRun],
    prior_lsb_dps: f64,
    settings: &crate::settings::Fit,
) -> Option<(f64, String)> {
    let (quant_ratio, step_match_rel) = (settings.quant_ratio, settings.step_match_rel);
    let values: Vec<f64> = train
        .iter()
        .flat_map(|r| r.measured_rates_dps.iter().copied())
        .collect();
    match rate_step(&values) {
        Some(step) if step < quant_ratio * prior_lsb_dps => {
            ((step - prior_lsb_dps).abs() > step_match_rel * prior_lsb_dps).then(|| {
                (
                    step,
                    format!(
                        "output step {step:.5} deg/s: the grid the training runs' rates lie on (the prior's is {prior_lsb_dps:.5})"
                    ),
                )
            })
        }
        Some(_) => None,
        None => (prior_lsb_dps > 0.0 && !values.is_empty()).then(|| {
            (
                0.0,
                format!(
                    "no output step: the training runs' rates lie on no grid (the prior's is {prior_lsb_dps:.5} deg/s)"
                ),
            )
        }),
    }
}

/// A bias wander (a random walk or a bias instability).
pub(crate) fn is_wander(effect: &Effect) -> bool {
    matches!(effect.info().fit, FitProcedure::Wander(_))
}

/// Whether a regression or wander effect fitted on the training runs shows again on the
/// held-out runs: the same test on them ([`Fit::holdout_z`]: a regression coefficient
/// against their null replicas, with the test's standard error (the replicas' spread, or
/// the runs' own scatter where larger); the wander estimator's excess over their
/// ensembles against the replicas') deviates by at least `replication_z` (`tests.replication_z`) in the
/// direction of the training test. The test named in advance for this effect's
/// signature: a weak effect (a temperature bias of 0.05 °/s/°C over a 2 °C warm-up,
/// beside the bias's wander) moves one coefficient by a few standard errors, and a
/// random walk's held-out likelihood rests on the one or two runs that wandered most, so
/// the likelihood of every statistic, each with its simulation noise, may not show
/// either at P < 5% over a few runs. Against the nominal model: the share of the
/// coefficient other effects would give is a product of effects, left out. False for
/// the other fit procedures.
pub fn replicates(fit: &Fit, replication_z: f64) -> bool {
    fit.holdout_z
        .is_some_and(|z| z.is_finite() && fit.z.is_finite() && z * fit.z.signum() >= replication_z)
}

/// [`replicates`], for an effect added to the effects `beside`: a wander's held-out test
/// reads the Allan-variance excess over the nominal model, which another wander beside it
/// already explains (a bias instability named on top of a rate random walk on the
/// walk's held-out excess), so a wander replicates only with no other wander beside it.
pub fn replicates_beside(fit: &Fit, beside: &[Effect], replication_z: f64) -> bool {
    replicates(fit, replication_z) && !(is_wander(&fit.effect) && beside.iter().any(is_wander))
}

/// Whether an effect's own test, read on the held-out runs ([`Fit::holdout_z`]), points
/// the other way from the training runs' (below zero in the training direction). Such
/// an effect is not named, however the held-out likelihood of every statistic takes it:
/// with the effect there, the held-out z lies near the training one (below zero with
/// chance 3e-5 at a training z of 4); when the training z came from another effect's
/// fitting error, it points either way. On the self-test, a −0.05% `scale_factor`
/// beside a `temperature_scale` fitted 27% high (training z −5.3, held out +1.1, held-out
/// `delta_bic` +164 at P 0.000), and a 0.05% `scale_asymmetry` beside a 1% scale and a
/// random walk (z 4.3, held out −1.1). False without a held-out test.
pub fn contradicted(fit: &Fit) -> bool {
    fit.holdout_z
        .is_some_and(|z| z.is_finite() && fit.z.is_finite() && z * fit.z.signum() < 0.0)
}

/// Stouffer's combination of a test on `train_runs` runs (`train_z`) and the same test
/// on `holdout_runs` other runs (`holdout_z`), each weighted by the square root of its
/// runs: standard normal when both are, as the test on all the runs together would be.
pub fn pooled_z(train_z: f64, train_runs: usize, holdout_z: f64, holdout_runs: usize) -> f64 {
    let (a, b) = (train_runs as f64, holdout_runs as f64);
    (a.sqrt() * train_z + b.sqrt() * holdout_z) / (a + b).sqrt()
}

/// The z-score of the runs' mean coefficient against their replicas'
/// ([`CoefficientTest`]), as the training test reads it ([`regression_fit`]).
fn replication_z(coefficients: &[(f64, Vec<f64>)], scatter_p: f64) -> f64 {
    let test = CoefficientTest::of(coefficients, scatter_p);
    test.deviation / test.se()
}

/// Each run's coefficient `index` and its null replicas' values.
fn run_coefficients(runs: &[&RealRun], null: &[Vec<Member>], index: usize) -> Vec<(f64, Vec<f64>)> {
    runs.iter()
        .zip(null)
        .map(|(run, members)| {
            let replicas = members.iter().map(|m| m.features.coef[index]).collect();
            (run.features.coef[index], replicas)
        })
        .collect()
}

/// A regression coefficient of real runs against their null replicas: the one reading of
/// it the training test and the held-out replication share.
struct CoefficientTest {
    /// The runs' mean coefficient less the pooled replicas' mean (member `j` of every run
    /// makes pooled replica `j`).
    deviation: f64,
    /// The pooled replicas' standard deviation.
    replica_sd: f64,
    /// Pooled replicas.
    replicas: usize,
    /// The runs' own scatter, when it exceeds the null's ([`scatter_of`]).
    scatter: Option<Scatter>,
}

impl CoefficientTest {
    fn of(coefficients: &[(f64, Vec<f64>)], scatter_p: f64) -> Self {
        let real = mean(coefficients.iter().map(|(c, _)| *c));
        let members = coefficients.iter().map(|(_, r)| r.len()).min().unwrap_or(0);
        let replicas: Vec<f64> = (0..members)
            .map(|j| mean(coefficients.iter().map(|(_, r)| r[j])))
            .collect();
        let (m0, replica_sd) = mean_sd(&replicas);
        Self {
            deviation: real - m0,
            replica_sd,
            replicas: replicas.len(),
            scatter: scatter_of(coefficients, scatter_p),
        }
    }

    /// The runs' scatter where it exceeds the replicas' spread.
    fn wider_scatter(&self) -> Option<&Scatter> {
        self.scatter.as_ref().filter(|s| s.se > self.replica_sd)
    }

    /// The standard error of [`Self::deviation`]: the replicas' spread, or the runs' own
    /// scatter where that is larger.
    fn se(&self) -> f64 {
        self.wider_scatter().map_or(self.replica_sd, |s| s.se)
    }
}

/// The between-run spread of the bias ([`super::features::Features::bias_dps`]) of
/// `runs` against their null ensembles: `(n−1) s²/v0` is χ²(n−1) without a turn-on bias
/// (s²: the runs' sample variance, v0: the mean of the replicas'). Each run's bias is
/// taken less what the `known` effects give it in a noise-free simulation of the run with
/// `model` ([`known_bias_dps`]). Returns (its Wilson–Hilferty z-score, s², v0, n−1).
fn bias_spread(
    runs: &[&RealRun],
    null: &[Vec<Member>],
    model: &SensorModel,
    known: &[Effect],
) -> (f64, f64, f64, f64) {
    let real: Vec<f64> = runs
        .par_iter()
        .map(|r| r.features.bias_dps - known_bias_dps(r, model, known))
        .collect();
    let s2 = sample_var(&real);
    let members = null.iter().map(Vec::len).min().unwrap_or(0);
    let null_vars: Vec<f64> = (0..members)
        .map(|j| {
            let v: Vec<f64> = null.iter().map(|m| m[j].features.bias_dps).collect();
            sample_var(&v)
        })
        .collect();
    let v0 = mean(null_vars.iter().copied());
    let k = runs.len().saturating_sub(1) as f64;
    let x = k * s2 / v0;
    let c = 2.0 / (9.0 * k);
    let z = ((x / k).cbrt() - (1.0 - c)) / c.sqrt();
    (z, s2, v0, k)
}

/// The bias the `known` effects alone give `run` (its regression intercept in a
/// noise-free simulation with `model`, less the model's own): 0 without known effects.
/// A count-stamped clock whose lag grows leaks the rate times the lag into the intercept,
/// by as much as the turns differ between runs: unremoved, it reads as a turn-on bias.
pub(crate) fn known_bias_dps(run: &RealRun, model: &SensorModel, known: &[Effect]) -> f64 {
    if known.is_empty() {
        return 0.0;
    }
    let quiet = model.noise_free();
    let with = simulate_member(run, &quiet, known, 1).features.bias_dps;
    let without = simulate_member(run, &quiet, &[], 1).features.bias_dps;
    with - without
}

/// Two-sided 95% quantile of Student's t with `dof` degrees of freedom.
pub fn t95(dof: usize) -> f64 {
    const T: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
        2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
        2.052, 2.048, 2.045, 2.042,
    ];
    match dof {
        0 => f64::INFINITY,
        d if d <= 30 => T[d - 1],
        _ => 1.96,
    }
}

/// An effect that cannot be tested on these runs, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Untestable {
    /// Effect id.
    pub id: &'static str,
    /// What data is missing.
    pub reason: String,
}

/// The static statistics the white noise is matched to: the Allan variance at `block`
/// samples ((deg/s)²; at one sample, half the mean squared first difference), and, for
/// the bias under a coarse output step ([`solve_white_and_bias`]), the rests' mean and
/// the moving residual's.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct WhiteTarget {
    /// The measured Allan variance ((deg/s)²).
    pub avar_dps2: f64,
    /// Its averaging time in samples.
    pub block: usize,
    /// Mean of the gyro at rest, as rounded (deg/s; NaN: not measured).
    pub rest_mean_dps: f64,
    /// How far a simulated rest mean may lie from `rest_mean_dps` and match it (deg/s):
    /// `tests.z_critical` standard errors.
    pub rest_mean_tol_dps: f64,
    /// Mean residual over the moving samples (deg/s; NaN: none), where the motion
    /// dithers the rounding.
    pub moving_mean_dps: f64,
}

/// The whiteness check of the training runs' rests: the white noise their first
/// differences give and the one their Allan variance at a short τ gives, each matched
/// through the nominal model (its wander and output step included).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RestWhiteness {
    /// Averaging time of the check (s).
    pub tau_s: f64,
    /// Angle random walk from the first differences (deg/√h).
    pub first_difference_arw_deg_per_rt_h: f64,
    /// Angle random walk from the Allan variance at `tau_s` (deg/√h).
    pub block_arw_deg_per_rt_h: f64,
    /// Block differences the check rests on.
    pub block_differences: usize,
    /// (block / first-difference white variance − 1) over its standard error √(3/n)
    /// (consecutive block differences share a block: a white noise's non-overlapping
    /// Allan variance from n differences has a relative variance of about 3/n).
    pub z: f64,
    /// |z| ≥ `tests.z_critical` and the variances differ by at least `fit.white_check_min`
    /// of the first differences': the rests' noise is coloured, and the baseline's white
    /// noise is the block's (the band the angle integrates), not the first differences'.
    pub coloured: bool,
}

/// The nominal model fitted on some training runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Nominal {
    /// The model.
    pub model: SensorModel,
    /// Where each value came from.
    pub notes: Vec<String>,
    /// The static statistic the white noise was matched to (if measured at rest).
    pub white_target: Option<WhiteTarget>,
    /// The whiteness check of the rests (when they hold enough blocks).
    pub whiteness: Option<RestWhiteness>,
}

/// The nominal model for these training runs, notes on where each value came from, and
/// the static statistic the white noise was matched to (if measured).
///
/// The white noise comes from the runs' rests when they hold 2 s of them, else from
/// `moving`, the effective noise of their moving residual ([`super::effective`]: the
/// white level its Allan deviation reads from 1 to 10 s, an estimate: the bound the
/// effective noise reports would widen every simulated residual by its margin), else from
/// the prior.
/// At rest it is matched to the first differences, unless the rests' Allan variance at
/// `statistics.white_check_tau_s` reads a white noise that differs beyond
/// `tests.z_critical`: a low-pass inside the band (a MEMS gyro's digital filter) leaves
/// the first differences short of the low band that the angle integrates, and the
/// block's statistic is used instead ([`RestWhiteness`]).
/// The output step is the runs' own ([`runs_output_step`]) when it is no coarser than
/// quantization is named at; the bias wander and a coarser step stay the prior's: a
/// wander or a step beyond them is what the vocabulary's `bias_instability`,
/// `rate_random_walk` and `quantization` name, and a baseline fitted to them would absorb
/// the effect it should reveal. The notes say whether the prior's wander is within what
/// the residual allows.
pub fn nominal_model(
    train: &[&RealRun],
    prior: &SensorModel,
    moving: Option<&super::effective::MeasuredNoise>,
    short: Option<&super::short_white::ShortWhite>,
    settings: &Settings,
) -> Nominal {
    let mut model = *prior;
    let mut notes = Vec::new();
    if let Some(run) = train.first() {
        model.sample_rate_hz = run.sample_rate_hz;
    }
    let means: Vec<f64> = train
        .iter()
        .map(|r| r.features.bias_dps)
        .filter(|c| c.is_finite())
        .collect();
    if !means.is_empty() {
        model.bias_dps = means.iter().sum::<f64>() / means.len() as f64;
        notes.push(format!(
            "bias {:.4} deg/s: mean over the training runs of each run's regression intercept (runs with 2 s of static samples) or mean residual, gyro - reference rate (runs in continuous motion)",
            model.bias_dps
        ));
    }
    if let Some((lsb_dps, note)) = runs_output_step(train, prior.lsb_dps, &settings.fit) {
        model.lsb_dps = lsb_dps;
        notes.push(note);
    }
    let mut target = None;
    let mut whiteness = None;
    if rests_suffice(train) {
        let (chosen, rest_whiteness, count) = rest_white_target(train, &model, settings);
        whiteness = rest_whiteness;
        model.arw_deg_per_rt_h = arw_of(chosen.1.sigma_dps, &model);
        target = Some(chosen.0);
        notes.push(rest_white_note(
            model.arw_deg_per_rt_h,
            whiteness.as_ref(),
            count,
        ));
        if chosen.1.shift_dps != 0.0 {
            notes.push(rounded_bias_note(model.bias_dps, &chosen.1, model.lsb_dps));
            model.bias_dps = chosen.1.bias_dps;
        }
    } else if let Some(m) = moving.filter(|m| m.white_level_deg_per_rt_h > 0.0) {
        notes.push(moving_white(&mut model, prior, m, short));
    } else {
        notes.push(format!(
            "angle random walk {:.4} deg/sqrt(h) from the prior model: fewer than 2 s of static samples and no moving residual to measure",
            model.arw_deg_per_rt_h
        ));
    }
    notes.push(prior_wander(
        &mut model,
        prior,
        moving,
        settings.fit.wander_prior_floor,
    ));
    Nominal {
        model,
        notes,
        white_target: target,
        whiteness,
    }
}

/// Angle random walk (deg/√h) of a white noise of `sigma_dps` (deg/s) per sample of `model`.
fn arw_of(sigma_dps: f64, model: &SensorModel) -> f64 {
    sigma_dps * 60.0 / model.sample_rate_hz.sqrt()
}

/// Mean over the `train` runs of a rest statistic `pick` gives as (value, count),
/// weighted by the count, and the total count.
fn pooled_rest(train: &[&RealRun], pick: fn(&RealRun) -> (f64, usize)) -> (f64, usize) {
    let (sum, count) = train.iter().fold((0.0, 0usize), |(s, c), r| {
        let (v, n) = pick(r);
        if n > 0 && v.is_finite() {
            (s + v * n as f64, c + n)
        } else {
            (s, c)
        }
    });
    (sum / count.max(1) as f64, count)
}

/// The white noise matched at rest ([`nominal_model`]): the target and the per-sample σ
/// (deg/s) solved for `model` with the bias that goes with it under the model's output
/// step ([`solve_white_and_bias`]), from the first differences unless the rests'
/// whiteness check finds them coloured (then from the block's Allan variance), the check
/// when it ran, and how many first differences the rests hold.
fn rest_white_target(
    train: &[&RealRun],
    model: &SensorModel,
    settings: &Settings,
) -> ((WhiteTarget, RestMatch), Option<RestWhiteness>, usize) {
    let (diff_var, count) = pooled_rest(train, |r| r.features.static_diff_var);
    let (block_var, block_count) = pooled_rest(train, |r| r.features.static_block_var);
    let (rest_mean_dps, rest_count) = pooled_rest(train, |r| r.features.static_mean_dps);
    let (moving_mean_dps, moving_count) = pooled_rest(train, |r| r.features.moving_mean_dps);
    // The rests' mean is known to its standard error: white samples of the first
    // differences' variance.
    let rest_mean_tol_dps =
        settings.tests.z_critical * (diff_var / rest_count.max(1) as f64).sqrt();
    let mut whiteness = None;
    let diff_target = WhiteTarget {
        avar_dps2: diff_var,
        block: 1,
        rest_mean_dps: if rest_count > 0 {
            rest_mean_dps
        } else {
            f64::NAN
        },
        rest_mean_tol_dps,
        moving_mean_dps: if moving_count > 0 {
            moving_mean_dps
        } else {
            f64::NAN
        },
    };
    let diff = solve_white_and_bias(diff_target, model, model.lsb_dps, None);
    let diff_sigma = diff.sigma_dps;
    let mut chosen = (diff_target, diff);
    let block = super::features::white_check_block(
        model.sample_rate_hz,
        settings.statistics.white_check_tau_s,
    );
    if block_count >= settings.fit.min_white_check_diffs && diff_sigma > 0.0 {
        let block_target = WhiteTarget {
            avar_dps2: block_var,
            block,
            ..diff_target
        };
        let block_match = solve_white_and_bias(block_target, model, model.lsb_dps, None);
        let block_sigma = block_match.sigma_dps;
        let ratio = (block_sigma / diff_sigma).powi(2);
        let z = (ratio - 1.0) / (3.0 / block_count as f64).sqrt();
        let coloured = z.abs() >= settings.tests.z_critical
            && (ratio - 1.0).abs() >= settings.fit.white_check_min;
        if coloured {
            chosen = (block_target, block_match);
        }
        whiteness = Some(RestWhiteness {
            tau_s: block as f64 / model.sample_rate_hz,
            first_difference_arw_deg_per_rt_h: arw_of(diff_sigma, model),
            block_arw_deg_per_rt_h: arw_of(block_sigma, model),
            block_differences: block_count,
            z,
            coloured,
        });
    }
    (chosen, whiteness, count)
}

/// The note on a bias `was_dps` replaced by the pre-rounding bias of `matched`, solved
/// with the white noise under an output step `lsb_dps` coarse against it.
fn rounded_bias_note(was_dps: f64, matched: &RestMatch, lsb_dps: f64) -> String {
    format!(
        "bias {:.4} deg/s (was {was_dps:.4}): the output step {lsb_dps:.5} deg/s is coarse against the noise, so the rests' mean is the bias rounded towards the level the output sits on most ({:+.4} deg/s); bias and white noise solved together so that the simulated rounded rest output matches both the rests' mean and their Allan variance, the bias nearest the moving residual's mean, where the motion dithers the rounding",
        matched.bias_dps, matched.shift_dps
    )
}

/// The note on the white noise measured at rest: `arw_deg_per_rt_h`, matched to the first
/// differences of `count` static samples or, when the rests' `whiteness` check finds
/// their noise coloured, to the Allan variance at its τ.
fn rest_white_note(
    arw_deg_per_rt_h: f64,
    whiteness: Option<&RestWhiteness>,
    count: usize,
) -> String {
    match whiteness {
        Some(w) if w.coloured => format!(
            "angle random walk {:.4} deg/sqrt(h): matched to the Allan variance at {:.3} s of the gyro at rest ({} block differences), not to its first differences ({:.4} deg/sqrt(h)): the rest noise is not white ({:.2}x the first differences' white variance, z {:.1}; {}); the angle integrates the low band, and the simulated noise stays white, so its high band is not the sensor's",
            arw_deg_per_rt_h,
            w.tau_s,
            w.block_differences,
            w.first_difference_arw_deg_per_rt_h,
            (w.block_arw_deg_per_rt_h / w.first_difference_arw_deg_per_rt_h).powi(2),
            w.z,
            if w.z > 0.0 {
                "more in the low band than at the top: a low-pass inside the band, such as the sensor's own digital filter, or motion at rest that the reference does not resolve"
            } else {
                "the top of the band holds noise the low band does not, such as a vibration at rest"
            },
        ),
        Some(w) => format!(
            "angle random walk {:.4} deg/sqrt(h): matched to the first differences of {count} static samples (output rounding included); the rest noise is white at {:.3} s ({:.4} deg/sqrt(h) from the Allan variance there, z {:.1})",
            arw_deg_per_rt_h, w.tau_s, w.block_arw_deg_per_rt_h, w.z
        ),
        None => format!(
            "angle random walk {:.4} deg/sqrt(h): matched to the first differences of {count} static samples (output rounding included)",
            arw_deg_per_rt_h
        ),
    }
}

/// The bias wander of the nominal `model` (the prior's Gauss–Markov σ and τ, its range and
/// output step), against the bound the training runs' moving residual `moving` allows:
/// the σ comes down to that bound when it is under `floor` of the prior's (never up: a
/// larger wander is an effect to name); the note saying so.
fn prior_wander(
    model: &mut SensorModel,
    prior: &SensorModel,
    moving: Option<&super::effective::MeasuredNoise>,
    floor: f64,
) -> String {
    let mut wander = if model.gm_sigma_dps == 0.0 {
        format!(
            "no bias wander (Gauss-Markov sigma 0): a wander the runs show is the vocabulary's to name (bias_instability, rate_random_walk), a spread of their biases turn_on_bias; range {} deg/s: from the prior model",
            model.range_dps
        )
    } else {
        format!(
            "Gauss-Markov bias sigma {} deg/s, T {} s, range {} deg/s: from the prior model",
            model.gm_sigma_dps, model.gm_tau_s, model.range_dps
        )
    };
    if model.lsb_dps == prior.lsb_dps {
        wander = format!(
            "{wander}; output step {:.5} deg/s: the prior's",
            model.lsb_dps
        );
    }
    if let Some(m) = moving.filter(|_| model.gm_sigma_dps > 0.0) {
        let k_prior = gyro_analysis::noise::export::gauss_markov_random_walk(
            model.gm_sigma_dps,
            model.gm_tau_s,
        );
        let k = m.rate_random_walk_dps_per_rt_s;
        let verdict = match (m.rate_random_walk_resolved, k >= floor * k_prior) {
            (true, _) => format!("K {k_prior:.3e} deg/s/sqrt(s) at tau = 3 s, against {k:.3e} fitted to the training residual (a larger wander is the vocabulary's to name)"),
            (false, true) => format!("K {k_prior:.3e} deg/s/sqrt(s) at tau = 3 s, against the bound the training residual allows ({k:.3e}): kept"),
            (false, false) => {
                // A prior that wanders more than the runs allow is not this sensor's: it
                // is set aside (σ 0), and the wander the runs do show is the vocabulary's
                // to name by its shape (`bias_instability`, `rate_random_walk`). Lowered
                // to the bound instead, it would hold that wander before any candidate is
                // tried: a 45 °/h bias instability at the CRM100's noise went unnamed.
                let sigma_prior = model.gm_sigma_dps;
                model.gm_sigma_dps = 0.0;
                format!("K {k_prior:.3e} deg/s/sqrt(s) at tau = 3 s, and the training residual allows at most {k:.3e}, under {floor} of it: the prior's wander is larger than these runs show, so it is set aside (sigma {sigma_prior} -> 0 deg/s) and what wander the runs show is for the vocabulary to name")
            }
        };
        wander.push_str("; its wander: ");
        wander.push_str(&verdict);
    }
    wander
}

/// The white noise of runs that never rest, from `m`, the training runs' moving residual
/// (its short band `short` when that agrees with the 1–10 s level), written into `model`;
/// the note saying so. `prior` for the comparison.
fn moving_white(
    model: &mut SensorModel,
    prior: &SensorModel,
    m: &super::effective::MeasuredNoise,
    short: Option<&super::short_white::ShortWhite>,
) -> String {
    let (lo, hi) = super::short_white::SHORT_TAUS_S;
    match short {
        Some(w) if w.agrees => {
            model.arw_deg_per_rt_h = w.level_deg_per_rt_h;
            format!(
                "angle random walk {:.4} deg/sqrt(h): fewer than 2 s of static samples, so fitted to the moving residual of the training runs, read from {lo} to {hi} s and matched by simulating the runs (the smoothing, the reference's differentiation and the output step shape the residual there); it agrees with the level read from 1 to 10 s, {:.4} (z {:.1}), and has more blocks; it holds what the reference does not resolve as well as the sensor's own noise; the prior's is {:.4}",
                model.arw_deg_per_rt_h, w.long_level_deg_per_rt_h, w.z, prior.arw_deg_per_rt_h
            )
        }
        _ => {
            model.arw_deg_per_rt_h = m.white_level_deg_per_rt_h;
            let short_note = short.map_or(String::new(), |w| {
                format!(
                    "; from {lo} to {hi} s, matched by simulation, it reads {:.4} (z {:.1}): more there than white noise, such as a rig's line or a response the model lacks",
                    w.level_deg_per_rt_h, w.z
                )
            });
            format!(
                "angle random walk {:.4} deg/sqrt(h): fewer than 2 s of static samples, so fitted to the moving residual of the training runs (the white level its Allan deviation reads from 1 to 10 s, degrees-of-freedom weighted, at most the largest the curve allows, {:.4}{short_note}; it holds what the reference does not resolve as well as the sensor's own noise; the prior's is {:.4})",
                model.arw_deg_per_rt_h, m.arw_deg_per_rt_h, prior.arw_deg_per_rt_h
            )
        }
    }
}

/// The training runs hold the 2 s of static samples (at least 20) from which the
/// nominal model's white noise is measured at rest.
pub fn rests_suffice(train: &[&RealRun]) -> bool {
    let Some(fs) = train.first().map(|r| r.sample_rate_hz) else {
        return false;
    };
    let count: usize = train
        .iter()
        .map(|r| r.features.static_diff_var)
        .filter(|(v, n)| *n > 0 && v.is_finite())
        .map(|(_, n)| n)
        .sum();
    count >= ((2.0 * fs) as usize).max(20)
}

/// The white-noise σ (deg/s per sample) whose simulated static output — bias, the
/// Gauss-Markov wander, white noise (through the sensor's low-pass of `cutoff_hz`, when
/// given, as the simulator's `bandwidth` filters it), rounded to the output step `lsb_dps`
/// ([`gyro_sim::output_step_dps`]) —
/// has the Allan variance `target` at its block length (at one sample: half the mean
/// squared first difference), at the bias of `model`. Rounding a signal that barely moves
/// is not the textbook lsb²/12, so the match is by simulation ([`StaticOutput`]).
pub fn solve_white_sigma(
    target: WhiteTarget,
    model: &SensorModel,
    lsb_dps: f64,
    cutoff_hz: Option<f64>,
) -> f64 {
    StaticOutput::new(target.block, model, lsb_dps, cutoff_hz)
        .sigma_for(target.avar_dps2, model.bias_dps)
}

/// The pre-rounding bias and the white noise matched jointly at rest
/// ([`solve_white_and_bias`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestMatch {
    /// Bias before the output's rounding (deg/s).
    pub bias_dps: f64,
    /// White noise per sample (deg/s).
    pub sigma_dps: f64,
    /// What the rounding adds to the mean at rest (deg/s): the rests' mean reads
    /// `bias_dps` plus this. Zero where the step is fine against the noise.
    pub shift_dps: f64,
}

/// The bias and white σ whose simulated static output, rounded to `lsb_dps`
/// ([`solve_white_sigma`]'s simulation), matches both the rests' Allan variance `target`
/// and their mean (`target.rest_mean_dps`, within `target.rest_mean_tol_dps`).
///
/// Under a step coarse against the noise the output sits on one or two levels, and the
/// rests' mean reads the bias pulled towards the level it sits on most (0.15 deg/s under
/// a 0.264 step with 0.047 of noise reads 0.17): the bias, not the mean, is what the
/// motion carries, where it dithers the rounding. Both static statistics then read only
/// how often the output leaves its level, so they pin the bias and σ along a curve (the
/// bias nearer the rounding threshold, σ smaller), not each: the bias on that curve is the
/// one nearest the moving residual's mean (`target.moving_mean_dps`, the bias where the
/// motion dithers the rounding) among those whose simulated rest mean matches the rests'
/// (without it, the one whose rest mean is the rests'). Where the rounding's shift of the
/// mean is within the simulation's resolution (the step fine against the noise), the
/// bias stays `model`'s and σ is [`solve_white_sigma`]'s.
pub fn solve_white_and_bias(
    target: WhiteTarget,
    model: &SensorModel,
    lsb_dps: f64,
    cutoff_hz: Option<f64>,
) -> RestMatch {
    let sim = StaticOutput::new(target.block, model, lsb_dps, cutoff_hz);
    let today = RestMatch {
        bias_dps: model.bias_dps,
        sigma_dps: sim.sigma_for(target.avar_dps2, model.bias_dps),
        shift_dps: 0.0,
    };
    let mean_dps = target.rest_mean_dps;
    if lsb_dps <= 0.0 || !mean_dps.is_finite() {
        return today;
    }
    // Noise that dithers the rounding at every bias shifts the mean by at most the
    // first harmonic of a Gaussian's rounding error, (step/π)·e^(−2π²σ²/step²): below
    // the simulation's resolution (at 0.8 of σ, for the σ's along the curve), no bias
    // on the curve can move the rest mean, and the search below would return `today`.
    let dithered_sigma = 0.8 * today.sigma_dps / lsb_dps;
    let max_shift_dps = lsb_dps / std::f64::consts::PI
        * (-2.0 * std::f64::consts::PI.powi(2) * dithered_sigma.powi(2)).exp();
    if max_shift_dps <= 3.0 * sim.mean_resolution_dps() {
        return today;
    }
    let tol_dps = target.rest_mean_tol_dps.max(0.0);
    // The pre-rounding bias `b` on the curve of static matches, its σ, and the rest mean
    // it gives (the rounding's shift added: the draw's own mean is not the data's).
    let on_curve = |bias_dps: f64| {
        let sigma_dps = sim.sigma_for(target.avar_dps2, bias_dps);
        let shift_dps = sim.rounding_shift(bias_dps, sigma_dps);
        RestMatch {
            bias_dps,
            sigma_dps,
            shift_dps,
        }
    };
    let rest_mean = |m: &RestMatch| m.bias_dps + m.shift_dps;
    // The rest mean along the curve rises with the bias (in steps where the output
    // changes level): bisection for the bias where it crosses `level`, within a step.
    let crossing = |level: f64| {
        let (mut lo, mut hi) = (level - lsb_dps, level + lsb_dps);
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            if rest_mean(&on_curve(mid)) < level {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        on_curve(0.5 * (lo + hi))
    };
    let found = match target.moving_mean_dps {
        anchor if anchor.is_finite() => {
            let at = on_curve(anchor);
            let m = rest_mean(&at);
            if m < mean_dps - tol_dps {
                crossing(mean_dps - tol_dps)
            } else if m > mean_dps + tol_dps {
                crossing(mean_dps + tol_dps)
            } else {
                at
            }
        }
        _ => crossing(mean_dps),
    };
    if found.shift_dps.abs() <= 3.0 * sim.mean_resolution_dps() {
        return today;
    }
    found
}

/// The static output a white noise is matched through: bias, the Gauss-Markov wander of
/// the model, white noise (low-passed at `cutoff_hz` when given), rounded to the output
/// step; one fixed draw (40 000 samples, or 40 000 blocks; fixed seed), so that every
/// bias and σ tried sees the same noise.
struct StaticOutput {
    /// Unit white noise, low-passed when the sensor has a cutoff.
    white: Vec<f64>,
    /// The Gauss-Markov wander (deg/s).
    wander: Vec<f64>,
    /// Samples per block of the Allan variance.
    block: usize,
    /// Output step (deg/s; 0: none).
    lsb_dps: f64,
}

impl StaticOutput {
    fn new(block: usize, model: &SensorModel, lsb_dps: f64, cutoff_hz: Option<f64>) -> Self {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let block = block.max(1);
        let n = 40_000 * block;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x000A_11A4);
        let mut white: Vec<f64> = (0..n).map(|_| StandardNormal.sample(&mut rng)).collect();
        // The filter is linear: filtering the unit noise once scales with σ.
        if let Some(cutoff_hz) = cutoff_hz {
            let mut filter = gyro_sim::TwoPoleLowPass::new(cutoff_hz, model.sample_rate_hz, 0.0);
            white.iter_mut().for_each(|w| *w = filter.step(*w));
        }
        let dt = 1.0 / model.sample_rate_hz;
        let phi = (-dt / model.gm_tau_s).exp();
        let drive = model.gm_sigma_dps * (1.0 - phi * phi).sqrt();
        let mut g = model.gm_sigma_dps * {
            let x: f64 = StandardNormal.sample(&mut rng);
            x
        };
        let wander: Vec<f64> = (0..n)
            .map(|_| {
                let x: f64 = StandardNormal.sample(&mut rng);
                g = phi * g + drive * x;
                g
            })
            .collect();
        Self {
            white,
            wander,
            block,
            lsb_dps,
        }
    }

    /// Sample `k` before and after rounding (deg/s).
    fn sample(&self, k: usize, bias_dps: f64, sigma_dps: f64) -> (f64, f64) {
        let x = bias_dps + self.wander[k] + sigma_dps * self.white[k];
        if self.lsb_dps > 0.0 {
            (x, (x / self.lsb_dps).round() * self.lsb_dps)
        } else {
            (x, x)
        }
    }

    /// Allan variance at the block length ((deg/s)²) of the rounded output.
    fn block_var(&self, bias_dps: f64, sigma_dps: f64) -> f64 {
        let block = self.block;
        let mut prev = f64::NAN;
        let (mut sum, mut count) = (0.0, 0usize);
        let (mut acc, mut filled) = (0.0, 0usize);
        for k in 0..self.white.len() {
            let mut x = self.sample(k, bias_dps, sigma_dps).1;
            if block > 1 {
                acc += x;
                filled += 1;
                if filled < block {
                    continue;
                }
                x = acc / block as f64;
                (acc, filled) = (0.0, 0);
            }
            if prev.is_finite() {
                sum += (x - prev) * (x - prev);
                count += 1;
            }
            prev = x;
        }
        sum / count.max(1) as f64 / 2.0
    }

    /// What the rounding adds to the mean (deg/s): the rounded output's mean less the
    /// unrounded's, over the same draw (so that the draw's own mean cancels).
    fn rounding_shift(&self, bias_dps: f64, sigma_dps: f64) -> f64 {
        let n = self.white.len();
        let sum: f64 = (0..n)
            .map(|k| {
                let (x, rounded) = self.sample(k, bias_dps, sigma_dps);
                rounded - x
            })
            .sum();
        sum / n.max(1) as f64
    }

    /// The standard error of [`Self::rounding_shift`] where the rounding is dithered
    /// (errors uniform over a step, independent): step / √(12 n).
    fn mean_resolution_dps(&self) -> f64 {
        self.lsb_dps / (12.0 * self.white.len().max(1) as f64).sqrt()
    }

    /// The σ (deg/s) at `bias_dps` whose Allan variance is `target_dps2` (bisection; 0
    /// when the rounding alone reaches it).
    fn sigma_for(&self, target_dps2: f64, bias_dps: f64) -> f64 {
        let (mut lo, mut hi) = (
            0.0,
            (2.0 * target_dps2 * self.block as f64).sqrt().max(1e-6) * 2.0,
        );
        if self.block_var(bias_dps, lo) >= target_dps2 {
            return 0.0;
        }
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if self.block_var(bias_dps, mid) < target_dps2 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}

/// The model to simulate with `effects` added. The white noise is matched again to the
/// measured static statistic `white_target` where an effect changes what it measured:
/// with quantisation (it was measured with the rounding in it; the bias is solved with
/// it, [`solve_white_and_bias`], since a coarse step moves the rests' mean off the bias),
/// and with a `bandwidth`
/// when the statistic is the rests' block Allan variance (the low band the angle
/// integrates, which the sensor's low-pass must keep: a cutoff near the block's
/// frequency still lowers it). First differences stay as they are under a bandwidth:
/// they are the top of the band, which a low-pass shapes, and their mismatch is the
/// evidence against it.
pub fn model_with(
    nominal: &SensorModel,
    effects: &[Effect],
    white_target: Option<WhiteTarget>,
) -> SensorModel {
    let mut model = *nominal;
    let Some(target) = white_target else {
        return model;
    };
    let active = || effects.iter().filter(|e| !e.is_neutral(nominal));
    // An effect read from the output grid is the output's step, in place of the model's.
    let extra_lsb = active().find_map(|e| match (e.info().fit, e.params().as_slice()) {
        (FitProcedure::OutputGrid, [lsb_dps]) => Some(*lsb_dps),
        _ => None,
    });
    let cutoff_hz = active()
        .find_map(|e| match e {
            Effect::Bandwidth { cutoff_hz } => Some(*cutoff_hz),
            _ => None,
        })
        .filter(|_| target.block > 1);
    if extra_lsb.is_some() || cutoff_hz.is_some() {
        let lsb_dps = gyro_sim::output_step_dps(nominal.lsb_dps, extra_lsb.unwrap_or(0.0));
        // Under a named step the bias is solved with the white noise: the nominal's is
        // the rests' mean as rounded, off the bias by what a coarse step adds.
        let sigma_dps = if extra_lsb.is_some() {
            let matched = solve_white_and_bias(target, nominal, lsb_dps, cutoff_hz);
            model.bias_dps = matched.bias_dps;
            matched.sigma_dps
        } else {
            solve_white_sigma(target, nominal, lsb_dps, cutoff_hz)
        };
        model.arw_deg_per_rt_h = arw_of(sigma_dps, &model);
    }
    model
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v
        .filter(|x| x.is_finite())
        .fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

/// Mean and sample standard deviation of the finite values (NaN for fewer than two).
pub(super) fn mean_sd(v: &[f64]) -> (f64, f64) {
    let f: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if f.len() < 2 {
        return (f64::NAN, f64::NAN);
    }
    let m = f.iter().sum::<f64>() / f.len() as f64;
    let var = f.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (f.len() - 1) as f64;
    (m, var.sqrt())
}

fn sample_var(v: &[f64]) -> f64 {
    let (_, sd) = mean_sd(v);
    sd * sd
}

/// Everything the estimators need.
pub struct FitInput<'a> {
    /// Training runs.
    pub train: &'a [&'a RealRun],
    /// Their baseline ensembles (same member count each).
    pub null: &'a [Vec<Member>],
    /// The nominal model.
    pub model: &'a SensorModel,
    /// Every training run's temperature varies.
    pub temperature_ok: bool,
    /// Seed of the ensembles (training run `i` has seed index `i`).
    pub seed: u64,
    /// Held-out runs: a regression coefficient's test is also read on them
    /// ([`Fit::holdout_z`]), and pooled with the training runs' ([`pooled_z`]).
    pub holdout: &'a [&'a RealRun],
    /// Their baseline ensembles.
    pub holdout_null: &'a [Vec<Member>],
    /// The numbers that decide the fits.
    pub settings: &'a Settings,
    /// A count-stamped clock read from the lag lines, beyond the per-sample statistics'
    /// reach ([`super::lag_line::grown_clock_fit`]), its test passed: held as known.
    pub grown_clock: Option<&'a Fit>,
    /// The effects `null` and `holdout_null` were simulated with beyond the nominal model:
    /// none, but for a wander refitted beside deterministic effects ([`Joint::fits`]).
    pub null_effects: &'a [Effect],
}

impl FitInput<'_> {
    fn members(&self) -> usize {
        self.null.iter().map(Vec::len).min().unwrap_or(0)
    }

    /// Pooled value of `f` over the training runs and over each null replica
    /// ([`pooled`]).
    fn pooled(&self, f: &dyn Fn(&super::features::Features) -> f64) -> (f64, Vec<f64>) {
        let null: Vec<&[Member]> = self.null.iter().map(Vec::as_slice).collect();
        pooled(self.train, &null, f)
    }

    /// Pooled regression coefficients of noise-free simulations with `effects`.
    fn noise_free(&self, effects: &[Effect]) -> [f64; N_REG] {
        let quiet = self.model.noise_free();
        let coefs: Vec<[f64; N_REG]> = self
            .train
            .par_iter()
            .map(|r| simulate_features(r, &quiet, effects, 1))
            .collect();
        std::array::from_fn(|i| mean(coefs.iter().map(|c| c[i])))
    }
}

/// Pooled value of `f`: its mean over `runs`, and over each replica of their ensembles
/// in `null` ([`pooled_replicas`]).
fn pooled(
    runs: &[&RealRun],
    null: &[&[Member]],
    f: &dyn Fn(&super::features::Features) -> f64,
) -> (f64, Vec<f64>) {
    let real = mean(runs.iter().map(|r| f(&r.features)));
    (real, pooled_replicas(null, f))
}

/// The mean of `f` over each replica of the runs' ensembles `members`: member `j` of
/// every run makes replica `j`, as many as the smallest ensemble holds.
fn pooled_replicas(
    members: &[&[Member]],
    f: &dyn Fn(&super::features::Features) -> f64,
) -> Vec<f64> {
    let replicas = members.iter().map(|m| m.len()).min().unwrap_or(0);
    (0..replicas)
        .map(|j| mean(members.iter().map(|m| f(&m[j].features))))
        .collect()
}

/// What the regression fits share: the noise-free coefficients without any effect, and
/// the effects already established from direct evidence (a clock error from the time
/// stamps), on top of which the others are fitted.
struct Known {
    quiet: [f64; N_REG],
    effects: Vec<Effect>,
    /// Noise-free coefficients with `effects`.
    with_effects: [f64; N_REG],
    /// Bias wanders fitted beside: a spread between runs is read against ensembles
    /// simulated with them ([`between_run_fit`]).
    wanders: Vec<Effect>,
}

impl Known {
    fn new(input: &FitInput, quiet: [f64; N_REG], effects: Vec<Effect>) -> Self {
        let with_effects = if effects.is_empty() {
            quiet
        } else {
            input.noise_free(&effects)
        };
        Self {
            quiet,
            effects,
            with_effects,
            wanders: Vec::new(),
        }
    }
}

/// The 95% interval of a regression fit holds the effect's absence: a zero coefficient
/// (ppm, scale, …); for a latency, a delay under `negligible_delay_samples` (`fit.negligible_delay_samples`) of a sample
/// period of `model`; for a bandwidth, a cutoff the effect table counts as neutral (at the
/// Nyquist frequency, the fit's stand-in for no limit) or none (a delay interval reaching
/// zero maps to it).
pub(crate) fn interval_holds_absence(
    fit: &Fit,
    model: &SensorModel,
    negligible_delay_samples: f64,
) -> bool {
    let [(lo, hi)] = fit.ci95.as_slice() else {
        return false;
    };
    let absent = match fit.effect {
        Effect::Bandwidth { .. } => {
            return hi.is_none_or(|cutoff_hz| Effect::Bandwidth { cutoff_hz }.is_neutral(model))
        }
        Effect::Latency { .. } if model.sample_rate_hz > 0.0 => {
            negligible_delay_samples / model.sample_rate_hz
        }
        _ => 0.0,
    };
    lo.is_none_or(|l| l <= absent) && hi.is_none_or(|h| h >= -absent)
}

/// A latency whose whole 95% interval lies under `negligible_delay_samples` of a sample
/// period of `model` (either sign): what it could be is below what the log's timing
/// resolves, so it is not named, however many standard errors it lies from zero (a
/// −57 µs [−85, −28] latency at 1 kHz beside a rate random walk, whose wander the
/// acceleration regression reads a little of). False for the other effects.
pub(crate) fn negligible(fit: &Fit, model: &SensorModel, negligible_delay_samples: f64) -> bool {
    let (Effect::Latency { .. }, [(Some(lo), Some(hi))]) = (fit.effect, fit.ci95.as_slice()) else {
        return false;
    };
    let bound_s = negligible_delay_samples / model.sample_rate_hz;
    bound_s.is_finite() && lo.abs() < bound_s && hi.abs() < bound_s
}

/// Effects which [`Joint`] refits given the others: those fitted from the joint
/// regression; the spread of the bias between runs, into which a deterministic effect
/// leaks by as much as the runs' turns differ (a 50 ms latency: σ 0.036 °/s over four
/// runs of one bias) and which a wander spreads too; and a wander, whose excess holds
/// what deterministic effects leave in the residual.
fn conditional(effect: &Effect) -> bool {
    matches!(
        effect.info().fit,
        FitProcedure::Regression { .. } | FitProcedure::BetweenRunSpread | FitProcedure::Wander(_)
    )
}

/// A bias wander, whose ensembles a spread between runs is read against beside it.
fn wander(effect: &Effect) -> bool {
    matches!(effect.info().fit, FitProcedure::Wander(_))
}

/// Deterministic effects, which a noise-free calibration can hold as known.
fn deterministic(effect: &Effect) -> bool {
    matches!(
        effect.info().fit,
        FitProcedure::Regression { .. } | FitProcedure::StampedClock | FitProcedure::Plateau
    )
}

/// Joint fits of a set of effects: each regression-based effect refitted with the others
/// of the set (and the stamped clock) held as known, one pass in the set's order. Each
/// effect alone is fitted against the nominal model, which misses products of effects
/// (a 1% scale factor makes a latency look 1% longer); held-out statistics resolve such
/// differences, so sets are scored with their joint fits. Cached per set.
pub struct Joint<'a> {
    input: &'a FitInput<'a>,
    quiet: [f64; N_REG],
    clock: Vec<Effect>,
    cache: std::sync::Mutex<std::collections::BTreeMap<String, Vec<Option<Fit>>>>,
}

impl Joint<'_> {
    /// The effects held as known under every fit: the clock, stamped or read from the
    /// lag line.
    pub fn known(&self) -> &[Effect] {
        &self.clock
    }

    /// The refitted fit of each effect of `set` (`None`: kept as fitted alone).
    pub fn fits(&self, set: &[Effect]) -> Vec<Option<Fit>> {
        if set.len() < 2 || !set.iter().any(conditional) {
            return vec![None; set.len()];
        }
        let key = format!("{set:?}");
        if let Some(hit) = self.cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
            return hit;
        }
        let mut current = set.to_vec();
        let mut out = vec![None; set.len()];
        for i in 0..set.len() {
            if !conditional(&set[i]) {
                continue;
            }
            let others = known_besides(&self.clock, &current, i);
            let wanders: Vec<Effect> = match set[i].info().fit {
                FitProcedure::BetweenRunSpread => (current.iter().enumerate())
                    .filter(|&(j, e)| j != i && wander(e))
                    .map(|(_, e)| *e)
                    .collect(),
                _ => Vec::new(),
            };
            if others.len() == self.clock.len() && wanders.is_empty() {
                continue;
            }
            // A wander beside deterministic effects is read against ensembles simulated
            // with them: alone, its Allan-variance excess over the nominal model holds
            // what they leave in the residual (a 50 ms latency read as a random walk of
            // 0.044 °/s/√s).
            let beside_null = wander(&set[i]).then(|| {
                let members = |_: usize| self.input.settings.fit.wander_gain_members;
                let train = simulate_runs_with(self.input, self.input.train, 0, &others, &members);
                let first = self.input.train.len();
                let holdout =
                    simulate_runs_with(self.input, self.input.holdout, first, &others, &members);
                (train, holdout)
            });
            let beside = beside_null.as_ref().map(|(train, holdout)| FitInput {
                null: train,
                holdout_null: holdout,
                null_effects: &others,
                ..*self.input
            });
            let input = beside.as_ref().unwrap_or(self.input);
            let known = Known {
                wanders,
                ..Known::new(input, self.quiet, others.clone())
            };
            if let Ok(f) = fit_one(input, &known, set[i].info()) {
                current[i] = f.effect;
                out[i] = Some(f);
            }
        }
        if let Ok(mut c) = self.cache.lock() {
            c.insert(key, out.clone());
        }
        out
    }

    /// The effects of `set` with their joint fits.
    pub fn effects(&self, set: &[Effect]) -> Vec<Effect> {
        set.iter()
            .zip(self.fits(set))
            .map(|(e, f)| f.map_or(*e, |f| f.effect))
            .collect()
    }
}

/// The effects held as known when member `i` of `set` is refitted: the stamped `clock`
/// and the set's other deterministic effects. The clock is known whether or not the set
/// names it, and counted once (added twice, a −1091 ppm clock simulated as −2182 ppm
/// moved the scale refitted beside it by 0.11%).
fn known_besides(clock: &[Effect], set: &[Effect], i: usize) -> Vec<Effect> {
    clock
        .iter()
        .chain(
            set.iter()
                .enumerate()
                .filter(|(j, e)| *j != i && !clock.iter().any(|c| c.id() == e.id()))
                .map(|x| x.1),
        )
        .copied()
        .filter(deterministic)
        .collect()
}

#[cfg(test)]
mod known_tests {
    use super::*;

    #[test]
    fn the_stamped_clock_is_known_once() {
        let clock = [Effect::ClockError { ppm: -1091.0 }];
        let set = [
            Effect::Latency { delay_s: 0.013 },
            Effect::ScaleFactor { k: 0.006 },
            Effect::ClockError { ppm: -1091.0 },
        ];
        let known = known_besides(&clock, &set, 1);
        assert_eq!(
            known,
            vec![clock[0], Effect::Latency { delay_s: 0.013 }],
            "{known:?}"
        );
        assert_eq!(known_besides(&[], &set, 0).len(), 2);
    }
}

/// Relative mismatch at which the gain calibration stops iterating.
const CALIBRATION_TOL: f64 = 2e-4;

/// Fit every effect of the vocabulary on the training runs (alone, on top of a clock
/// error seen in the time stamps), and the context for joint fits of sets.
pub fn fit_all<'a>(input: &'a FitInput<'a>) -> (Vec<Fit>, Vec<Untestable>, Joint<'a>) {
    let mut fits = Vec::new();
    let mut untestable = Vec::new();
    let quiet = input.noise_free(&[]);
    let mut clock: Vec<Effect> = clock_fit(input)
        .ok()
        .filter(|f| f.passes)
        .map(|f| f.effect)
        .into_iter()
        .collect();
    // A count-stamped clock whose lag grows beyond the per-sample statistics' reach is
    // read from the lag lines and held as known, like the stamped one.
    let grown = input.grown_clock;
    clock.extend(grown.iter().map(|f| f.effect));
    let known = Known::new(input, quiet, clock.clone());
    for info in EFFECTS {
        let fitted = match &grown {
            Some(f) if f.effect.id() == info.id => Ok((*f).clone()),
            _ => fit_one(input, &known, info),
        };
        let fitted = fitted.and_then(|f| {
            let finite = f.effect.params().iter().all(|v| v.is_finite())
                && f.ci95
                    .iter()
                    .all(|(lo, hi)| !lo.is_some_and(f64::is_nan) && !hi.is_some_and(f64::is_nan));
            if finite {
                Ok(f)
            } else {
                Err(FitError::NotFinite)
            }
        });
        match fitted {
            Ok(f) => fits.push(f),
            Err(reason) => untestable.push(Untestable {
                id: info.id,
                reason: reason.to_string(),
            }),
        }
    }
    let joint = Joint {
        input,
        quiet,
        clock,
        cache: Default::default(),
    };
    (fits, untestable, joint)
}

/// A regression-coefficient effect: estimate, null z, gain-corrected parameter and CI.
///
/// `make` takes the first-order parameter, `to_param` maps a coefficient change to it.
/// The estimate is the coefficient's excess over the null replicas, less what the known
/// effects give; the parameter is the one whose noise-free simulation of the training
/// runs (with the known effects) shows that excess: one gain step, then, for a candidate
/// ([`RegressionFit::screens`]), secant steps until it matches within
/// [`CALIBRATION_TOL`] (held-out statistics resolve strong effects to a fraction of a
/// percent).
fn regression_fit(
    input: &FitInput,
    known: &Known,
    index: usize,
    make: &dyn Fn(f64) -> Effect,
    to_param: &dyn Fn(f64) -> f64,
) -> RegressionFit {
    let scatter_p = input.settings.fit.scatter_p;
    let test = CoefficientTest::of(&run_coefficients(input.train, input.null, index), scatter_p);
    let holdout_z = replication_z(
        &run_coefficients(input.holdout, input.holdout_null, index),
        scatter_p,
    );
    let raw = test.deviation - (known.with_effects[index] - known.quiet[index]);
    let s = input.settings;
    let mut half =
        s.tests.interval_z * test.replica_sd * (1.0 + 1.0 / test.replicas.max(1) as f64).sqrt();
    if let Some(scatter) = test.wider_scatter() {
        half = half.max(t95(scatter.runs - 1) * scatter.se);
    }
    let se = test.se();
    let z = raw / se;
    let screened = RegressionFit::screens(z, holdout_z, input);
    let response = |x: f64| -> f64 {
        let mut set = known.effects.clone();
        set.push(make(to_param(x)));
        input.noise_free(&set)[index] - known.with_effects[index]
    };
    // x: the coefficient change the parameter would give at unit gain.
    let mut x = raw;
    if to_param(raw) != 0.0 && to_param(raw).is_finite() {
        let r0 = response(raw);
        let g = r0 / raw;
        let ratio = s.fit.gain_ratio_max;
        if g.is_finite() && g > 1.0 / ratio && g < ratio {
            x = raw / g;
            if screened {
                let (mut xa, mut ra) = (raw, r0);
                for _ in 0..4 {
                    let rb = response(x);
                    if (rb - raw).abs() <= CALIBRATION_TOL * raw.abs() {
                        break;
                    }
                    let slope = (rb - ra) / (x - xa);
                    let next = x + (raw - rb) / slope;
                    if !(slope.is_finite() && slope > 0.0 && next.is_finite())
                        || (next / raw).abs() > ratio
                    {
                        break;
                    }
                    (xa, ra) = (x, rb);
                    x = next;
                }
            }
        }
    }
    let gain = if x != 0.0 { raw / x } else { 1.0 };
    // Plus the systematic allowance of the simulation-calibrated gain.
    let half = (half * half + (s.fit.systematic_rel * raw).powi(2)).sqrt();
    let (lo, hi) = ((raw - half) / gain, (raw + half) / gain);
    RegressionFit {
        effect: make(to_param(x)),
        z,
        holdout_z,
        ci: (to_param(lo), to_param(hi)),
    }
}

/// A regression effect fitted on the training runs, with its coefficient's z-scores in
/// the coefficient's direction.
struct RegressionFit {
    effect: Effect,
    /// The training runs' z, less what the known effects give.
    z: f64,
    /// The held-out runs' z against their null replicas (NaN without held-out runs).
    holdout_z: f64,
    /// The parameter's 95% interval, in the order of the coefficient's bounds.
    ci: (f64, f64),
}

impl RegressionFit {
    /// The test in direction `sign` (+1: the coefficient's; −1 for readings that negate
    /// it; `two_sided` tests take |z|) passes on the training runs, or on all the runs:
    /// each half shows the coefficient at least `tests.replication_z` standard errors from
    /// its null in the same direction (so the interval fitted on the training runs does
    /// not hold the effect's absence), and the two pooled ([`pooled_z`]) reach
    /// `tests.z_critical`. A weak effect's coefficient is then tested on every run at the
    /// same bound (either test alone has its false-alarm rate; the held-out runs must
    /// still qualify it, `select`).
    fn passes(
        tests: &crate::settings::Tests,
        z: f64,
        holdout_z: f64,
        (train_runs, holdout_runs): (usize, usize),
        sign: f64,
        two_sided: bool,
    ) -> bool {
        let (z, holdout_z) = (sign * z, sign * holdout_z);
        let judge = |v: f64| if two_sided { v.abs() } else { v };
        if judge(z) >= tests.z_critical {
            return true;
        }
        let pooled = pooled_z(z, train_runs, holdout_z, holdout_runs);
        judge(z) >= tests.replication_z
            && holdout_z * z.signum() >= tests.replication_z
            && pooled * z.signum() >= tests.z_critical
    }

    /// Screened for calibration: passes two-sided in the coefficient's direction.
    fn screens(z: f64, holdout_z: f64, input: &FitInput) -> bool {
        Self::passes(
            &input.settings.tests,
            z,
            holdout_z,
            Self::runs(input),
            1.0,
            true,
        )
    }

    /// Training and held-out runs.
    fn runs(input: &FitInput) -> (usize, usize) {
        (input.train.len(), input.holdout.len())
    }

    /// The fit judged in direction `sign`, `two_sided` or not, with the interval
    /// `ci95`.
    fn judged(
        self,
        input: &FitInput,
        sign: f64,
        ci95: Vec<(Option<f64>, Option<f64>)>,
        two_sided: bool,
        test: &str,
    ) -> Fit {
        let (z, holdout_z) = (sign * self.z, sign * self.holdout_z);
        let runs = Self::runs(input);
        let tests = &input.settings.tests;
        let mut fit = judged(tests.z_critical, self.effect, z, ci95, two_sided, test);
        fit.holdout_z = holdout_z.is_finite().then_some(holdout_z);
        if !fit.passes && Self::passes(tests, self.z, self.holdout_z, runs, sign, two_sided) {
            fit.passes = true;
            let pooled = pooled_z(z, runs.0, holdout_z, runs.1);
            fit.test = format!(
                "{test}; z {z:.1} on the training runs, {pooled:.1} pooled with the held-out runs"
            );
        }
        fit
    }
}

/// The real runs' own scatter of one regression coefficient, when it is larger than
/// the null replicas' beyond chance.
struct Scatter {
    /// Standard error of the runs' mean coefficient from their scatter.
    se: f64,
    /// Runs.
    runs: usize,
}

/// The null replicas give each coefficient's spread under the nominal model; something
/// the nominal model lacks and that moves every run differently (a bias that wanders
/// along the motion by chance) spreads the real runs' coefficients further, and a test
/// against the null alone then finds a scale or a temperature term in a random walk.
/// Each run's excess over its own replicas' mean is compared with a replica's spread
/// about that mean: when their variance exceeds the null's beyond chance (χ² with
/// runs − 1 degrees of freedom, one-sided `scatter_p`, the setting `fit.scatter_p`), the runs' own standard error
/// is returned. `None`: fewer than 3 runs, or no excess scatter.
/// On each run's real value and its replicas' values ([`run_coefficients`]).
fn scatter_of(runs: &[(f64, Vec<f64>)], scatter_p: f64) -> Option<Scatter> {
    let mut excess = Vec::new();
    let mut null_var = Vec::new();
    for (real, coefs) in runs {
        let (m, sd) = mean_sd(coefs);
        if real.is_finite() && m.is_finite() && sd.is_finite() {
            excess.push(real - m);
            null_var.push(sd * sd);
        }
    }
    let n = excess.len();
    if n < 3 {
        return None;
    }
    let between = sample_var(&excess);
    let null = null_var.iter().sum::<f64>() / n as f64;
    let dof = (n - 1) as f64;
    (between * dof > chi2_quantile(scatter_p, dof) * null).then(|| Scatter {
        se: (between / n as f64).sqrt(),
        runs: n,
    })
}

#[cfg(test)]
mod scatter_tests {
    use super::*;

    /// Replicas spread ±1 about 0 (sample sd 1), one per run.
    fn replicas() -> Vec<f64> {
        vec![-1.0, 1.0, -1.0, 1.0, 0.0, 0.0]
    }

    #[test]
    fn runs_within_the_null_spread_keep_the_null_test() {
        // A constant excess (a real effect the same in every run) plus scatter like the
        // null's: the null's standard error stands.
        let runs: Vec<_> = [5.3, 4.1, 5.9, 4.6, 5.0]
            .iter()
            .map(|&x| (x, replicas()))
            .collect();
        assert!(scatter_of(&runs, Settings::DEFAULT.fit.scatter_p).is_none());
    }

    #[test]
    fn runs_scattered_beyond_the_null_give_their_own_error() {
        // Excesses of ±6 where the replicas spread ±1 (a wander the null lacks): the
        // runs' standard error, sd / √n.
        let values = [6.0, -5.0, 7.0, -6.0, 4.0];
        let runs: Vec<_> = values.iter().map(|&x| (x, replicas())).collect();
        let s =
            scatter_of(&runs, Settings::DEFAULT.fit.scatter_p).expect("scatter beyond the null");
        let (_, sd) = mean_sd(&values);
        assert_eq!(s.runs, 5);
        assert!((s.se - sd / 5f64.sqrt()).abs() < 1e-12, "{}", s.se);
        // Fewer than 3 runs: no scatter to judge.
        assert!(scatter_of(&runs[..2], Settings::DEFAULT.fit.scatter_p).is_none());
        // A run without a finite coefficient is left out.
        let mut with_nan = runs.clone();
        with_nan.push((f64::NAN, replicas()));
        assert_eq!(
            scatter_of(&with_nan, Settings::DEFAULT.fit.scatter_p).map(|s| s.runs),
            Some(5)
        );
    }
}

/// Clock error from the time stamps ([`StampedClock`]): the training runs' mean ppm,
/// tested against its standard error (between-run scatter and each run's stamp
/// scatter; at least 0.01 ppm).
fn clock_fit(input: &FitInput) -> Result<Fit, FitError> {
    let clocks: Option<Vec<StampedClock>> = input.train.iter().map(|r| r.clock).collect();
    let Some(clocks) = clocks else {
        return Err(FitError::NoNominalRate);
    };
    let ppm: Vec<f64> = clocks.iter().map(|c| c.ppm).collect();
    let n = ppm.len() as f64;
    let m = ppm.iter().sum::<f64>() / n;
    let between = if ppm.len() > 1 { sample_var(&ppm) } else { 0.0 };
    let within = clocks.iter().map(|c| c.se_ppm * c.se_ppm).sum::<f64>() / n;
    let se = ((between + within) / n).sqrt().max(0.01);
    let z = m / se;
    let half = t95(ppm.len().saturating_sub(1)).max(input.settings.tests.interval_z) * se;
    Ok(Fit {
        effect: Effect::ClockError { ppm: m },
        ci95: vec![(Some(m - half), Some(m + half))],
        z,
        passes: z.abs() >= input.settings.tests.z_critical,
        test: "time stamps' period vs the nominal sample rate".into(),
        direct: false,
        holdout_z: None,
        shape_loglik: None,
    })
}

/// Why an effect cannot be fitted on these training runs.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub(crate) enum FitError {
    /// No nominal sample rate to compare the time stamps with.
    #[error(
        "needs the nominal sample rate (`# sample_rate_hz` metadata or \
         --sample-rate-hz): a clock error shows as time stamps drifting from it"
    )]
    NoNominalRate,
    /// The temperature does not vary enough.
    #[error(
        "needs a temperature column that varies by at least {min_c} degC in every training run"
    )]
    NoTemperatureChange {
        /// The smallest range that counts (`statistics.min_temperature_range_c`, °C).
        min_c: f64,
    },
    /// Fewer than 3 training runs for a between-run spread.
    #[error("needs at least 3 training runs (between-run spread of the bias)")]
    TooFewRunsForSpread,
    /// Fewer than 2 training runs long enough for the wander's Allan variance.
    #[error("needs at least 2 training runs longer than {min_s} s")]
    TooShortForWander {
        /// Shortest usable run (s).
        min_s: f64,
    },
    /// The residual regression has no estimate for the effect's regressor.
    #[error(
        "needs training runs whose motion determines it: the residual regression on {regressor} \
         has no estimate (runs too short, or without rotations)"
    )]
    NoRegression {
        /// What the regressor is.
        regressor: &'static str,
    },
    /// No run has a stretch of residuals long enough for the line spectrum.
    #[error("needs stretches of at least {segment_s} s of residuals in every run (the line spectrum's segment)")]
    NoSpectrum {
        /// Segment length (s).
        segment_s: f64,
    },
    /// The fit gave a parameter or a bound that is not a number.
    #[error("the fit gives no finite estimate on these runs (too short, or too little motion)")]
    NotFinite,
    /// The table pairs the effect with a procedure for another number of parameters.
    #[error("effect `{id}`: its fitting procedure fits {expected} parameter(s)")]
    ParamCount {
        /// Effect id.
        id: &'static str,
        /// Parameters the procedure fits.
        expected: usize,
    },
}

/// The z-score of a test whose outcome is exact (no null distribution).
const EXACT: f64 = f64::NAN;

/// A fit judged by its z-score: passes when |z| (two-sided) or z (one-sided) reaches
/// `tests.z_critical`.
fn judged(
    z_critical: f64,
    effect: Effect,
    z: f64,
    ci95: Vec<(Option<f64>, Option<f64>)>,
    two_sided: bool,
    test: &str,
) -> Fit {
    let passes = if two_sided {
        z.abs() >= z_critical
    } else {
        z >= z_critical
    };
    Fit {
        effect,
        ci95,
        z,
        passes,
        test: test.to_string(),
        direct: false,
        holdout_z: None,
        shape_loglik: None,
    }
}

/// An ordered interval of two bounds.
fn ordered((a, b): (f64, f64)) -> Vec<(Option<f64>, Option<f64>)> {
    vec![(Some(a.min(b)), Some(a.max(b)))]
}

/// `info`'s effect from its single parameter (for the procedures that fit one).
fn single_param(info: &'static EffectInfo) -> Result<impl Fn(f64) -> Effect, FitError> {
    if info.params.len() != 1 {
        return Err(FitError::ParamCount {
            id: info.id,
            expected: 1,
        });
    }
    Ok(move |v: f64| info.typical.with_params(&[v]).unwrap_or(info.typical))
}

/// What the regression column `index` is, for a reason given to the user.
fn regressor_name(index: usize) -> &'static str {
    match index {
        reg::RATE => "the reference rate",
        reg::ABS_RATE => "the absolute reference rate",
        reg::RATE_CUBED => "the cubed reference rate",
        reg::RATE_SQUARED => "the squared reference rate",
        reg::ACCELERATION => "the angular acceleration",
        reg::TIME_ACCELERATION => "time times the angular acceleration",
        reg::DELTA_T => "the temperature change",
        reg::RATE_DELTA_T => "the rate times the temperature change",
        _ => "its regressor",
    }
}

/// The column of the residual regression for `regressor`.
fn regressor_index(regressor: Regressor) -> usize {
    match regressor {
        Regressor::Rate => reg::RATE,
        Regressor::AbsRate => reg::ABS_RATE,
        Regressor::RateCubed => reg::RATE_CUBED,
        Regressor::RateSquared => reg::RATE_SQUARED,
        Regressor::Acceleration => reg::ACCELERATION,
        Regressor::TimeAcceleration => reg::TIME_ACCELERATION,
        Regressor::DeltaT => reg::DELTA_T,
        Regressor::RateDeltaT => reg::RATE_DELTA_T,
    }
}

/// Fit the effect of table entry `info` with its procedure.
fn fit_one(input: &FitInput, known: &Known, info: &'static EffectInfo) -> Result<Fit, FitError> {
    match info.fit {
        FitProcedure::Regression {
            regressor,
            reading,
            needs_temperature,
            test,
        } => {
            if needs_temperature && !input.temperature_ok {
                return Err(FitError::NoTemperatureChange {
                    min_c: input.settings.statistics.min_temperature_range_c,
                });
            }
            let index = regressor_index(regressor);
            regression_procedure(input, known, info, index, reading, test)
        }
        FitProcedure::StampedClock => clock_fit(input),
        FitProcedure::BetweenRunSpread => between_run_fit(input, known, info),
        FitProcedure::Wander(shape) => wander_fit(input, info, shape),
        FitProcedure::Plateau => plateau_fit(input, info),
        FitProcedure::OutputGrid => grid_fit(input, info),
        FitProcedure::Gaps => gaps_fit(input, info),
        FitProcedure::SpectralLine => line_fit(input, info),
    }
}

/// A parameter read from the regression coefficient of column `index`
/// ([`regression_fit`]).
fn regression_procedure(
    input: &FitInput,
    known: &Known,
    info: &'static EffectInfo,
    index: usize,
    reading: Reading,
    test: &str,
) -> Result<Fit, FitError> {
    let make = single_param(info)?;
    // Runs too short, or without the motion the regressor needs, leave the regression
    // without an estimate: untestable, never a NaN fit.
    let (real, replicas) = input.pooled(&|f| f.coef[index]);
    let finite_replicas = replicas.iter().filter(|c| c.is_finite()).count();
    if !real.is_finite() || finite_replicas < 2 {
        return Err(FitError::NoRegression {
            regressor: regressor_name(index),
        });
    }
    Ok(match reading {
        Reading::Coefficient => {
            let f = regression_fit(input, known, index, &make, &|x| x);
            let ci = ordered(f.ci);
            f.judged(input, 1.0, ci, true, test)
        }
        Reading::CubicCoefficient => {
            let scale = CUBIC_SCALE_DPS.powi(3);
            let f = regression_fit(input, known, index, &make, &|x| x / scale);
            let ci = ordered(f.ci);
            f.judged(input, 1.0, ci, true, test)
        }
        Reading::SquareCoefficient => {
            let scale = CUBIC_SCALE_DPS.powi(2);
            let f = regression_fit(input, known, index, &make, &|x| x / scale);
            let ci = ordered(f.ci);
            f.judged(input, 1.0, ci, true, test)
        }
        Reading::Delay => {
            let range = info.params[0].range;
            let make = |d: f64| make(range.clamp(d));
            let f = regression_fit(input, known, index, &make, &|x| -x);
            let ci = ordered(f.ci);
            f.judged(input, -1.0, ci, true, test)
        }
        Reading::ClockPpm => {
            let range = info.params[0].range;
            let make = |p: f64| make(range.clamp(p));
            let f = regression_fit(input, known, index, &make, &|x| -x * 1e6);
            let ci = ordered(f.ci);
            f.judged(input, -1.0, ci, true, test)
        }
        Reading::LowPassDelay => {
            // A two-pole low-pass delays slow motion by a delay inverse to its cutoff
            // (`low_pass_delay_s`): fitted as a delay (its first-order parameter),
            // calibrated as a low-pass.
            let nyquist = 0.5 * input.model.sample_rate_hz;
            let to_cutoff = |d: f64| -> f64 {
                if d > 0.0 {
                    gyro_sim::low_pass_cutoff_hz(d).min(nyquist)
                } else {
                    nyquist
                }
            };
            let make = |d: f64| make(to_cutoff(d));
            let f = regression_fit(input, known, index, &make, &|x| -x);
            // Interval: the (calibrated) delay's, mapped like the estimate.
            let (d_lo, d_hi) = (f.ci.0.min(f.ci.1), f.ci.0.max(f.ci.1));
            let bound = |dd: f64| (dd > 0.0).then(|| to_cutoff(dd));
            f.judged(input, -1.0, vec![(bound(d_hi), bound(d_lo))], false, test)
        }
    })
}

/// A between-run spread of the bias: σ² is the runs' variance less the replicas'
/// ([`bias_spread`]), with χ² bounds.
fn between_run_fit(
    input: &FitInput,
    known: &Known,
    info: &'static EffectInfo,
) -> Result<Fit, FitError> {
    let single = single_param(info)?;
    if input.train.len() < 3 {
        return Err(FitError::TooFewRunsForSpread);
    }
    let beside_wanders =
        (!known.wanders.is_empty()).then(|| simulate_train_with(input, &known.wanders));
    let null = beside_wanders.as_deref().unwrap_or(input.null);
    let (z, s2, v0, k) = bias_spread(input.train, null, input.model, &known.effects);
    let sigma = (s2 - v0).max(0.0).sqrt();
    let lo = (k * s2 / chi2_quantile(0.975, k) - v0).max(0.0).sqrt();
    let hi = (k * s2 / chi2_quantile(0.025, k) - v0).max(0.0).sqrt();
    Ok(Fit {
        direct: true,
        ..judged(
            input.settings.tests.z_critical,
            single(sigma),
            z,
            vec![(Some(lo), Some(hi))],
            false,
            "between-run variance of the bias vs null replicas (chi-square, one-sided; \
             replicated on the held-out runs)",
        )
    })
}

/// A bias wander of `shape` from the Allan variance of the residual at long τ.
fn wander_fit(
    input: &FitInput,
    info: &'static EffectInfo,
    shape: WanderShape,
) -> Result<Fit, FitError> {
    let single = single_param(info)?;
    let usable = input
        .train
        .iter()
        .filter(|r| r.features.wander_avar[2].is_finite())
        .count();
    if usable < 2 {
        return Err(FitError::TooShortForWander {
            min_s: 2.0 * WANDER_TAUS_S[2],
        });
    }
    let per_tau = wander_per_tau(input, shape);
    // Per run: the excess over that run's own ensemble mean.
    let per_run = |avar: &[f64; 3], members: &[Member]| {
        wander_shape_solve(&per_tau, &|k| {
            avar[k] - mean(members.iter().map(|m| m.features.wander_avar[k]))
        })
    };
    let (thetas, s_theta) = wander_excess(input.train, input.null, &per_run);
    let (mut theta, sd) = mean_sd(&thetas);
    let z = theta / s_theta;
    // The same estimator (the training runs' weights) on the held-out runs: the
    // replication of the wander ([`replicates`]).
    let holdout_z = {
        let (thetas, s) = wander_excess(input.holdout, input.holdout_null, &per_run);
        let z = mean(thetas.iter().copied()) / s;
        (thetas.len() >= 2 && z.is_finite()).then_some(z)
    };
    let mut half = t95(thetas.len().saturating_sub(1)) * sd / (thetas.len() as f64).sqrt();
    let make = |theta: f64| single(theta.max(0.0).sqrt());
    let mut overshoot = None;
    let mut shape_loglik = None;
    if z >= input.settings.tests.z_critical && theta > 0.0 {
        let sims = simulate_train_with(input, &[make(theta)]);
        let gain = mean_wander_response(input, &sims, &per_run) / theta;
        let ratio = input.settings.fit.wander_gain_ratio_max;
        let gain = if gain.is_finite() && gain > 1.0 / ratio && gain < ratio {
            theta /= gain;
            half /= gain;
            gain
        } else {
            1.0
        };
        // The shape: the wander fitted (mostly at 1 s, where the replicas scatter least)
        // must not predict far more wander at any τ than the runs show, training and
        // held-out pooled (one minute holds about three 16 s windows).
        let observed: Vec<(f64, f64)> =
            per_tau.iter().map(|&(real, m0, _, _)| (real, m0)).collect();
        let terms = shape_terms(input, &observed, &sims, gain);
        overshoot = wander_overshoot(&terms, input.settings.fit.wander_overshoot);
        shape_loglik = wander_shape_loglik(&terms);
    }
    let lo = (theta - half).max(0.0).sqrt();
    let hi = (theta + half).max(0.0).sqrt();
    let test = "Allan variance of the regression residual at 1/4/16 s vs null replicas (one-sided)";
    let mut fit = judged(
        input.settings.tests.z_critical,
        make(theta),
        z,
        vec![(Some(lo), Some(hi))],
        false,
        test,
    );
    fit.holdout_z = holdout_z;
    fit.shape_loglik = shape_loglik.filter(|_| fit.passes);
    if let Some((tau, ratio)) = overshoot.filter(|_| fit.passes) {
        fit.passes = false;
        fit.test = format!(
            "{test}, and its shape: at {tau} s the fitted wander's Allan variance is {ratio:.0} \
             times the runs' (more than {}: not a bias wander)",
            input.settings.fit.wander_overshoot
        );
    }
    Ok(fit)
}

/// Per τ of [`WANDER_TAUS_S`]: the training runs' pooled Allan variance of the residual,
/// the mean and standard deviation of their null replicas' ((deg/s)²), and the Allan
/// variance of a unit wander of `shape` at that τ.
fn wander_per_tau(input: &FitInput, shape: WanderShape) -> Vec<(f64, f64, f64, f64)> {
    let shape_at = |tau: f64| -> f64 {
        match shape {
            WanderShape::RandomWalk => tau / 3.0,
            WanderShape::Flicker => (0..6)
                .map(|i| gauss_markov_avar_continuous(tau, 1.0, 10f64.powf(0.6 * i as f64)) / 6.0)
                .sum(),
        }
    };
    let mut per_tau = Vec::new();
    for (k, &tau) in WANDER_TAUS_S.iter().enumerate() {
        let (real, replicas) = input.pooled(&|f| f.wander_avar[k]);
        let (m0, s0) = mean_sd(&replicas);
        per_tau.push((real, m0, s0, shape_at(tau)));
    }
    per_tau
}

/// The wander's size θ (σ² or K²) that the Allan variance `excess` over the null at each
/// τ of `per_tau` reads: the weighted least squares of the excess on the shape.
fn wander_shape_solve(per_tau: &[(f64, f64, f64, f64)], excess: &dyn Fn(usize) -> f64) -> f64 {
    // Weighted least squares of the excess on the shape: θ = σ² or K².
    let (mut num, mut den) = (0.0, 0.0);
    for (k, (_, _, s0, f)) in per_tau.iter().enumerate() {
        let w = 1.0 / (s0 * s0).max(1e-30);
        num += w * f * excess(k);
        den += w * f * f;
    }
    num / den
}

/// The training runs simulated with `effect` on the nominal model: per run, as many
/// members as `fit.wander_gain_members` allows (and its null ensemble holds), on the null
/// members' seeds.
fn simulate_train_with(input: &FitInput, effect: &[Effect]) -> Vec<Vec<Member>> {
    let effects: Vec<Effect> = input.null_effects.iter().chain(effect).copied().collect();
    let members = |r: usize| {
        input
            .settings
            .fit
            .wander_gain_members
            .min(input.null[r].len())
    };
    simulate_runs_with(input, input.train, 0, &effects, &members)
}

/// `runs` simulated with `effects` on `input`'s model, `members(r)` members of run `r`,
/// seeded as the ensembles of run index `first + r` are.
fn simulate_runs_with(
    input: &FitInput,
    runs: &[&RealRun],
    first: usize,
    effects: &[Effect],
    members: &(dyn Fn(usize) -> usize + Sync),
) -> Vec<Vec<Member>> {
    (0..runs.len())
        .into_par_iter()
        .map(|r| {
            (0..members(r))
                .map(|j| {
                    simulate_member(
                        runs[r],
                        input.model,
                        effects,
                        super::ensemble::member_seed(input.seed, first + r, j),
                    )
                })
                .collect()
        })
        .collect()
}

/// The wander estimator's mean response to the simulated members `sims` ([`simulate_train_with`]):
/// the mean over members of `per_run` on the simulation minus `per_run` on the null member
/// of the same seed (divided by θ, it is the estimator's gain).
fn mean_wander_response(
    input: &FitInput,
    sims: &[Vec<Member>],
    per_run: &dyn Fn(&[f64; 3], &[Member]) -> f64,
) -> f64 {
    // Gain: the same estimator on the training runs simulated with the
    // effect, against the same seeds without it.
    let gains: Vec<f64> = (0..input.train.len())
        .flat_map(|r| {
            let sims = &sims[r];
            (0..sims.len()).map(move |j| (r, j))
        })
        .map(|(r, j)| {
            let k_sim = per_run(&sims[r][j].features.wander_avar, &input.null[r]);
            let k_null = per_run(&input.null[r][j].features.wander_avar, &input.null[r]);
            k_sim - k_null
        })
        .collect();
    mean(gains.into_iter())
}

/// One τ of a wander's shape evidence ([`wander_shape_loglik`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct ShapeTerm {
    /// The pooled Allan variance of the runs and the mean of their null replicas'
    /// ((deg/s)²), for the training runs and, when at least two measure it, the held-out
    /// runs.
    observed: [Option<(f64, f64)>; 2],
    /// The excess over the null the fitted wander predicts ((deg/s)²).
    excess: f64,
    /// The spread of the pooled value under the fitted wander, relative to its mean.
    relative_sd: f64,
}

/// The shape terms of a wander fitted to `input`'s training runs: `observed` the
/// training runs' pooled Allan variance and their null replicas' mean at each of
/// [`WANDER_TAUS_S`], `sims` the training runs simulated with the wander before its
/// `gain` correction (member `j` of every run pooled makes replica `j`).
fn shape_terms(
    input: &FitInput,
    observed: &[(f64, f64)],
    sims: &[Vec<Member>],
    gain: f64,
) -> Vec<ShapeTerm> {
    let train: Vec<&[Member]> = sims.iter().map(Vec::as_slice).collect();
    // The held-out runs that measure the τ, pooled when at least two do.
    let holdout = |k: usize| -> Option<(f64, f64)> {
        let (runs, null): (Vec<&RealRun>, Vec<&[Member]>) = input
            .holdout
            .iter()
            .zip(input.holdout_null)
            .filter(|(r, m)| r.features.wander_avar[k].is_finite() && !m.is_empty())
            .map(|(r, m)| (*r, m.as_slice()))
            .unzip();
        (runs.len() >= 2).then(|| {
            let (real, replicas) = pooled(&runs, &null, &|f| f.wander_avar[k]);
            (real, mean(replicas.into_iter()))
        })
    };
    observed
        .iter()
        .enumerate()
        .map(|(k, &(real, null))| {
            let (simulated, sd) = mean_sd(&pooled_replicas(&train, &|f| f.wander_avar[k]));
            ShapeTerm {
                observed: [Some((real, null)), holdout(k)],
                excess: (simulated - null) / gain,
                relative_sd: sd / simulated,
            }
        })
        .collect()
}

/// The log-likelihood of the runs' pooled Allan variances at [`WANDER_TAUS_S`] under a
/// fitted wander: at each τ and for the training and the held-out runs, a normal of
/// mean the runs' null mean plus the wander's predicted excess and of the simulated
/// relative spread. A random walk's Allan variance grows as τ, a bias instability's is
/// flat: fitted mostly at 1 s, where the replicas scatter least, each predicts the
/// other's 16 s value several times off. Training and held-out runs are pooled: one
/// minute holds about three 16 s windows, so the shape of five runs is often not
/// decisive. `None` when a term is not finite.
fn wander_shape_loglik(terms: &[ShapeTerm]) -> Option<f64> {
    let mut total = 0.0;
    for t in terms {
        for (real, null) in t.observed.iter().flatten() {
            let predicted = null + t.excess;
            let sd = t.relative_sd * predicted;
            let z = (real - predicted) / sd;
            total += -0.5 * z * z - sd.ln();
        }
    }
    (total.is_finite() && !terms.is_empty()).then_some(total)
}

/// The wander estimator `per_run` (a run's excess over its ensemble's mean, read on the
/// Allan variances at [`WANDER_TAUS_S`]) on each of `runs` that measures it, and its
/// standard deviation under the nominal model: the estimator of the runs' pooled null
/// replicas (member `j` of every run makes replica `j`), each against the pooled mean.
fn wander_excess(
    runs: &[&RealRun],
    null: &[Vec<Member>],
    per_run: &dyn Fn(&[f64; 3], &[Member]) -> f64,
) -> (Vec<f64>, f64) {
    let usable: Vec<usize> = (0..runs.len().min(null.len()))
        .filter(|&r| runs[r].features.wander_avar.iter().all(|v| v.is_finite()))
        .collect();
    let thetas: Vec<f64> = usable
        .iter()
        .map(|&r| per_run(&runs[r].features.wander_avar, &null[r]))
        .filter(|t| t.is_finite())
        .collect();
    let members = usable.iter().map(|&r| null[r].len()).min().unwrap_or(0);
    // Replica j, pooled over the runs, less the pooled replicas' mean, through the same
    // estimator: per_run of each run's member j against its own ensemble is that.
    let null_thetas: Vec<f64> = (0..members)
        .map(|j| {
            mean(
                usable
                    .iter()
                    .map(|&r| per_run(&null[r][j].features.wander_avar, &null[r])),
            )
        })
        .collect();
    let (_, sd) = mean_sd(&null_thetas);
    (thetas, sd)
}

/// The τ (s) and ratio where a fitted wander predicts the most Allan variance against
/// the runs', if more than `overshoot` (`fit.wander_overshoot`) times; `terms` at each of
/// [`WANDER_TAUS_S`]. The runs are the training runs, with the held-out runs' pooled
/// values added when the wander predicts their value at the first τ (1 s, where it is
/// fitted) within the same factor: one minute holds about three 16 s windows, so five
/// runs of a random walk can fall 3 times under its 16 s value by chance, and held-out
/// runs that wander like the training ones tell it; held-out runs whose 1 s value the
/// wander is far from (motion at another speed leaving another residual) cannot vouch
/// for its shape.
fn wander_overshoot(terms: &[ShapeTerm], overshoot: f64) -> Option<(f64, f64)> {
    let ratio =
        |t: &ShapeTerm, half: usize| t.observed[half].map(|(real, null)| (null + t.excess) / real);
    let holdout_alike = terms
        .first()
        .and_then(|t| ratio(t, 1))
        .is_some_and(|r| r.is_finite() && (1.0 / overshoot..=overshoot).contains(&r));
    let halves: &[usize] = if holdout_alike { &[0, 1] } else { &[0] };
    terms
        .iter()
        .zip(WANDER_TAUS_S)
        .map(|(t, tau)| {
            let (predicted, real) = halves
                .iter()
                .filter_map(|&h| t.observed[h])
                .fold((0.0, 0.0), |(p, r), (real, null)| {
                    (p + null + t.excess, r + real)
                });
            (tau, predicted / real)
        })
        .filter(|(_, ratio)| ratio.is_finite() && *ratio > overshoot)
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

#[cfg(test)]
mod wander_shape_tests {
    use super::*;

    /// An interval holds an effect's absence when it reaches a zero coefficient, a delay
    /// under a tenth of a sample, or for a bandwidth, a neutral or unbounded cutoff.
    #[test]
    fn intervals_that_hold_absence() {
        let fit = |effect, lo: Option<f64>, hi: Option<f64>| Fit {
            effect,
            ci95: vec![(lo, hi)],
            z: 5.0,
            passes: true,
            test: String::new(),
            direct: false,
            holdout_z: None,
            shape_loglik: None,
        };
        let holds = |effect, lo, hi, fs| {
            let model = SensorModel {
                sample_rate_hz: fs,
                ..SensorModel::default()
            };
            interval_holds_absence(
                &fit(effect, lo, hi),
                &model,
                Settings::DEFAULT.fit.negligible_delay_samples,
            )
        };
        let latency = Effect::Latency { delay_s: -0.0003 };
        assert!(holds(latency, Some(-0.0025), Some(0.0018), 100.0));
        assert!(!holds(latency, Some(0.0106), Some(0.0125), 100.0));
        assert!(!holds(latency, Some(-0.012), Some(-0.010), 100.0));
        assert!(holds(latency, None, Some(0.01), 100.0));
        // 33 µs [6, 60] at 1 kHz: under a tenth of a sample (0.1 ms); at 100 µs, not.
        assert!(holds(latency, Some(6e-6), Some(6e-5), 1000.0));
        assert!(!holds(latency, Some(1.1e-4), Some(2e-4), 1000.0));
        let scale = Effect::ScaleFactor { k: 1e-5 };
        assert!(!holds(scale, Some(6e-6), Some(6e-5), 1000.0));
        let bandwidth = Effect::Bandwidth { cutoff_hz: 30.0 };
        assert!(holds(bandwidth, Some(20.0), None, 100.0));
        assert!(!holds(bandwidth, Some(20.0), Some(40.0), 100.0));
        assert!(holds(bandwidth, Some(500.0), Some(500.0), 1000.0));
        // Negligible: the whole interval under a tenth of a sample, either sign; only a
        // latency.
        let model = SensorModel::default();
        let negligible_at = |effect, lo, hi| {
            negligible(
                &fit(effect, lo, hi),
                &model,
                Settings::DEFAULT.fit.negligible_delay_samples,
            )
        };
        assert!((model.sample_rate_hz - 1000.0).abs() < 1e-9);
        assert!(negligible_at(latency, Some(-8.5e-5), Some(-2.8e-5)));
        assert!(negligible_at(latency, Some(2e-5), Some(9e-5)));
        assert!(!negligible_at(latency, Some(2e-5), Some(1.2e-4)));
        assert!(!negligible_at(latency, Some(-1.2e-4), Some(-2e-5)));
        assert!(!negligible_at(latency, None, Some(9e-5)));
        assert!(!negligible_at(scale, Some(-1e-5), Some(1e-5)));
    }

    #[test]
    fn a_wander_matching_the_runs_at_every_tau_passes() {
        let per_tau = [
            (0.02, 0.001, 0.021),
            (0.05, 0.0005, 0.06),
            (0.2, 0.0002, 0.3),
        ];
        assert_eq!(
            wander_overshoot(
                &training(&per_tau, 1.0),
                Settings::DEFAULT.fit.wander_overshoot
            ),
            None
        );
    }

    #[test]
    fn a_wander_fitted_at_1_s_that_overshoots_16_s_is_caught() {
        // ssong yaw, slow: the runs' residual fades by 16 s, a random walk grows.
        let per_tau = [
            (0.02, 0.001, 0.02),
            (0.008, 0.0005, 0.03),
            (0.0004, 0.0002, 0.11),
        ];
        let (tau, ratio) = wander_overshoot(
            &training(&per_tau, 1.0),
            Settings::DEFAULT.fit.wander_overshoot,
        )
        .unwrap();
        assert_eq!(tau, 16.0);
        assert!((ratio - 275.0).abs() < 1.0, "{ratio}");
        // The gain correction scales the simulated excess back.
        assert!(wander_overshoot(
            &training(&per_tau, 1000.0),
            Settings::DEFAULT.fit.wander_overshoot
        )
        .is_none());
    }

    #[test]
    fn the_overshoot_reads_the_held_out_runs_too() {
        // Self-test seed 20261204, a 0.02 deg/s/sqrt(s) random walk beside a scale
        // factor ((deg/s)²): the training runs wandered little at 16 s (the random walk
        // fitted to them predicts 3.4 times their value), the held-out runs twice the
        // prediction.
        let rows = [
            (1.807e-4, 4.153e-5, 1.368e-4, 1.979e-4, 3.975e-5),
            (3.376e-4, 5.990e-5, 3.265e-4, 3.875e-4, 5.837e-5),
            (1.698e-4, 1.029e-4, 5.698e-4, 1.181e-3, 9.447e-5),
        ];
        let mut terms = training(&rows.map(|(r, n, p, _, _)| (r, n, p)), 1.0);
        let (tau, ratio) =
            wander_overshoot(&terms, Settings::DEFAULT.fit.wander_overshoot).unwrap();
        assert_eq!(tau, 16.0);
        assert!((ratio - 3.36).abs() < 0.01, "{ratio}");
        for (t, (_, _, _, real, null)) in terms.iter_mut().zip(rows) {
            t.observed[1] = Some((real, null));
        }
        assert_eq!(
            wander_overshoot(&terms, Settings::DEFAULT.fit.wander_overshoot),
            None
        );
        // ssong yaw, slow → medium: the medium runs' 1 s value is 60 times what a wander
        // fitted to the slow runs predicts; they cannot vouch for its shape.
        let slow = [
            (2.0e-4, 4.0e-5, 2.0e-4),
            (2.0e-4, 5.0e-5, 1.4e-4),
            (1.0e-5, 8.0e-6, 9.7e-5),
        ];
        let mut terms = training(&slow, 1.0);
        for (t, scale) in terms.iter_mut().zip([60.0, 6.0, 1.5]) {
            let predicted = t.observed[0].map_or(0.0, |(_, null)| null + t.excess);
            t.observed[1] = Some((predicted * scale, t.observed[0].map_or(0.0, |o| o.1)));
        }
        let (tau, ratio) =
            wander_overshoot(&terms, Settings::DEFAULT.fit.wander_overshoot).unwrap();
        assert_eq!(tau, 16.0);
        assert!((ratio - 9.7).abs() < 0.01, "{ratio}");
    }

    /// Shape terms of the training runs alone from (real, null, simulated) per τ and a
    /// gain.
    fn training(per_tau: &[(f64, f64, f64)], gain: f64) -> Vec<ShapeTerm> {
        per_tau
            .iter()
            .map(|&(real, null, simulated)| ShapeTerm {
                observed: [Some((real, null)), None],
                excess: (simulated - null) / gain,
                relative_sd: 0.3,
            })
            .collect()
    }

    /// Shape terms from (training real, null, predicted, spread of the prediction) and
    /// (held-out real, null) at 1, 4 and 16 s.
    fn terms(rows: [[f64; 6]; 3], holdout: bool) -> Vec<ShapeTerm> {
        rows.iter()
            .map(|&[real, null, predicted, sd, h_real, h_null]| ShapeTerm {
                observed: [Some((real, null)), holdout.then_some((h_real, h_null))],
                excess: predicted - null,
                relative_sd: sd / predicted,
            })
            .collect()
    }

    #[test]
    fn the_shape_tells_a_random_walk_from_a_bias_instability() {
        // Self-test seed 20261205, a 0.02 deg/s/sqrt(s) random walk alone ((deg/s)²):
        // the runs' 16 s Allan variance is 3.6 times what the bias instability fitted
        // to them predicts; the random walk fitted to them matches it.
        let instability = [
            [1.944e-4, 4.086e-5, 2.196e-4, 8.74e-6, 2.245e-4, 4.265e-5],
            [5.198e-4, 5.804e-5, 3.171e-4, 5.43e-5, 3.445e-4, 5.997e-5],
            [9.012e-4, 9.939e-5, 2.492e-4, 1.04e-4, 5.192e-4, 8.492e-5],
        ];
        let walk = [
            [1.944e-4, 4.086e-5, 2.024e-4, 1.19e-5, 2.245e-4, 4.265e-5],
            [5.198e-4, 5.804e-5, 4.742e-4, 5.84e-5, 3.445e-4, 5.997e-5],
            [9.012e-4, 9.939e-5, 9.293e-4, 3.19e-4, 5.192e-4, 8.492e-5],
        ];
        let all = |rows| wander_shape_loglik(&terms(rows, true)).unwrap();
        assert!(all(walk) > all(instability) + 10.0);
        // The held-out runs alone wandered less at 16 s and lean the other way: the
        // shape of five one-minute runs is often not decisive, so both halves count.
        let held_out_only = |rows: [[f64; 6]; 3]| {
            let swapped =
                rows.map(|[_, null, p, sd, hr, hn]| [hr, hn, p - null + hn, sd, 0.0, 0.0]);
            wander_shape_loglik(&terms(swapped, false)).unwrap()
        };
        assert!(held_out_only(instability) > held_out_only(walk));
        assert_eq!(wander_shape_loglik(&[]), None);
    }
}

/// A clip level from samples on a plateau at the largest |rate|.
fn plateau_fit(input: &FitInput, info: &'static EffectInfo) -> Result<Fit, FitError> {
    let single = single_param(info)?;
    let clipped: usize = input.train.iter().map(|r| r.features.plateau_samples).sum();
    let limit = input
        .train
        .iter()
        .map(|r| r.features.max_abs_rate_dps)
        .fold(0.0f64, f64::max);
    let null: Vec<f64> = (0..input.members())
        .map(|j| {
            input
                .null
                .iter()
                .map(|m| m[j].features.plateau_samples as f64)
                .sum()
        })
        .collect();
    let (m0, s0) = mean_sd(&null);
    let z = (clipped as f64 - m0) / s0.max(1.0);
    let tol = input.model.lsb_dps.max(1e-6);
    // No plateau: no clip seen below the range.
    let min_clipped = input.settings.fit.min_clipped;
    let limit = if clipped >= min_clipped {
        limit
    } else {
        input.model.range_dps
    };
    let mut f = judged(
        input.settings.tests.z_critical,
        single(limit.max(1e-3)),
        z,
        vec![(Some(limit - tol), Some(limit + tol))],
        false,
        "samples on a plateau at the largest |rate| while the reference is faster, vs null replicas",
    );
    f.passes = f.passes && clipped >= min_clipped;
    f.direct = true;
    Ok(f)
}

/// An output grid step coarser than the nominal one.
fn grid_fit(input: &FitInput, info: &'static EffectInfo) -> Result<Fit, FitError> {
    let single = single_param(info)?;
    let values: Vec<f64> = input
        .train
        .iter()
        .flat_map(|r| r.measured_rates_dps.iter().copied())
        .collect();
    let nominal = input.model.lsb_dps;
    let quant_ratio = input.settings.fit.quant_ratio;
    Ok(match rate_step(&values) {
        Some(step) => {
            let passes = step >= quant_ratio * nominal && step > 0.0;
            Fit {
                effect: single(step),
                ci95: vec![(Some(step * 0.999), Some(step * 1.001))],
                z: EXACT,
                passes,
                direct: true,
                holdout_z: None,
                shape_loglik: None,
                test: format!(
                    "output grid step {step:.6} deg/s vs nominal {nominal:.6} (named above {quant_ratio}x)"
                ),
            }
        }
        None => Fit {
            effect: single(nominal),
            ci95: vec![(Some(0.0), Some(quant_ratio * nominal))],
            z: EXACT,
            passes: false,
            direct: true,
            holdout_z: None,
            shape_loglik: None,
            test: "no output grid coarser than the nominal step".into(),
        },
    })
}

/// Dropouts from the gaps in the time stamps: their rate and mean length.
fn gaps_fit(input: &FitInput, info: &'static EffectInfo) -> Result<Fit, FitError> {
    let gaps: u64 = input.train.iter().map(|r| r.gaps).sum();
    let filled: u64 = input.train.iter().map(|r| r.filled_slots).sum();
    let duration: f64 = input.train.iter().map(|r| r.duration_s).sum();
    let g = gaps as f64;
    let rate = g / duration.max(1e-9);
    let mean_samples = if gaps > 0 {
        (filled as f64 / g).max(1.0)
    } else {
        1.0
    };
    let min_gaps = input.settings.fit.min_gaps;
    let rate_half = input.settings.tests.interval_z * g.sqrt() / duration.max(1e-9);
    let sd = (mean_samples * (mean_samples - 1.0)).sqrt();
    let len_half = input.settings.tests.interval_z * sd / g.max(1.0).sqrt();
    let effect = info
        .typical
        .with_params(&[rate, mean_samples])
        .ok_or(FitError::ParamCount {
            id: info.id,
            expected: 2,
        })?;
    Ok(Fit {
        effect,
        ci95: vec![
            (Some((rate - rate_half).max(0.0)), Some(rate + rate_half)),
            (Some((mean_samples - len_half).max(1.0)), Some(mean_samples + len_half)),
        ],
        z: EXACT,
        passes: gaps >= min_gaps,
        direct: true,
        holdout_z: None,
        shape_loglik: None,
        test: format!("{gaps} gaps ({filled} samples filled) in the training runs; the nominal model has none (named from {min_gaps})"),
    })
}

/// A vibration from the strongest line of the training runs' residual spectrum against
/// the null replicas' strongest ([`super::line`]); replicated on the held-out runs.
fn line_fit(input: &FitInput, info: &'static EffectInfo) -> Result<Fit, FitError> {
    let line = super::line::search(input.train, input.null).ok_or(FitError::NoSpectrum {
        segment_s: input.settings.statistics.line_segment_s,
    })?;
    let effect = info
        .typical
        .with_params(&[line.amplitude_dps, line.frequency_hz])
        .ok_or(FitError::ParamCount {
            id: info.id,
            expected: 2,
        })?;
    let per_run = super::line::amplitudes(input.train, line.frequency_hz);
    let (_, sd) = mean_sd(&per_run);
    let half = if sd.is_finite() {
        t95(per_run.len().saturating_sub(1)) * sd / (per_run.len() as f64).sqrt()
    } else {
        f64::INFINITY
    };
    let amplitude_half = (half * half + (0.1 * line.amplitude_dps).powi(2)).sqrt();
    Ok(Fit {
        effect,
        ci95: vec![
            (
                Some((line.amplitude_dps - amplitude_half).max(0.0)),
                Some(line.amplitude_dps + amplitude_half),
            ),
            (
                Some(line.frequency_hz - line.resolution_hz),
                Some(line.frequency_hz + line.resolution_hz),
            ),
        ],
        z: line.z,
        passes: line.z >= input.settings.tests.z_critical
            && line.ratio >= input.settings.statistics.line_min_ratio,
        direct: true,
        holdout_z: None,
        shape_loglik: None,
        test: format!(
            "strongest line of the gyro's spectrum not coherent with the reference, above {} Hz ({:.1} times its local floor, at least {}) vs the null replicas' strongest (one-sided; replicated on the held-out runs)",
            input.settings.statistics.min_line_hz,
            line.ratio,
            input.settings.statistics.line_min_ratio
        ),
    })
}

#[cfg(test)]
mod whiteness_tests {
    #![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
    use super::*;
    use gyro_log::{regularize, GridOptions};
    use gyro_sim::{simulate, BenchProfile, Motion, SimOptions};
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    const FS: f64 = 200.0;
    /// White noise per sample (deg/s): 0.1 · 60 / √200 = 0.42 deg/√h.
    const SIGMA: f64 = 0.1;

    /// Noise-free bench runs (rest, turn, rest) at [`FS`] plus white noise of [`SIGMA`]
    /// per sample, through a one-pole low-pass at `cutoff_hz` (DC gain 1: the same noise
    /// density in the low band) when given.
    fn runs(cutoff_hz: Option<f64>) -> Vec<RealRun> {
        let model = SensorModel {
            sample_rate_hz: FS,
            ..SensorModel::default().noise_free()
        };
        (0..3u64)
            .map(|i| {
                let motion = Motion::bench(&BenchProfile::default(), 7 + i);
                let options = SimOptions {
                    seed: i,
                    ..SimOptions::default()
                };
                let log = simulate(&model, &[], &motion, &options);
                let mut regular = regularize(&log, &GridOptions::default()).unwrap();
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(100 + i);
                let alpha = cutoff_hz.map(|f| 1.0 - (-std::f64::consts::TAU * f / FS).exp());
                let mut y = 0.0;
                for slot in &mut regular.slots {
                    let w: f64 = StandardNormal.sample(&mut rng);
                    y = match alpha {
                        Some(a) => y + a * (SIGMA * w - y),
                        None => SIGMA * w,
                    };
                    slot.rate_dps += y;
                }
                RealRun::prepare(format!("run {i}"), regular).unwrap()
            })
            .collect()
    }

    fn nominal(cutoff_hz: Option<f64>) -> Nominal {
        let runs = runs(cutoff_hz);
        let refs: Vec<&RealRun> = runs.iter().collect();
        let prior = SensorModel {
            lsb_dps: 0.0,
            ..SensorModel::default()
        };
        nominal_model(&refs, &prior, None, None, &Settings::DEFAULT)
    }

    /// White rest noise passes the check, and the white noise is the first differences'
    /// (within 5% of the truth).
    #[test]
    fn white_rest_noise_keeps_the_first_differences() {
        let truth = SIGMA * 60.0 / FS.sqrt();
        let n = nominal(None);
        let w = n.whiteness.unwrap();
        assert!(!w.coloured, "{w:?}");
        assert!(w.z.abs() < Settings::DEFAULT.tests.z_critical, "{w:?}");
        assert_eq!(n.white_target.unwrap().block, 1);
        assert!(
            (n.model.arw_deg_per_rt_h / truth - 1.0).abs() < 0.05,
            "{w:?}"
        );
        assert!(n
            .notes
            .iter()
            .any(|s| s.contains("the rest noise is white")));
    }

    /// Rest noise through a 20 Hz low-pass: the first differences read far less than
    /// the low band's density, the check says so, and the white noise comes from the
    /// 0.05 s blocks, near the truth the angle integrates (the blocks weigh the band
    /// around 10 Hz most, so a cutoff at 20 Hz still takes a little from them).
    #[test]
    fn low_passed_rest_noise_is_read_in_the_low_band() {
        let truth = SIGMA * 60.0 / FS.sqrt();
        let n = nominal(Some(20.0));
        let w = n.whiteness.unwrap();
        assert!(
            w.coloured && w.z > Settings::DEFAULT.tests.z_critical,
            "{w:?}"
        );
        assert!(w.first_difference_arw_deg_per_rt_h < 0.6 * truth, "{w:?}");
        assert_eq!(n.white_target.unwrap().block, 10);
        let ratio = n.model.arw_deg_per_rt_h / truth;
        assert!((0.8..1.1).contains(&ratio), "{ratio} {w:?}");
        assert!(n
            .notes
            .iter()
            .any(|s| s.contains("the rest noise is not white")));
    }
}

#[cfg(test)]
mod rounded_bias_tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    const FS: f64 = 100.0;
    const STEP_DPS: f64 = 0.264;

    /// A gyro at `bias_dps` with white noise `sigma_dps`, its output rounded to `step_dps`:
    /// the target of 20 000 static samples (first-difference Allan variance, mean) and the
    /// mean residual of 20 000 samples turning at up to 60 deg/s (the motion dithers the
    /// rounding), as `rest_white_target` reads them.
    fn target(bias_dps: f64, sigma_dps: f64, step_dps: f64) -> WhiteTarget {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6030);
        let mut out = |rate_dps: f64| {
            let w: f64 = StandardNormal.sample(&mut rng);
            ((bias_dps + rate_dps + sigma_dps * w) / step_dps).round() * step_dps
        };
        let n = 20_000;
        let rest: Vec<f64> = (0..n).map(|_| out(0.0)).collect();
        let moving_sum: f64 = (0..n)
            .map(|k| {
                let rate_dps = 60.0 * (std::f64::consts::TAU * 0.2 * k as f64 / FS).sin();
                out(rate_dps) - rate_dps
            })
            .sum();
        let diff_var =
            rest.windows(2).map(|d| (d[1] - d[0]).powi(2)).sum::<f64>() / (n - 1) as f64 / 2.0;
        WhiteTarget {
            avar_dps2: diff_var,
            block: 1,
            rest_mean_dps: rest.iter().sum::<f64>() / n as f64,
            rest_mean_tol_dps: Settings::DEFAULT.tests.z_critical * (diff_var / n as f64).sqrt(),
            moving_mean_dps: moving_sum / n as f64,
        }
    }

    /// The nominal model as `nominal_model` leaves it: the bias the rests' mean reads.
    fn nominal(target: &WhiteTarget) -> SensorModel {
        SensorModel {
            sample_rate_hz: FS,
            bias_dps: target.rest_mean_dps,
            gm_sigma_dps: 0.0,
            lsb_dps: 0.0,
            ..SensorModel::default()
        }
    }

    /// A step coarse against the noise (0.264 deg/s over 0.047 of noise at a bias of
    /// 0.15): the rests' mean reads about 0.17, and σ solved at that bias alone is about
    /// twice the truth; solved with the bias, the bias is within 0.003 deg/s and σ within
    /// 10%, and the simulated rest mean matches the rests'.
    #[test]
    fn a_coarse_step_solves_the_bias_with_the_white_noise() {
        let (bias_dps, sigma_dps) = (0.15, 0.047);
        let t = target(bias_dps, sigma_dps, STEP_DPS);
        let model = nominal(&t);
        assert!(t.rest_mean_dps > bias_dps + 0.015, "{t:?}");
        let old = solve_white_sigma(t, &model, STEP_DPS, None);
        assert!(old > 1.5 * sigma_dps, "the single-sigma solve: {old}");
        let m = solve_white_and_bias(t, &model, STEP_DPS, None);
        assert!((m.bias_dps - bias_dps).abs() < 0.003, "{m:?} {t:?}");
        assert!((m.sigma_dps / sigma_dps - 1.0).abs() < 0.1, "{m:?} {t:?}");
        assert!(
            (m.bias_dps + m.shift_dps - t.rest_mean_dps).abs() <= t.rest_mean_tol_dps,
            "{m:?} {t:?}"
        );
    }

    /// A moving mean the rests cannot have (0.25: the output would sit on the upper level
    /// far more often) is not taken: the bias is the nearest whose rest mean matches.
    #[test]
    fn the_moving_mean_is_taken_only_where_the_rests_allow_it() {
        let t = WhiteTarget {
            moving_mean_dps: 0.25,
            ..target(0.15, 0.047, STEP_DPS)
        };
        let m = solve_white_and_bias(t, &nominal(&t), STEP_DPS, None);
        assert!(m.bias_dps < 0.2, "{m:?}");
        let rest_mean = m.bias_dps + m.shift_dps;
        assert!(
            (rest_mean - t.rest_mean_dps).abs() <= 1.01 * t.rest_mean_tol_dps,
            "{m:?} {t:?}"
        );
    }

    /// A step fine against the noise (the CRM100's 1/24 deg/s under 0.127 of noise)
    /// dithers the rests: the bias stays the nominal's and σ is the single solve's.
    #[test]
    fn a_fine_step_keeps_the_bias_and_the_single_solve() {
        let step_dps = 1.0 / 24.0;
        let t = target(0.15, 0.127, step_dps);
        let model = nominal(&t);
        let m = solve_white_and_bias(t, &model, step_dps, None);
        assert_eq!(m.bias_dps, model.bias_dps);
        assert_eq!(m.shift_dps, 0.0);
        assert_eq!(m.sigma_dps, solve_white_sigma(t, &model, step_dps, None));
        assert!((m.sigma_dps / 0.127 - 1.0).abs() < 0.05, "{m:?}");
    }
}

#[cfg(test)]
mod replication_tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// `runs` runs of 40 replicas each of unit spread, each run's coefficient `shift` (in
    /// units of the pooled replicas' spread, 1/√runs) above its replicas' mean, plus a
    /// run-to-run scatter of standard deviation `scatter`.
    fn coefficients(runs: usize, shift: f64, scatter: f64, seed: u64) -> Vec<(f64, Vec<f64>)> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        // Evenly spread about zero, of standard deviation `scatter`.
        let centre = (runs as f64 - 1.0) / 2.0;
        let spread = ((runs * runs - 1) as f64 / 12.0).sqrt();
        let offsets: Vec<f64> = (0..runs)
            .map(|i| scatter * (i as f64 - centre) / spread)
            .collect();
        (0..runs)
            .map(|i| {
                let replicas: Vec<f64> = (0..40).map(|_| normal()).collect();
                let m = replicas.iter().sum::<f64>() / 40.0;
                let real = m + shift / (runs as f64).sqrt() + offsets[i];
                (real, replicas)
            })
            .collect()
    }

    #[test]
    fn a_shift_replicates_in_standard_errors_of_the_pooled_replicas() {
        for seed in 0..20 {
            // Replicas' spread pooled over 5 runs: 1/√5, so a shift of 3 of those is z ≈ 3.
            let z = replication_z(
                &coefficients(5, 3.0, 0.0, seed),
                Settings::DEFAULT.fit.scatter_p,
            );
            assert!((2.0..4.2).contains(&z), "seed {seed}: {z}");
            let z = replication_z(
                &coefficients(5, 0.0, 0.0, seed),
                Settings::DEFAULT.fit.scatter_p,
            );
            assert!(z.abs() < 1.8, "seed {seed}: {z}");
        }
    }

    /// A fit of `z` on the training runs whose held-out coefficient reads `holdout_z`,
    /// both in the test's direction.
    fn fit(z: f64, holdout_z: Option<f64>) -> Fit {
        Fit {
            effect: Effect::Latency { delay_s: 0.005 },
            ci95: vec![(Some(0.004), Some(0.006))],
            z,
            passes: true,
            test: String::new(),
            direct: false,
            holdout_z,
            shape_loglik: None,
        }
    }

    #[test]
    fn the_held_out_test_is_read_in_the_training_direction() {
        const RZ: f64 = Settings::DEFAULT.tests.replication_z;
        // A delay is the negated acceleration coefficient: its test's z and the held-out
        // z are both negated, and a negative pair replicates.
        assert!(replicates(&fit(-6.0, Some(-2.5)), RZ));
        assert!(replicates(&fit(6.0, Some(2.0)), RZ));
        assert!(!replicates(&fit(-6.0, Some(2.5)), RZ));
        assert!(!replicates(&fit(6.0, Some(1.9)), RZ));
        assert!(!replicates(&fit(6.0, None), RZ));
        assert!(!replicates(&fit(f64::NAN, Some(3.0)), RZ));
        // A wander replicates only with no other wander beside it.
        let walk = Fit {
            effect: Effect::RateRandomWalk {
                k_dps_per_rt_s: 0.02,
            },
            ..fit(30.0, Some(20.0))
        };
        let instability = Effect::BiasInstability { sigma_dps: 0.05 };
        let scale = Effect::ScaleFactor { k: 0.01 };
        assert!(replicates_beside(&walk, &[scale], RZ));
        assert!(!replicates_beside(&walk, &[scale, instability], RZ));
        assert!(replicates_beside(
            &fit(-6.0, Some(-2.5)),
            &[instability],
            RZ
        ));
        assert!(contradicted(&fit(-5.3, Some(1.1))));
        assert!(contradicted(&fit(4.3, Some(-1.1))));
        assert!(!contradicted(&fit(4.3, Some(0.4))));
        assert!(!contradicted(&fit(-6.0, Some(-2.5))));
        assert!(!contradicted(&fit(6.0, None)));
        assert!(!contradicted(&fit(f64::NAN, Some(-3.0))));
    }

    #[test]
    fn a_weak_coefficient_passes_on_all_runs_in_the_training_direction() {
        let runs = (5, 5);
        let passes = |z, hz, sign, two_sided| {
            RegressionFit::passes(&Settings::DEFAULT.tests, z, hz, runs, sign, two_sided)
        };
        // Training alone.
        assert!(passes(4.2, f64::NAN, 1.0, true));
        assert!(passes(-4.2, f64::NAN, 1.0, true));
        assert!(!passes(3.5, f64::NAN, 1.0, true));
        // 3.1 on training and 3.0 held out: 4.3 on all ten runs.
        assert!(passes(3.1, 3.0, 1.0, true));
        assert!(passes(-3.1, -3.0, 1.0, true));
        // Not when the held-out runs show less, or the other way.
        assert!(!passes(3.1, 2.0, 1.0, true));
        assert!(!passes(3.1, -3.0, 1.0, true));
        // A one-sided test in the negated direction (a bandwidth's delay): the
        // coefficient's −3.1 and −3.0 pass, +3.1 and +3.0 do not.
        assert!(passes(-3.1, -3.0, -1.0, false));
        assert!(!passes(3.1, 3.0, -1.0, false));
        // A held-out z that drags the training z past 4: the training half must show
        // the effect too (its interval would hold the effect's absence).
        assert!(!passes(1.9, 11.0, 1.0, true));
        assert!(!passes(-1.0, 7.0, 1.0, true));
        // Nor a held-out half below 2 that a training z near 4 carries.
        assert!(!passes(3.9, 1.9, 1.0, true));
    }

    #[test]
    fn the_pooled_z_is_the_test_on_all_runs() {
        // Equal runs: the mean of the two z-scores times √2.
        assert!((pooled_z(3.0, 5, 3.0, 5) - 3.0 * 2f64.sqrt()).abs() < 1e-12);
        // A held-out half that shows nothing dilutes the training half.
        assert!((pooled_z(4.0, 5, 0.0, 5) - 4.0 / 2f64.sqrt()).abs() < 1e-12);
        // Weighted by runs: 1 held-out run of 9 barely moves it.
        assert!((pooled_z(3.0, 9, 0.0, 1) - 3.0 * 0.9f64.sqrt()).abs() < 1e-12);
        // Standard normal without an effect: simulated pairs of independent N(0, 1).
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let z: Vec<f64> = (0..20_000)
            .map(|_| pooled_z(normal(), 3, normal(), 7))
            .collect();
        let (m, sd) = mean_sd(&z);
        assert!(m.abs() < 0.03 && (sd - 1.0).abs() < 0.03, "{m} {sd}");
    }

    #[test]
    fn runs_that_scatter_beyond_their_replicas_widen_the_error() {
        // The same shift among runs that disagree by 3 replica spreads: the standard error
        // is their scatter's, and the shift no longer replicates.
        for seed in 0..20 {
            let tight = replication_z(
                &coefficients(5, 3.0, 0.0, seed),
                Settings::DEFAULT.fit.scatter_p,
            );
            let loose = replication_z(
                &coefficients(5, 3.0, 3.0, seed),
                Settings::DEFAULT.fit.scatter_p,
            );
            assert!(
                loose.abs() < tight.abs(),
                "seed {seed}: {loose} against {tight}"
            );
            assert!(
                loose < Settings::DEFAULT.tests.replication_z,
                "seed {seed}: {loose}"
            );
        }
    }
}
