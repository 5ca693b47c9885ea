//! Compensation of the correctable effects: written into a model file, applied by
//! `run --model`, and scored on the held-out runs (the pipeline's max abs angle error
//! without and with it).
//!
//! What the core corrects is each effect's [`CoreCorrection`] in the effect table
//! (`gyro_sim::EFFECTS`): a scale, asymmetry or temperature coefficient of the core's
//! correction (ΔT from the first temperature of the run, as the simulator defines it),
//! the model file's reference delay (a low-pass: its low-frequency delay
//! 2 / (2π · 1.554 f_c)), or Kalman compensation of the bias at every rest.

use super::ensemble::RealRun;
use super::{CompensationRun, CompensationSummary};
use crate::model::ModelFile;
use crate::replay::{replay_with, ReplayOptions};
use gyro_core::Compensation;
use gyro_sim::{CoreCorrection, Effect, LOW_PASS_POLE_RATIO};
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
            CoreCorrection::LowPassReferenceDelay => {
                model.reference_delay_s +=
                    1.0 / (std::f64::consts::PI * LOW_PASS_POLE_RATIO * value);
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

/// Stage 5: the base model with the corrections of the selected effects and its
/// held-out angle errors, when any selected effect is correctable.
pub(crate) fn compensate(
    holdout: &[RealRun],
    base: &ModelFile,
    selected: &[Effect],
    progress: &dyn super::Progress,
) -> (Option<CompensationSummary>, Option<ModelFile>) {
    let (corrected, ids) = corrected_model(base, selected);
    if ids.is_empty() {
        return (None, None);
    }
    progress.stage("compensated replays of held-out runs", 0);
    let summary = score(holdout, base, &corrected, ids);
    (Some(summary), Some(corrected))
}

/// Max abs angle error of every held-out run with `base` and with `corrected`.
pub fn score(
    holdout: &[RealRun],
    base: &ModelFile,
    corrected: &ModelFile,
    ids: Vec<&'static str>,
) -> CompensationSummary {
    let runs = holdout
        .par_iter()
        .map(|run| {
            let max_abs = |m: &ModelFile| -> f64 {
                replay_with(&run.log, &m.config, &ReplayOptions::from_model(m))
                    .ok()
                    .and_then(|r| r.summary.max_abs_error_deg)
                    .unwrap_or(f64::NAN)
            };
            CompensationRun {
                name: run.name.clone(),
                max_abs_error_before_deg: max_abs(base),
                max_abs_error_after_deg: max_abs(corrected),
            }
        })
        .collect();
    CompensationSummary {
        corrected: ids,
        runs,
    }
}
