//! Sim-to-real diagnosis: where a real sensor
//! differs from its simulation, which unmodelled effect causes it, and how far adding the
//! effect closes the gap on runs not used to fit it.
//!
//! Method, fixed before looking at any data:
//! 1. **Baseline**: the nominal model (`fit::nominal_model`; or `--model`) re-simulates
//!    every run with its own reference motion and temperatures as an ensemble of
//!    [`Options::members`] seeds; every run, real or simulated, goes through the same
//!    statistics (`stats`) and features (`features`).
//! 2. **Where**: z-scores of each statistic against the run's ensemble, combined over runs
//!    (Stouffer: Σz/√n); the gap G and its floor (`score`).
//! 3. **Which**: every effect of the vocabulary is fitted on the training runs
//!    (`fit`); each one whose parameter test passes is added to the nominal model and the
//!    held-out runs are re-simulated with the same seeds ([`Options::candidate_members`]
//!    of them; every testable one with [`Options::score_every_candidate`]). An effect
//!    is significant when its parameter test passes on the training runs (or, for a
//!    regression coefficient, pooled with the same test on the held-out runs), its held-out
//!    ΔBIC is positive and the bootstrap over held-out runs gives P(no improvement) < 5%.
//!    Effects are ranked by held-out gap reduction. When several are significant, each is
//!    dropped in turn from the model holding all of them (leave-one-out); one whose
//!    removal costs nothing significant is redundant: it is confounded with the others
//!    (e.g. a latency next to a bandwidth) and not named. A clock error is measured from
//!    the time stamps against the nominal sample rate (`ensemble::StampedClock`); the
//!    regression-based effects are fitted on top of it (on the nominal grid the pipeline
//!    integrates on, a fast clock scales the rate like a scale factor).
//! 4. **How far**: the gap with the selected effects on the training and held-out runs,
//!    and the fraction of the held-out gap closed relative to the floor.
//!
//! [`diagnose`] runs this as stages, one module each: `baseline` (1), `locate` (2),
//! `fit` and `select` (3), `compensate` (the correctable effects replayed through
//! the core) and `summarise` (4, and the [`Diagnosis`]).
//!
//! ```no_run
//! use gyro_diagnose::{diagnose, split, Options, RealRun, Silent};
//! use gyro_log::{load, GridOptions, LogOptions};
//!
//! let log = load(
//!     "fixtures/logs/bench_run.csv".as_ref(),
//!     &LogOptions::default(),
//!     &GridOptions::default(),
//!     &mut |_| {},
//! )?;
//! // 30 s windows: the first two train, the rest are held out.
//! let mut runs = split(&log, 30.0)
//!     .into_iter()
//!     .enumerate()
//!     .map(|(i, w)| RealRun::prepare(format!("window {i}"), w))
//!     .collect::<Result<Vec<_>, _>>()?;
//! let holdout = runs.split_off(2);
//! let result = diagnose(&runs, &holdout, &Options::default(), &Silent)?;
//! println!(
//!     "named: {:?}, held-out gap closed: {:.0}%, model fits: {}",
//!     result.verdict.unmodelled,
//!     100.0 * result.verdict.fraction_closed_holdout,
//!     result.verdict.model_fits
//! );
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod baseline;
pub(crate) mod compensate;
pub mod detection;
mod diagnosis;
pub mod effective;
pub(crate) mod ensemble;
pub mod envelopes;
pub(crate) mod features;
pub mod files;
pub(crate) mod fit;
pub mod lag_line;
pub mod line;
pub mod locate;
pub(crate) mod low_band;
pub mod posterior;
pub(crate) mod score;
mod select;
pub mod selftest;
pub mod settings;
pub mod short_white;
pub(crate) mod stats;
mod summarise;
pub mod turns;

pub use compensate::{BIAS_ID, SCALE_FROM_TURNS};
pub use diagnosis::{
    CompensationRun, CompensationSummary, Diagnosis, EffectResult, GapSummary, InputEntry,
    ModelSummary, NotCorrected, RunSummary, Unexplained, UntestableEntry, Verdict, Where,
};
pub use ensemble::{motion_from_reference, split, GridKind, RealRun, ReferenceGrid};
pub use settings::{Settings, SettingsError};
pub use stats::stretches;

use baseline::Runs;
use fit::FitInput;
use select::Scorer;

use gyro_analysis::model::ModelFile;
use gyro_sim::SensorModel;

/// Settings of a diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Members of the baseline ensemble per run.
    pub members: usize,
    /// Members of each candidate's ensemble per held-out run (the baseline's first seeds).
    pub candidate_members: usize,
    /// Seed of every ensemble.
    pub seed: u64,
    /// Bootstrap resamples over runs.
    pub bootstrap: usize,
    /// The sensor model to start from.
    pub prior: SensorModel,
    /// Use the prior model as it is (`--model`), without fitting the bias and white noise.
    pub fixed_model: bool,
    /// The model file whose pipeline configuration replays the held-out runs, and to
    /// which the corrections are added.
    pub base_model: ModelFile,
    /// Score every fitted effect alone on the held-out runs, also those whose parameter
    /// test does not pass on the training runs (which can never be named): their
    /// held-out figures and posterior checks are then reported too, for one more
    /// candidate ensemble each.
    pub score_every_candidate: bool,
    /// Every number that decides the diagnosis: thresholds, p-values, z-limits, windows,
    /// bounds ([`Settings`]).
    pub settings: Settings,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            members: 50,
            candidate_members: 20,
            seed: 1,
            bootstrap: 2000,
            prior: default_prior(),
            fixed_model: false,
            base_model: ModelFile::new(gyro_core::Config::default()),
            score_every_candidate: false,
            settings: Settings::default(),
        }
    }
}

/// The sensor model a diagnosis starts from without `--model`, and the self-check
/// simulates its runs from: the simulator's nominal sensor without its Gauss–Markov bias
/// wander. What the runs show of bias, white noise, output step and range is read from
/// them ([`fit::nominal_model`]); a bias wander the runs show is what the vocabulary's
/// `bias_instability` and `rate_random_walk` name, so a prior wander would hold it unnamed
/// (a prior of σ 0.05 °/s over 100 s wanders as a 180 °/h bias instability does).
pub fn default_prior() -> SensorModel {
    SensorModel {
        gm_sigma_dps: 0.0,
        ..SensorModel::default()
    }
}

/// Why a diagnosis cannot run.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    /// A run cannot be used.
    #[error("{name}: {message}")]
    Run {
        /// Run name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// Fewer than 2 training runs.
    #[error(
        "{found} training run(s): at least 2 are needed (3 to test turn-on bias), each a log with reference_deg"
    )]
    TooFewTrainingRuns {
        /// Training runs given.
        found: usize,
    },
    /// Fewer than 2 held-out runs.
    #[error(
        "{found} held-out run(s): at least 2 are needed to score effects on runs not used to fit them"
    )]
    TooFewHeldOutRuns {
        /// Held-out runs given.
        found: usize,
    },
    /// Runs at different sample rates.
    #[error(
        "sample rates differ: {first} is at {first_hz} Hz, {other} at {other_hz} Hz; diagnose compares runs of one sensor setup"
    )]
    MismatchedRates {
        /// The first training run.
        first: String,
        /// Its sample rate (Hz).
        first_hz: f64,
        /// A run at another rate.
        other: String,
        /// That run's sample rate (Hz).
        other_hz: f64,
    },
    /// A setting of [`Options::settings`] is not valid.
    #[error("diagnose settings: {0}")]
    Settings(#[from] SettingsError),
}

impl DiagnoseError {
    /// What to pass to `gyro-cli diagnose` to get past it, where there is advice.
    pub fn advice(&self) -> Option<&'static str> {
        match self {
            Self::TooFewHeldOutRuns { .. } => {
                Some("pass --holdout, or --split-s to cut logs into windows")
            }
            Self::MismatchedRates { .. } => {
                Some("resample, or pass --sample-rate-hz to place all on one grid")
            }
            Self::Run { .. } | Self::TooFewTrainingRuns { .. } | Self::Settings(_) => None,
        }
    }

    /// The message with its [`advice`](Self::advice) in parentheses, as `gyro-cli` says it.
    pub fn with_advice(&self) -> String {
        match self.advice() {
            Some(advice) => format!("{self} ({advice})"),
            None => self.to_string(),
        }
    }
}

impl Options {
    /// Diagnose against `file`'s sensor model as it is (`--model`), its pipeline
    /// configuration replaying the held-out runs.
    pub fn with_fixed_model(self, file: ModelFile) -> Self {
        Self {
            prior: file.sensor,
            base_model: file,
            fixed_model: true,
            ..self
        }
    }
}

/// Progress reports.
pub trait Progress: Sync {
    /// A new stage with `total` steps.
    fn stage(&self, name: &str, total: u64);
    /// One step done.
    fn tick(&self);
}

/// No progress reporting.
pub struct Silent;

impl Progress for Silent {
    fn stage(&self, _: &str, _: u64) {}
    fn tick(&self) {}
}

/// Check the runs can be diagnosed together.
pub fn check_runs(train: &[RealRun], holdout: &[RealRun]) -> Result<(), DiagnoseError> {
    if train.len() < 2 {
        return Err(DiagnoseError::TooFewTrainingRuns { found: train.len() });
    }
    if holdout.len() < 2 {
        return Err(DiagnoseError::TooFewHeldOutRuns {
            found: holdout.len(),
        });
    }
    let first = &train[0];
    for run in train.iter().chain(holdout) {
        let ratio = run.sample_rate_hz / first.sample_rate_hz;
        if (ratio - 1.0).abs() > 1e-3 {
            return Err(DiagnoseError::MismatchedRates {
                first: first.name.clone(),
                first_hz: first.sample_rate_hz,
                other: run.name.clone(),
                other_hz: run.sample_rate_hz,
            });
        }
    }
    Ok(())
}

/// `runs` prepared again from their logs with `settings`.
fn prepare_again(runs: &[RealRun], settings: &Settings) -> Result<Vec<RealRun>, DiagnoseError> {
    runs.iter()
        .map(|r| {
            RealRun::prepare_with(r.name.clone(), r.log.clone(), settings).map_err(|e| {
                DiagnoseError::Run {
                    name: r.name.clone(),
                    message: format!("prepared again with the options' settings: {e}"),
                }
            })
        })
        .collect()
}

/// Diagnose `train` against `holdout`, stage by stage: baseline, locate, fit, select,
/// compensate, summarise.
pub fn diagnose(
    train: &[RealRun],
    holdout: &[RealRun],
    options: &Options,
    progress: &dyn Progress,
) -> Result<Diagnosis, DiagnoseError> {
    options.settings.validate()?;
    check_runs(train, holdout)?;
    // Runs prepared with other statistics or reference settings than the options' are
    // prepared again from their logs: the settings given are the ones every run is read
    // with.
    let prepared = (!train
        .iter()
        .chain(holdout)
        .all(|r| r.prepared_with(&options.settings)))
    .then(|| {
        Ok::<_, DiagnoseError>((
            prepare_again(train, &options.settings)?,
            prepare_again(holdout, &options.settings)?,
        ))
    })
    .transpose()?;
    let (train, holdout) = match &prepared {
        Some((t, h)) => (t.as_slice(), h.as_slice()),
        None => (train, holdout),
    };

    // 0. A count-stamped clock whose lag grows beyond the per-sample statistics' reach,
    // read directly from the lag lines (no model needed): held as known from the start.
    let grown_clock = {
        let (t, h): (Vec<&RealRun>, Vec<&RealRun>) =
            (train.iter().collect(), holdout.iter().collect());
        lag_line::grown_clock_fit(&t, &h, &options.settings).filter(|f| f.passes)
    };
    let known: Vec<gyro_sim::Effect> = grown_clock.iter().map(|f| f.effect).collect();
    // A slow one: the last rows read motion past the reference's end, which no
    // re-simulation from the reference can hold; they are left out of every run.
    let trimmed = match known.first() {
        Some(&gyro_sim::Effect::ClockErrorCountStamped { ppm }) if ppm < 0.0 => Some((
            lag_line::within_reference(train, ppm)?,
            lag_line::within_reference(holdout, ppm)?,
        )),
        _ => None,
    };
    let (train, holdout) = match &trimmed {
        Some((t, h)) => (t.as_slice(), h.as_slice()),
        None => (train, holdout),
    };
    Ok(diagnose_prepared(
        train,
        holdout,
        grown_clock.as_ref(),
        &known,
        options,
        progress,
    ))
}

/// Stages 1 to 6 of [`diagnose`] on runs prepared with the options' settings (and
/// trimmed to the reference), `known` the effects held as known from the start (the
/// `grown_clock`, when its test passed).
fn diagnose_prepared(
    train: &[RealRun],
    holdout: &[RealRun],
    grown_clock: Option<&fit::Fit>,
    known: &[gyro_sim::Effect],
    options: &Options,
    progress: &dyn Progress,
) -> Diagnosis {
    let runs = Runs::new(train, holdout);

    // 1. Baseline, and 2. where.
    let base = baseline::baseline(&runs, known, options, progress);
    let r#where = locate::locate(
        base.train.scores.iter().chain(&base.holdout.scores),
        &options.settings,
    );

    // 3. Fit every effect on the training runs.
    let input = FitInput {
        train: &runs.train,
        null: &base.train.members,
        model: &base.nominal,
        temperature_ok: train.iter().all(|r| r.features.temperature_varies),
        seed: options.seed,
        holdout: &runs.holdout,
        holdout_null: &base.holdout.members,
        settings: &options.settings,
        grown_clock,
        null_effects: &[],
    };
    let (fits, untestable, joint) = fit::fit_all(&input);

    // 4. Select on the held-out runs.
    let scorer = Scorer::new(&runs, &base, options, progress, &joint);
    let mut candidates = select::score_alone(&scorer, fits);
    let selection = select::select_checked(&scorer, &mut candidates);
    let holdout_before = scorer.before;
    let selected_effects = select::joint_refit(&joint, &mut candidates, &selection.selected);
    let selected_sensor = fit::model_with(&base.nominal, &selected_effects, base.white_target);

    // 5. and 5b.
    let (compensation, corrected_model, turns) = compensate_and_turns(
        train,
        holdout,
        &selected_effects,
        base.nominal.bias_dps,
        options,
        progress,
    );

    // 6. Summarise.
    let train_after = summarise::train_after(
        &runs,
        &base,
        &selected_sensor,
        &selected_effects,
        options,
        progress,
    );
    summarise::summarise(summarise::Findings {
        runs: &runs,
        baseline: base,
        r#where,
        untestable,
        holdout_before,
        candidates,
        selection,
        selected_effects,
        selected_sensor,
        train_after,
        compensation,
        corrected_model,
        turns,
        settings: &options.settings,
    })
}

/// Stages 5 and 5b of [`diagnose`]: the compensation of the `selected_effects` on the
/// held-out runs (`nominal_bias_dps` the nominal model's fitted bias), the corrected
/// model, and what the turns show.
fn compensate_and_turns(
    train: &[RealRun],
    holdout: &[RealRun],
    selected_effects: &[gyro_sim::Effect],
    nominal_bias_dps: f64,
    options: &Options,
    progress: &dyn Progress,
) -> (
    Option<CompensationSummary>,
    Option<ModelFile>,
    Option<turns::TurnEvidence>,
) {
    // 5. Compensate the correctable effects (scales from the turns when the reference
    // lags beyond the per-sample statistic).
    // A count-stamped clock named: the lag grows by its doing, and what is left is the
    // lag line's start.
    let growing = selected_effects.iter().any(summarise::is_count_clock);
    let train_lags_s = turns::run_lags_s(train, growing, &options.settings);
    let (compensation, corrected_model) = compensate::compensate(
        holdout,
        options,
        turns::lag_beyond_statistic(&train_lags_s, options.settings.statistics.max_lag_s),
        // The nominal model's bias is fitted on the training runs unless it was given.
        if options.fixed_model {
            0.0
        } else {
            nominal_bias_dps
        },
        selected_effects,
        progress,
    );

    // 5b. What the turns show, rest to rest, on top of what was written.
    let turn_base = corrected_model
        .clone()
        .unwrap_or_else(|| options.base_model.clone());
    let (turns, turn_model) =
        turns::turn_evidence(train, &train_lags_s, growing, holdout, &turn_base, options);
    let corrected_model = turn_model.or(corrected_model);
    (compensation, corrected_model, turns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_settings_are_refused_before_any_run_is_read() {
        let mut options = Options::default();
        options.settings.tests.z_critical = f64::NAN;
        let e = diagnose(&[], &[], &options, &Silent).expect_err("NaN z must be refused");
        assert!(matches!(
            e,
            DiagnoseError::Settings(SettingsError::NonFinite(name)) if name.ends_with("z_critical")
        ));
        assert!(e.to_string().contains("z_critical"), "{e}");
    }
}
