//! Stage 1, baseline: the nominal model, and every run re-simulated with it as an
//! ensemble scored against the run; the floor of the gap between simulated ensembles.

use super::effective::{measure, MeasuredNoise};
use super::ensemble::{ensembles, Member, RealRun};
use super::features::WANDER_TAUS_S;
use super::score::{self, gap, score, RunScore};
use super::short_white::short_white;
use super::stats::{Segment, Statistic};
use super::{fit, Options, Progress};
use gyro_sim::{Effect, SensorModel};

/// The training and held-out runs with their seed indices in the ensembles (training
/// runs first, then the held-out runs).
pub(crate) struct Runs<'a> {
    /// Training runs.
    pub(crate) train: Vec<&'a RealRun>,
    /// Held-out runs.
    pub(crate) holdout: Vec<&'a RealRun>,
    /// Seed index of each training run.
    pub(crate) train_ids: Vec<usize>,
    /// Seed index of each held-out run.
    pub(crate) holdout_ids: Vec<usize>,
}

impl<'a> Runs<'a> {
    pub(crate) fn new(train: &'a [RealRun], holdout: &'a [RealRun]) -> Self {
        Self {
            train: train.iter().collect(),
            holdout: holdout.iter().collect(),
            train_ids: (0..train.len()).collect(),
            holdout_ids: (train.len()..train.len() + holdout.len()).collect(),
        }
    }
}

/// Runs scored against their ensembles.
pub(crate) struct Evaluation {
    /// Each run's score.
    pub(crate) scores: Vec<RunScore>,
    /// Each run's ensemble.
    pub(crate) members: Vec<Vec<Member>>,
}

/// Simulate `members` members of every run with `model` and `effects`, and score each
/// run against its ensemble.
pub(crate) fn evaluate(
    runs: &[&RealRun],
    ids: &[usize],
    model: &SensorModel,
    effects: &[Effect],
    options: &Options,
    members: usize,
    progress: &dyn Progress,
) -> Evaluation {
    let tick = || progress.tick();
    let ens = ensembles(runs, ids, model, effects, options.seed, members, &tick);
    let scores = runs
        .iter()
        .zip(&ens)
        .map(|(r, m)| score(&r.stats, m, options.settings.score.likelihood_dof))
        .collect();
    Evaluation {
        scores,
        members: ens,
    }
}

/// Scores against only the first `k` members of each ensemble.
pub(crate) fn rescore(
    runs: &[&RealRun],
    members: &[Vec<Member>],
    k: usize,
    likelihood_dof: f64,
) -> Vec<RunScore> {
    runs.iter()
        .zip(members)
        .map(|(r, m)| score(&r.stats, &m[..k.min(m.len())], likelihood_dof))
        .collect()
}

/// The baseline stage's result.
pub(crate) struct Baseline {
    /// The nominal model.
    pub(crate) nominal: SensorModel,
    /// Where its values came from.
    pub(crate) notes: Vec<String>,
    /// The static statistic the white noise was matched to (if fitted at rest).
    pub(crate) white_target: Option<fit::WhiteTarget>,
    /// The whiteness check of the training runs' rests.
    pub(crate) whiteness: Option<fit::RestWhiteness>,
    /// The effective noise of the training runs' moving residual, compared with the
    /// sensor's own white noise (the rests', else the prior's or the given model's).
    pub(crate) moving_noise: Option<MeasuredNoise>,
    /// The white noise the effective noise is compared with (deg/√h) and where it came
    /// from.
    pub(crate) own_noise: (f64, &'static str),
    /// Members of each candidate's ensemble (the baseline's first seeds).
    pub(crate) candidate_members: usize,
    /// Training runs against the nominal model.
    pub(crate) train: Evaluation,
    /// Held-out runs against the nominal model.
    pub(crate) holdout: Evaluation,
    /// G between independent simulated ensembles.
    pub(crate) floor: f64,
    /// G of the training runs, nominal.
    pub(crate) train_gap: f64,
    /// G of the held-out runs, nominal.
    pub(crate) holdout_gap: f64,
}

/// Stage 1: the nominal model (fitted on the training runs, or the given one) and the
/// baseline ensembles of every run. `known`: effects established from direct evidence
/// before any fit (a count-stamped clock read from the lag lines), whose share of each
/// run's bias is taken out of the nominal bias.
pub(crate) fn baseline(
    runs: &Runs,
    known: &[Effect],
    options: &Options,
    progress: &dyn Progress,
) -> Baseline {
    let moving = measure(&runs.train, "training", &options.settings.turns);
    let never_rest = !options.fixed_model && !fit::rests_suffice(&runs.train);
    // Runs that never rest take their white noise from the moving residual, which holds
    // what a known effect leaves there (a grown count-stamped clock: the rate times a lag
    // of up to a second, 61.5 °/s on runs of 0.3 °/s of noise): taken out first.
    let cleaned = (never_rest && !known.is_empty())
        .then(|| less_known(&runs.train, known, &options.prior, options.seed));
    let white_runs: Vec<&RealRun> = match &cleaned {
        Some(c) => c.iter().collect(),
        None => runs.train.clone(),
    };
    let white_moving = match &cleaned {
        Some(_) => measure(&white_runs, "training", &options.settings.turns),
        None => moving.clone(),
    };
    // Runs that never rest: the moving residual's white level, read again where it
    // holds the most blocks.
    let short = match &white_moving {
        Some(m) if never_rest => short_white(
            &white_runs,
            &options.prior,
            m,
            options.seed,
            options.settings.tests.z_critical,
        ),
        _ => None,
    };
    let fit::Nominal {
        model: mut nominal,
        mut notes,
        white_target,
        whiteness,
    } = starting_model(runs, known, options, white_moving.as_ref(), short.as_ref());
    if cleaned.is_some() {
        let ids: Vec<&str> = known.iter().map(|e| e.id()).collect();
        notes.push(format!(
            "the white noise of these runs, which never rest, is read from their moving residual less what the {} established from the lag lines leaves in it (each run re-simulated without noise with and without it)",
            ids.join(", ")
        ));
    }
    let own_noise = match (options.fixed_model, white_target) {
        (true, _) => (nominal.arw_deg_per_rt_h, "given model"),
        (false, Some(_)) => (nominal.arw_deg_per_rt_h, "rests"),
        (false, None) => (options.prior.arw_deg_per_rt_h, "prior model"),
    };
    let moving_noise = moving.map(|m| m.compared_to(own_noise.0, own_noise.1));
    let m = options.members.max(4);
    let mc = options.candidate_members.clamp(2, m);
    progress.stage(
        "baseline ensembles",
        (m * (runs.train.len() + runs.holdout.len())) as u64,
    );
    let train = train_evaluation(runs, &mut nominal, &mut notes, options, m, progress);
    let holdout = evaluate(
        &runs.holdout,
        &runs.holdout_ids,
        &nominal,
        &[],
        options,
        m,
        progress,
    );
    let floor = ensemble_floor(&train, &holdout, options);
    Baseline {
        nominal,
        notes,
        white_target,
        whiteness,
        moving_noise,
        own_noise,
        candidate_members: mc,
        train_gap: gap(&train.scores),
        holdout_gap: gap(&holdout.scores),
        train,
        holdout,
        floor,
    }
}

/// `train` with the `known` effects' deterministic share taken out of each run's moving
/// residual: the residual of the run re-simulated without noise with them, less that
/// without them (what the reference and the regression leave alike), per sample.
fn less_known(
    train: &[&RealRun],
    known: &[Effect],
    prior: &SensorModel,
    seed: u64,
) -> Vec<RealRun> {
    let quiet = SensorModel {
        range_dps: f64::MAX,
        ..prior.noise_free()
    };
    train
        .iter()
        .enumerate()
        .map(|(i, run)| {
            let mut run = (*run).clone();
            let residual = |effects: &[Effect]| {
                super::ensemble::simulate_residuals(
                    &run,
                    &quiet,
                    effects,
                    super::ensemble::member_seed(seed, i, 0),
                )
                .ok()
                .map(|r| super::features::real_features(&r, 1e-9).1)
            };
            if let (Some(with), Some(without)) = (residual(known), residual(&[])) {
                for ((x, a), b) in run.residual_dps.iter_mut().zip(&with).zip(&without) {
                    *x -= a - b;
                }
            }
            run
        })
        .collect()
}

/// The nominal model to start from: the `--model` one as given (at the runs' sample rate)
/// when the model is fixed, else the one fitted on the training runs ([`fitted_nominal`]).
fn starting_model(
    runs: &Runs,
    known: &[Effect],
    options: &Options,
    moving: Option<&MeasuredNoise>,
    short: Option<&super::short_white::ShortWhite>,
) -> fit::Nominal {
    if options.fixed_model {
        let mut m = options.prior;
        if let Some(first) = runs.train.first() {
            m.sample_rate_hz = first.sample_rate_hz;
        }
        fit::Nominal {
            model: m,
            notes: vec!["the --model sensor model as given".to_string()],
            white_target: None,
            whiteness: None,
        }
    } else {
        fitted_nominal(runs, known, options, moving, short)
    }
}

/// The training runs' ensembles of `m` members against the `nominal` model; when their
/// Allan variance at long τ lies below the model's beyond chance, the model's
/// Gauss-Markov sigma is lowered (noted in `notes`) and the runs simulated again.
fn train_evaluation(
    runs: &Runs,
    nominal: &mut SensorModel,
    notes: &mut Vec<String>,
    options: &Options,
    m: usize,
    progress: &dyn Progress,
) -> Evaluation {
    let train_against = |model: &SensorModel| {
        evaluate(
            &runs.train,
            &runs.train_ids,
            model,
            &[],
            options,
            m,
            progress,
        )
    };
    let mut train = train_against(nominal);
    let wander = (!options.fixed_model)
        .then(|| wander_allowed(&train, nominal, options.settings.tests.z_critical))
        .flatten();
    if let Some(w) = wander {
        notes.push(format!(
            "bias wander: the training runs' Allan variance at {} s lies below the model's beyond chance (z {:.1}); the part above the white noise is {:.2} of the model's, so the Gauss-Markov sigma is lowered from {:.4} to {:.4} deg/s and the runs simulated again (never raised: a larger wander is an effect to name)",
            WANDER_TAUS_S[WANDER_TAUS_S.len() - 1],
            w.z,
            w.ratio,
            nominal.gm_sigma_dps,
            w.sigma_dps
        ));
        nominal.gm_sigma_dps = w.sigma_dps;
        progress.stage(
            "baseline ensembles, the wander lowered",
            (m * (runs.train.len() + runs.holdout.len())) as u64,
        );
        train = train_against(nominal);
    }
    train
}

/// The floor of the gap between independent simulated ensembles: [`score::floor`] over
/// every baseline member of the training and held-out runs.
fn ensemble_floor(train: &Evaluation, holdout: &Evaluation, options: &Options) -> f64 {
    let all: Vec<Vec<Member>> = train
        .members
        .iter()
        .chain(&holdout.members)
        .cloned()
        .collect();
    score::floor(&all, &options.settings.score)
}

/// The nominal model fitted on the training runs ([`fit::nominal_model`]), its bias less
/// the share the `known` effects leak into it, its range dropped when a run reads beyond
/// it; with the notes on each.
fn fitted_nominal(
    runs: &Runs,
    known: &[Effect],
    options: &Options,
    moving: Option<&MeasuredNoise>,
    short: Option<&super::short_white::ShortWhite>,
) -> fit::Nominal {
    let fit::Nominal {
        model: mut nominal,
        mut notes,
        white_target,
        whiteness,
    } = fit::nominal_model(
        &runs.train,
        &options.prior,
        moving,
        short,
        &options.settings,
    );
    if !known.is_empty() {
        let shares: Vec<f64> = runs
            .train
            .iter()
            .map(|r| fit::known_bias_dps(r, &nominal, known))
            .filter(|b| b.is_finite())
            .collect();
        if !shares.is_empty() {
            let share = shares.iter().sum::<f64>() / shares.len() as f64;
            nominal.bias_dps -= share;
            notes.push(format!(
                "bias {:.4} deg/s after taking out {share:+.4} deg/s that the count-stamped clock's growing lag leaks into the regression intercepts",
                nominal.bias_dps
            ));
        }
    }
    // The prior's range is the CRM100's: any run, trained on or held out, that reads
    // beyond it shows it is not this sensor's (it is not fitted, only refused).
    let largest = gyro_analysis::model::largest_plausible_abs_rate(
        runs.train
            .iter()
            .chain(&runs.holdout)
            .map(|r| r.features.max_abs_rate_dps),
        options.base_model.config.max_abs_rate_dps,
    );
    if let Some(note) = gyro_analysis::model::contradicted_range_note(nominal.range_dps, largest) {
        nominal.range_dps = f64::from(gyro_core::Config::default().max_abs_rate_dps);
        notes.push(note);
    }
    fit::Nominal {
        model: nominal,
        notes,
        white_target,
        whiteness,
    }
}

/// The bias wander the training runs allow, below the nominal model's.
#[derive(Clone, Copy, Debug, PartialEq)]
struct WanderAllowed {
    /// The Gauss–Markov σ (deg/s) whose wander matches the runs'.
    sigma_dps: f64,
    /// The runs' wander part of the longest τ's Allan variance over the model's.
    ratio: f64,
    /// Stouffer z of that statistic over the training runs.
    z: f64,
}

/// The Gauss–Markov σ the training runs' bias wander allows, when their Allan variance at
/// the longest τ of [`WANDER_TAUS_S`] lies below the nominal model's beyond chance (the
/// runs' z against their ensembles, combined by Stouffer, at most `−z_critical`): the
/// model's σ scaled by the square root of the ratio of the wander parts (each Allan
/// variance less the white noise's share, read from the shortest τ as `avar(τ₀) τ₀ / τ`),
/// at most 1. A prior that wanders more than these runs is not this sensor's, and a model
/// that does says "the model does not explain these runs" of a sensor that is fine.
/// `None` otherwise (never a larger σ: a wander beyond the model's is the vocabulary's
/// `bias_instability` or `rate_random_walk` to name).
fn wander_allowed(
    train: &Evaluation,
    nominal: &SensorModel,
    z_critical: f64,
) -> Option<WanderAllowed> {
    let (short, long) = (0, WANDER_TAUS_S.len() - 1);
    // Per run: (z, real log10 value, ensemble mean of it).
    let pick = |k: usize| -> Vec<(f64, f64, f64)> {
        train
            .scores
            .iter()
            .filter_map(|s| {
                let i =
                    s.z.iter()
                        .position(|(st, _)| st.is(Segment::All, Statistic::WanderLog10Avar(k)))?;
                let (stat, z) = &s.z[i];
                let (mean, _) = *s.moments.get(i)?;
                (z.is_finite() && stat.value.is_finite() && mean.is_finite())
                    .then_some((*z, stat.value, mean))
            })
            .collect()
    };
    let (at_long, at_short) = (pick(long), pick(short));
    if at_long.is_empty() || at_short.len() != at_long.len() {
        return None;
    }
    let z = at_long.iter().map(|v| v.0).sum::<f64>() / (at_long.len() as f64).sqrt();
    if z > -z_critical {
        return None;
    }
    let mean_of = |v: &[(f64, f64, f64)], pick: fn(&(f64, f64, f64)) -> f64| {
        10f64.powf(v.iter().map(pick).sum::<f64>() / v.len() as f64)
    };
    let white_share = WANDER_TAUS_S[short] / WANDER_TAUS_S[long];
    let part = |pick: fn(&(f64, f64, f64)) -> f64| {
        mean_of(&at_long, pick) - white_share * mean_of(&at_short, pick)
    };
    let (real, model) = (part(|v| v.1).max(0.0), part(|v| v.2));
    if model.is_nan() || model <= 0.0 {
        return None;
    }
    let ratio = (real / model).min(1.0);
    Some(WanderAllowed {
        sigma_dps: nominal.gm_sigma_dps * ratio.sqrt(),
        ratio,
        z,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::Stat;

    /// Training scores of `runs` runs whose Allan variances at 1 s and 16 s are `real` and
    /// whose ensembles' are `model` ((deg/s)²), the 16 s one at `z` on each run.
    fn scores(runs: usize, real: (f64, f64), model: (f64, f64), z: f64) -> Evaluation {
        let stat = |k: usize, value: f64| Stat {
            segment: Segment::All,
            statistic: Statistic::WanderLog10Avar(k),
            value: value.log10(),
        };
        let one = RunScore {
            z: vec![(stat(0, real.0), 0.0), (stat(2, real.1), z)],
            moments: vec![(model.0.log10(), 0.1), (model.1.log10(), 0.1)],
            ..RunScore::default()
        };
        Evaluation {
            scores: vec![one; runs],
            members: Vec::new(),
        }
    }

    #[test]
    fn a_prior_wandering_more_than_the_runs_comes_down_to_them() {
        let nominal = SensorModel {
            gm_sigma_dps: 0.05,
            ..SensorModel::default()
        };
        // White noise 1.6e-3 at 1 s (1e-4 of it at 16 s); the model's wander part at 16 s
        // 4e-4, the runs' 1e-4: a quarter, so σ halves.
        let model = (1.6e-3, 1e-4 + 4e-4);
        let real = (1.6e-3, 1e-4 + 1e-4);
        let w = wander_allowed(&scores(4, real, model, -2.5), &nominal, 4.0).unwrap();
        assert!((w.z + 5.0).abs() < 1e-12);
        assert!((w.ratio - 0.25).abs() < 1e-9, "{w:?}");
        assert!((w.sigma_dps - 0.025).abs() < 1e-9, "{w:?}");
        // Within chance (z −1.5 · 2 = −3): kept.
        assert_eq!(
            wander_allowed(&scores(4, real, model, -1.5), &nominal, 4.0),
            None
        );
        // Runs that wander more are never a reason to raise it.
        let more = (1.6e-3, 1e-4 + 9e-4);
        assert_eq!(
            wander_allowed(&scores(4, more, model, 5.0), &nominal, 4.0),
            None
        );
        // No wander above the white noise at all: none in the model either.
        let none = (1.6e-3, 0.9e-4);
        let w = wander_allowed(&scores(4, none, model, -3.0), &nominal, 4.0).unwrap();
        assert_eq!(w.sigma_dps, 0.0);
    }
}
