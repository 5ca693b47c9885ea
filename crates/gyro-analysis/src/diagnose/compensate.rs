//! Compensation of the correctable effects: written into a model file, applied by
//! `run --model`, and scored on the held-out runs (the pipeline's max abs angle error
//! without and with it).
//!
//! What the core corrects, per effect: `scale_factor` → `correction.scale_k`;
//! `clock_error` → `correction.scale_k` too (integrated over nominal periods, the samples
//! of a clock fast by ε give 1 + ε times the angle, exactly like a scale factor); `scale_asymmetry` →
//! `correction.asymmetry_k`; `temperature_bias` → `correction.bias_dps_per_c` and
//! `temperature_scale` → `correction.scale_per_c` (ΔT from the first temperature of the
//! run, as the simulator defines them); `latency` → `reference_delay_s`; `bandwidth` →
//! `reference_delay_s` of its low-frequency delay (2 / (2π · 1.554 f_c) for the two-pole
//! response); `turn_on_bias` → Kalman compensation (the bias estimated at every rest).
//! The others (nonlinearity, saturation, quantisation, dropouts, bias wander) have no
//! correction in the core.

use super::ensemble::RealRun;
use super::{CompensationRun, CompensationSummary};
use crate::model::ModelFile;
use crate::replay::{replay_with, ReplayOptions};
use gyro_core::Compensation;
use gyro_sim::Effect;
use rayon::prelude::*;

/// `base` with the corrections of `effects`, and the ids corrected.
pub fn corrected_model(base: &ModelFile, effects: &[Effect]) -> (ModelFile, Vec<&'static str>) {
    let mut model = base.clone();
    let mut ids = Vec::new();
    let c = &mut model.config.correction;
    for effect in effects {
        let used = match *effect {
            Effect::ScaleFactor { k } => {
                c.scale_k += k as f32;
                true
            }
            Effect::ClockError { ppm } => {
                c.scale_k += (ppm * 1e-6) as f32;
                true
            }
            Effect::ScaleAsymmetry { k } => {
                c.asymmetry_k += k as f32;
                true
            }
            Effect::TemperatureBias { dps_per_c } => {
                c.bias_dps_per_c += dps_per_c as f32;
                true
            }
            Effect::TemperatureScale { per_c } => {
                c.scale_per_c += per_c as f32;
                true
            }
            Effect::Latency { delay_s } => {
                model.reference_delay_s += delay_s;
                true
            }
            Effect::Bandwidth { cutoff_hz } => {
                model.reference_delay_s += 1.0 / (std::f64::consts::PI * 1.5538 * cutoff_hz);
                true
            }
            Effect::TurnOnBias { .. } => {
                model.config.compensation = Compensation::Kalman;
                true
            }
            _ => false,
        };
        if used {
            ids.push(effect.id());
        }
    }
    (model, ids)
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
