//! What a replay of a log runs with, from what `gyro-cli run` is given: the model file (or
//! the built-in configuration) with the given settings over it. One home for the command
//! line and the Python package (`gyro-py`), which both call [`RunSettings::resolve`].

use super::{Mode, ReplayOptions};
use crate::model::{self, ModelError, MAX_REFERENCE_DELAY_S};
use gyro_core::{Compensation, Config, Direction, Tightening};
use std::path::PathBuf;

/// The guard band of a tightening decision when none is given, in standard deviations.
pub const DEFAULT_K_SIGMA: f32 = 2.0;

/// What a replay is given, each setting named after `gyro-cli run`'s flag; `None`: the
/// model file's (else the built-in configuration's).
#[derive(Clone, Debug, PartialEq)]
pub struct RunSettings {
    /// `--model`: the model file whose configuration, range, tightening window, scale
    /// uncertainty and reference delay are the defaults.
    pub model: Option<PathBuf>,
    /// `--compensation`.
    pub compensation: Option<Compensation>,
    /// `--range-dps`.
    pub range_dps: Option<f32>,
    /// `--target-deg`: with `tolerance_deg`, a tightening window over the model's.
    pub target_deg: Option<f32>,
    /// `--tolerance-deg`.
    pub tolerance_deg: Option<f32>,
    /// `--k-sigma` of the given window ([`DEFAULT_K_SIGMA`] by default).
    pub k_sigma: f32,
    /// `--tightening-direction` of the given window.
    pub tightening_direction: Direction,
    /// `--scale-sigma`: else at least the model's.
    pub scale_sigma: Option<f32>,
    /// `--reference-delay-s`.
    pub reference_delay_s: Option<f64>,
    /// `--offline`.
    pub offline: bool,
}

impl Default for RunSettings {
    fn default() -> Self {
        Self {
            model: None,
            compensation: None,
            range_dps: None,
            target_deg: None,
            tolerance_deg: None,
            k_sigma: DEFAULT_K_SIGMA,
            tightening_direction: Direction::Positive,
            scale_sigma: None,
            reference_delay_s: None,
            offline: false,
        }
    }
}

/// What a replay runs with: the pipeline's configuration, the scoring options, the mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolved {
    /// The pipeline's configuration.
    pub config: Config,
    /// How the replay is scored.
    pub options: ReplayOptions,
    /// Causal or offline.
    pub mode: Mode,
}

/// Why the settings cannot be used; the messages are `gyro-cli run`'s.
#[derive(Debug, thiserror::Error)]
pub enum SettingsError {
    /// The reference delay is beyond what a model file may hold.
    #[error("--reference-delay-s {0}: expected at most {MAX_REFERENCE_DELAY_S} s either way")]
    ReferenceDelay(f64),
    /// The model file could not be used.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Half a tightening window.
    #[error("target_deg needs tolerance_deg (the tightening window's half-width)")]
    TargetWithoutTolerance,
    /// Half a tightening window.
    #[error("tolerance_deg needs target_deg (the tightening window's target)")]
    ToleranceWithoutTarget,
    /// The offline mode without the Kalman compensation.
    #[error(
        "--offline smooths the Kalman form's bias: it needs --compensation kalman (the model's compensation is {})",
        compensation_name(*.0)
    )]
    OfflineNeedsKalman(Compensation),
}

/// The compensation's name on the command line.
pub fn compensation_name(c: Compensation) -> &'static str {
    match c {
        Compensation::None => "none",
        Compensation::Paper => "paper",
        Compensation::Kalman => "kalman",
    }
}

/// Refuse a reference delay beyond what a model file may hold ([`MAX_REFERENCE_DELAY_S`]).
pub fn check_reference_delay(delay_s: Option<f64>) -> Result<(), SettingsError> {
    match delay_s {
        Some(d) if d.abs() > MAX_REFERENCE_DELAY_S => Err(SettingsError::ReferenceDelay(d)),
        _ => Ok(()),
    }
}

impl RunSettings {
    /// The configuration, scoring options and mode these settings give: the model file's
    /// (else [`Config::default`]) with its range, the given range, window, scale
    /// uncertainty (as given, else at least the model's calibration measured), compensation
    /// and reference delay over it.
    pub fn resolve(&self) -> Result<Resolved, SettingsError> {
        check_reference_delay(self.reference_delay_s)?;
        let (mut config, mut options, model_scale_sigma) = match &self.model {
            Some(path) => {
                let model = model::load(path)?;
                let config = Config {
                    range_dps: model.range_dps(),
                    ..model.config
                };
                (
                    config,
                    ReplayOptions::from_model(&model),
                    model.scale_sigma as f32,
                )
            }
            None => (Config::default(), ReplayOptions::default(), 0.0),
        };
        if let Some(delay_s) = self.reference_delay_s {
            options.reference_delay_s = delay_s;
        }
        if let Some(range_dps) = self.range_dps {
            config.range_dps = Some(range_dps);
        }
        match (self.target_deg, self.tolerance_deg) {
            (Some(target_deg), Some(tolerance_deg)) => {
                config.tightening = Some(Tightening {
                    target_deg,
                    tolerance_deg,
                    k_sigma: self.k_sigma,
                    direction: self.tightening_direction,
                    scale_sigma: 0.0,
                });
            }
            (Some(_), None) => return Err(SettingsError::TargetWithoutTolerance),
            (None, Some(_)) => return Err(SettingsError::ToleranceWithoutTarget),
            (None, None) => {}
        }
        // The scale uncertainty: as given, else at least what the model's calibration
        // measured (the model's own window keeps a larger one).
        if let Some(t) = &mut config.tightening {
            t.scale_sigma = match self.scale_sigma {
                Some(given) => given,
                None => t.scale_sigma.max(model_scale_sigma),
            };
        }
        if let Some(c) = self.compensation {
            config.compensation = c;
        }
        if self.offline && config.compensation != Compensation::Kalman {
            return Err(SettingsError::OfflineNeedsKalman(config.compensation));
        }
        let mode = if self.offline {
            Mode::Offline
        } else {
            Mode::Causal
        };
        Ok(Resolved {
            config,
            options,
            mode,
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn the_default_is_the_built_in_configuration() {
        let r = RunSettings::default().resolve().unwrap();
        assert_eq!(r.config, Config::default());
        assert_eq!(r.options, ReplayOptions::default());
        assert_eq!(r.mode, Mode::Causal);
    }

    #[test]
    fn a_window_and_its_refusals() {
        let s = RunSettings {
            target_deg: Some(90.0),
            tolerance_deg: Some(1.0),
            scale_sigma: Some(0.01),
            ..RunSettings::default()
        };
        let t = s.resolve().unwrap().config.tightening.unwrap();
        assert_eq!((t.target_deg, t.k_sigma, t.scale_sigma), (90.0, 2.0, 0.01));
        let half = RunSettings {
            tolerance_deg: None,
            ..s.clone()
        };
        assert!(matches!(
            half.resolve(),
            Err(SettingsError::TargetWithoutTolerance)
        ));
        let far = RunSettings {
            reference_delay_s: Some(-1.5),
            ..s
        };
        assert_eq!(
            far.resolve().unwrap_err().to_string(),
            "--reference-delay-s -1.5: expected at most 1 s either way"
        );
        let offline = RunSettings {
            offline: true,
            compensation: Some(Compensation::Paper),
            ..RunSettings::default()
        };
        assert!(offline
            .resolve()
            .unwrap_err()
            .to_string()
            .contains("(the model's compensation is paper)"));
    }
}
