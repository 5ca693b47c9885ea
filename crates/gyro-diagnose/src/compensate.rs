//! Compensation of the correctable effects: written into a model file, applied by
//! `run --model`, and scored on the held-out runs (the pipeline's max abs angle error
//! without and with it).
//!
//! What the core corrects is each effect's [`CoreCorrection`] in the effect table
//! (`gyro_sim::EFFECTS`): a scale, asymmetry or temperature coefficient of the core's
//! correction (ΔT from the first temperature of the run, as the simulator defines it),
//! the model file's reference delay (a low-pass: its low-frequency delay,
//! [`gyro_sim::low_pass_delay_s`]), a count-stamped clock (a scale and the model file's
//! `count_clock_ppm`), or Kalman compensation of the bias at every rest.

use super::ensemble::RealRun;
use super::{CompensationRun, CompensationSummary, NotCorrected};
use gyro_analysis::model::ModelFile;
use gyro_analysis::replay::{replay_with, ReplayOptions};
use gyro_core::Compensation;
use gyro_sim::{CoreCorrection, Effect};
use rayon::prelude::*;

/// `base` with the corrections of `effects`, and the ids corrected.
pub fn corrected_model(base: &ModelFile, effects: &[Effect]) -> (ModelFile, Vec<&'static str>) {
    let mut model = base.clone();
    let mut ids = Vec::new();
    let c = &mut model.config.correction;
    for effect in effects {
        let Some(&value) = effect.params().first() else {
            continue;
        };
        let used = match effect.info().correction {
            CoreCorrection::None => false,
            CoreCorrection::ScaleK { per_unit } => {
                c.scale_k += (value * per_unit) as f32;
                true
            }
            CoreCorrection::AsymmetryK => {
                c.asymmetry_k += value as f32;
                true
            }
            CoreCorrection::BiasPerC => {
                c.bias_dps_per_c += value as f32;
                true
            }
            CoreCorrection::ScalePerC => {
                c.scale_per_c += value as f32;
                true
            }
            CoreCorrection::ReferenceDelay => {
                model.reference_delay_s += value;
                true
            }
            CoreCorrection::CountClock => {
                c.scale_k += (value * 1e-6) as f32;
                model.count_clock_ppm += value;
                true
            }
            CoreCorrection::LowPassReferenceDelay => {
                model.reference_delay_s += gyro_sim::low_pass_delay_s(value);
                true
            }
            CoreCorrection::KalmanBias => {
                model.config.compensation = Compensation::Kalman;
                true
            }
        };
        if used {
            ids.push(effect.id());
        }
    }
    (model, ids)
}

/// Id of the bias correction in [`CompensationSummary`]: the nominal model's bias.
pub const BIAS_ID: &str = "bias";

/// Why a scale-type correction is not written when the reference lags beyond the
/// per-sample statistic ([`super::turns::lag_beyond_statistic`]).
pub const SCALE_FROM_TURNS: &str = "the reference lags beyond the per-sample statistic's reach, so the per-sample residual during turns is the rate times the lag, which a fit on the rate reads as a scale: the turns' totals, rest to rest, measure the scale instead";

/// Whether `effect`'s correction scales the rate (a fit of the residual on the rate, or
/// on the rate times the temperature).
fn is_scale(effect: &Effect) -> bool {
    matches!(
        effect.info().correction,
        CoreCorrection::ScaleK { .. } | CoreCorrection::AsymmetryK | CoreCorrection::ScalePerC
    )
}

/// A correction to try.
#[derive(Clone, Copy)]
enum Try {
    /// The nominal model's bias (deg/s), as the starting bias of the rest detector and the
    /// Kalman filter's bias mean: what the pipeline uses until a rest says otherwise.
    Bias(f64),
    /// A selected correctable effect.
    Effect(Effect),
}

/// `base` with the corrections of `tries`, and the ids corrected.
fn with_tries(base: &ModelFile, tries: &[Try]) -> (ModelFile, Vec<&'static str>) {
    let effects: Vec<Effect> = tries
        .iter()
        .filter_map(|t| match t {
            Try::Effect(e) => Some(*e),
            Try::Bias(_) => None,
        })
        .collect();
    let (mut model, mut ids) = corrected_model(base, &effects);
    for t in tries {
        if let Try::Bias(b) = t {
            model.config.motion.initial_bias_dps += *b as f32;
            model.config.kalman.bias_mean_dps += *b as f32;
            ids.insert(0, BIAS_ID);
        }
    }
    (model, ids)
}

/// Stage 5: the corrections that lower the held-out angle error, each on top of those
/// kept before it: first the nominal model's bias (`bias_dps`, fitted on the training
/// runs; skipped when zero), then the selected correctable effects in selection order.
/// Paired over the held-out runs, the total max abs error must fall with bootstrap P <
/// `tests.p_value` ([`crate::Settings`]); the others are named, not corrected. Returns the summary (when there
/// is anything to try) and the model to write (when a correction is kept).
pub(crate) fn compensate(
    holdout: &[RealRun],
    options: &super::Options,
    scale_from_turns: bool,
    bias_dps: f64,
    selected: &[Effect],
    progress: &dyn super::Progress,
) -> (Option<CompensationSummary>, Option<ModelFile>) {
    let base = &options.base_model;
    let mut tries: Vec<Try> = Vec::new();
    if bias_dps.is_finite() && bias_dps != 0.0 {
        tries.push(Try::Bias(bias_dps));
    }
    tries.extend(
        selected
            .iter()
            .filter(|e| !matches!(e.info().correction, CoreCorrection::None))
            .map(|e| Try::Effect(*e)),
    );
    if tries.is_empty() {
        return (None, None);
    }
    progress.stage("compensated replays of held-out runs", 0);
    let before = max_abs_errors(holdout, base);
    let mut kept: Vec<Try> = Vec::new();
    let mut current = before.clone();
    let mut not_corrected = Vec::new();
    for (k, t) in tries.iter().enumerate() {
        let mut trial = kept.clone();
        trial.push(*t);
        let (model, _) = with_tries(base, &trial);
        let after = max_abs_errors(holdout, &model);
        let paired = paired_gains(&current, &after);
        let seed = gyro_analysis::seed::derive_seed(options.seed, "correction", k as u64);
        let p = super::score::bootstrap_p(&paired, options.bootstrap.max(1), seed);
        let reason = match t {
            Try::Effect(e) if scale_from_turns && is_scale(e) => Some(SCALE_FROM_TURNS),
            _ => None,
        };
        if reason.is_none() && !paired.is_empty() && p < options.settings.tests.p_value {
            kept = trial;
            current = after;
        } else {
            not_corrected.push(NotCorrected {
                id: match t {
                    Try::Bias(_) => BIAS_ID,
                    Try::Effect(e) => e.id(),
                },
                median_max_abs_error_without_deg: median(&current),
                median_max_abs_error_with_deg: median(&after),
                runs_better: paired.iter().filter(|d| **d > 0.0).count(),
                runs: paired.len(),
                bootstrap_p: p,
                reason,
            });
        }
    }
    let (corrected, ids) = with_tries(base, &kept);
    let runs = holdout
        .iter()
        .zip(before.iter().zip(&current))
        .map(|(run, (b, a))| CompensationRun {
            name: run.name.clone(),
            max_abs_error_before_deg: *b,
            max_abs_error_after_deg: *a,
        })
        .collect();
    let summary = CompensationSummary {
        corrected: ids.clone(),
        not_corrected,
        runs,
    };
    (Some(summary), (!ids.is_empty()).then_some(corrected))
}

/// Per run, the error without less the error with (positive: better with), where both
/// are finite: what the bootstrap over held-out runs is taken on.
pub(super) fn paired_gains(without: &[f64], with: &[f64]) -> Vec<f64> {
    without
        .iter()
        .zip(with)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| a - b)
        .collect()
}

/// Median of the finite values (NaN when none).
pub(super) fn median(values: &[f64]) -> f64 {
    let finite: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    gyro_analysis::median(&finite).unwrap_or(f64::NAN)
}

/// Max abs angle error of every held-out run replayed with `model` (NaN when a run
/// cannot be replayed or has no reference).
pub(super) fn max_abs_errors(holdout: &[RealRun], model: &ModelFile) -> Vec<f64> {
    holdout
        .par_iter()
        .map(|run| {
            replay_with(&run.log, &model.config, &ReplayOptions::from_model(model))
                .ok()
                .and_then(|r| r.summary.max_abs_error_deg)
                .unwrap_or(f64::NAN)
        })
        .collect()
}
