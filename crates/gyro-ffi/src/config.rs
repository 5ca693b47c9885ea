//! The plain C configuration, and its conversion to and from gyro-core's `Config`.
//!
//! Floats are taken as they come (gyro-core validates them); flags and codes are `uint8_t`
//! checked here, so that no byte a C program writes can make an invalid Rust value.

use gyro_core::{
    Butterworth, Compensation, Config, Correction, Direction, GaussMarkov, KalmanConfig,
    MotionConfig, Tightening,
};

use crate::status::{GyroField, GyroStatus, Refusal};

/// Which error compensation gives the angle (`GyroConfig.compensation`).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroCompensation {
    /// The integrated rate as it is.
    None = 0,
    /// The paper's Gauss-Markov error model, subtracted per movement (`GyroConfig.paper`).
    Paper = 1,
    /// The Kalman form: Gauss-Markov bias with zero-rate updates at rest; gives the angle's
    /// standard deviation. The default.
    Kalman = 2,
}

/// Which sign of the angle tightens (`GyroTighteningConfig.direction`).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroDirection {
    /// A positive angle tightens.
    Positive = 0,
    /// A negative angle tightens.
    Negative = 1,
}

/// The low-pass filter, applied at the output rate.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroFilterConfig {
    /// Butterworth order (1 to 8; 2 by default).
    pub order: u8,
    /// Cutoff frequency (Hz), below half the output rate (12.5 by default).
    pub cutoff_hz: f32,
}

/// Motion detection, on the filtered rate minus the bias reference.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroMotionConfig {
    /// A movement must exceed this |rate − bias| (deg/s) at least once.
    pub enter_dps: f32,
    /// At or below this |rate − bias| (deg/s) a sample is quiet (at most `enter_dps`).
    pub exit_dps: f32,
    /// Least duration of a run of non-quiet samples that makes a movement (s).
    pub min_motion_s: f32,
    /// Quiet time that ends a movement (s).
    pub min_rest_s: f32,
    /// Bias reference (deg/s) until the first rest has been seen.
    pub initial_bias_dps: f32,
}

/// The paper's error model (`GYRO_COMPENSATION_PAPER`), as fitted by `gyro-cli calibrate`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroPaperConfig {
    /// Inverse correlation time β of the bias (1/s), at least 0.
    pub beta_per_s: f32,
    /// Bias at the start of a movement, b0 (deg/s).
    pub b0_dps: f32,
    /// Misalignment at the start of a movement, o0 (deg).
    pub o0_deg: f32,
}

/// The Kalman form (`GYRO_COMPENSATION_KALMAN`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroKalmanConfig {
    /// Inverse correlation time β of the bias (1/s), at least 0.
    pub beta_per_s: f32,
    /// Stationary standard deviation of the bias's wander within a run (deg/s).
    pub bias_sigma_dps: f32,
    /// The bias expected at power-up (deg/s): the estimate before the first rest.
    pub bias_mean_dps: f32,
    /// White rate noise, standard deviation per output sample (deg/s).
    pub rate_noise_dps: f32,
    /// Standard deviation of the initial bias estimate (deg/s): the spread of the bias
    /// between power-ups.
    pub initial_bias_sigma_dps: f32,
}

/// Correction of the sensor's scale and temperature errors (the identity by default): the
/// sensor reads `m = r·(1 + k + a·sign(r) + s·ΔT) + c·ΔT`, the pipeline inverts it. The
/// temperature terms apply only to samples pushed with `gyro_pipeline_push_with_temperature`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroCorrectionConfig {
    /// Scale error k (1 = 100%), within ±0.25.
    pub scale_k: f32,
    /// Scale asymmetry a: `r·(1 + a)` for positive rates, `r·(1 − a)` for negative ones.
    pub asymmetry_k: f32,
    /// Temperature bias c (deg/s per °C of ΔT), within ±10.
    pub bias_dps_per_c: f32,
    /// Temperature scale s (1/°C).
    pub scale_per_c: f32,
    /// 1: `temperature_ref_c` is the reference of ΔT; 0: the first valid temperature pushed.
    pub has_temperature_ref_c: u8,
    /// Reference temperature of ΔT (°C), used when `has_temperature_ref_c` is 1.
    pub temperature_ref_c: f32,
}

/// The tightening window movements are judged against (`GyroMovement.verdict`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroTighteningConfig {
    /// 1: judge every movement that ends; 0: no verdicts (the default).
    pub enabled: u8,
    /// Target angle (deg), in the tightening direction (> 0).
    pub target_deg: f32,
    /// Half-width of the window (deg): accepted angles lie in target ± tolerance.
    pub tolerance_deg: f32,
    /// Coverage factor k of the guard band k·σ (2 by default).
    pub k_sigma: f32,
    /// Which sign tightens: a `GyroDirection` code.
    pub direction: u8,
    /// Relative standard uncertainty of the scale factor (0.01 for 1%), added to σ in
    /// quadrature as `scale_sigma · |angle|` (0 by default: a calibrated scale).
    pub scale_sigma: f32,
}

/// Everything a pipeline is configured by. Fill it with `gyro_config_default`, then change
/// what differs: `gyro_pipeline_init` checks every field.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroConfig {
    /// Input sample rate (Hz; 1000 by default).
    pub sample_rate_hz: f32,
    /// Target output rate (Hz; 50 by default); the decimation factor is
    /// `round(sample_rate_hz / output_rate_hz)`.
    pub output_rate_hz: f32,
    /// Input samples with |rate| above this (deg/s) are rejected as implausible, and
    /// replaced by the last valid rate.
    pub max_abs_rate_dps: f32,
    /// The low-pass filter.
    pub filter: GyroFilterConfig,
    /// Motion detection.
    pub motion: GyroMotionConfig,
    /// Which compensation gives the angle: a `GyroCompensation` code.
    pub compensation: u8,
    /// The paper's error model.
    pub paper: GyroPaperConfig,
    /// The Kalman form.
    pub kalman: GyroKalmanConfig,
    /// Correction of scale and temperature errors.
    pub correction: GyroCorrectionConfig,
    /// 1: `range_dps` is the sensor's full-scale range; 0: unknown (the default).
    pub has_range_dps: u8,
    /// The sensor's full-scale range (deg/s), used when `has_range_dps` is 1: a movement
    /// during which a reading reaches it is flagged saturated, until a reading goes
    /// beyond it (then it is not this sensor's range; see
    /// `GyroPipelineInfo::range_contradicted`).
    pub range_dps: f32,
    /// The tightening window.
    pub tightening: GyroTighteningConfig,
}

/// `0` or `1` as a bool, anything else refused as out of range.
fn flag(value: u8, field: GyroField) -> Result<bool, Refusal> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err((GyroStatus::ConfigOutOfRange, field)),
    }
}

impl GyroConfig {
    /// gyro-core's configuration as the C struct.
    pub(crate) fn from_core(config: &Config) -> Self {
        let correction = &config.correction;
        let tightening = config.tightening.unwrap_or_default();
        Self {
            sample_rate_hz: config.sample_rate_hz,
            output_rate_hz: config.output_rate_hz,
            max_abs_rate_dps: config.max_abs_rate_dps,
            filter: GyroFilterConfig {
                order: config.filter.order,
                cutoff_hz: config.filter.cutoff_hz,
            },
            motion: GyroMotionConfig {
                enter_dps: config.motion.enter_dps,
                exit_dps: config.motion.exit_dps,
                min_motion_s: config.motion.min_motion_s,
                min_rest_s: config.motion.min_rest_s,
                initial_bias_dps: config.motion.initial_bias_dps,
            },
            compensation: match config.compensation {
                Compensation::None => GyroCompensation::None,
                Compensation::Paper => GyroCompensation::Paper,
                Compensation::Kalman => GyroCompensation::Kalman,
            } as u8,
            paper: GyroPaperConfig {
                beta_per_s: config.paper.beta_per_s,
                b0_dps: config.paper.b0_dps,
                o0_deg: config.paper.o0_deg,
            },
            kalman: GyroKalmanConfig {
                beta_per_s: config.kalman.beta_per_s,
                bias_sigma_dps: config.kalman.bias_sigma_dps,
                bias_mean_dps: config.kalman.bias_mean_dps,
                rate_noise_dps: config.kalman.rate_noise_dps,
                initial_bias_sigma_dps: config.kalman.initial_bias_sigma_dps,
            },
            correction: GyroCorrectionConfig {
                scale_k: correction.scale_k,
                asymmetry_k: correction.asymmetry_k,
                bias_dps_per_c: correction.bias_dps_per_c,
                scale_per_c: correction.scale_per_c,
                has_temperature_ref_c: u8::from(correction.temperature_ref_c.is_some()),
                temperature_ref_c: correction.temperature_ref_c.unwrap_or(0.0),
            },
            has_range_dps: u8::from(config.range_dps.is_some()),
            range_dps: config.range_dps.unwrap_or(0.0),
            tightening: GyroTighteningConfig {
                enabled: u8::from(config.tightening.is_some()),
                target_deg: tightening.target_deg,
                tolerance_deg: tightening.tolerance_deg,
                k_sigma: tightening.k_sigma,
                direction: match tightening.direction {
                    Direction::Positive => GyroDirection::Positive,
                    Direction::Negative => GyroDirection::Negative,
                } as u8,
                scale_sigma: tightening.scale_sigma,
            },
        }
    }

    /// The C struct as gyro-core's configuration; flags and codes are checked here, the
    /// numbers by gyro-core when the pipeline is built.
    pub(crate) fn to_core(self) -> Result<Config, Refusal> {
        let compensation = match self.compensation {
            0 => Compensation::None,
            1 => Compensation::Paper,
            2 => Compensation::Kalman,
            _ => return Err((GyroStatus::ConfigOutOfRange, GyroField::Compensation)),
        };
        let correction = &self.correction;
        let has_reference = flag(
            correction.has_temperature_ref_c,
            GyroField::CorrectionHasTemperatureRefC,
        )?;
        let has_range = flag(self.has_range_dps, GyroField::HasRangeDps)?;
        let tightening = &self.tightening;
        let judged = flag(tightening.enabled, GyroField::TighteningEnabled)?;
        let direction = match tightening.direction {
            0 => Direction::Positive,
            1 => Direction::Negative,
            _ => return Err((GyroStatus::ConfigOutOfRange, GyroField::TighteningDirection)),
        };
        Ok(Config {
            sample_rate_hz: self.sample_rate_hz,
            output_rate_hz: self.output_rate_hz,
            max_abs_rate_dps: self.max_abs_rate_dps,
            filter: Butterworth {
                order: self.filter.order,
                cutoff_hz: self.filter.cutoff_hz,
            },
            motion: MotionConfig {
                enter_dps: self.motion.enter_dps,
                exit_dps: self.motion.exit_dps,
                min_motion_s: self.motion.min_motion_s,
                min_rest_s: self.motion.min_rest_s,
                initial_bias_dps: self.motion.initial_bias_dps,
            },
            compensation,
            paper: GaussMarkov {
                beta_per_s: self.paper.beta_per_s,
                b0_dps: self.paper.b0_dps,
                o0_deg: self.paper.o0_deg,
            },
            kalman: KalmanConfig {
                beta_per_s: self.kalman.beta_per_s,
                bias_sigma_dps: self.kalman.bias_sigma_dps,
                bias_mean_dps: self.kalman.bias_mean_dps,
                rate_noise_dps: self.kalman.rate_noise_dps,
                initial_bias_sigma_dps: self.kalman.initial_bias_sigma_dps,
            },
            correction: Correction {
                scale_k: correction.scale_k,
                asymmetry_k: correction.asymmetry_k,
                bias_dps_per_c: correction.bias_dps_per_c,
                scale_per_c: correction.scale_per_c,
                temperature_ref_c: has_reference.then_some(correction.temperature_ref_c),
            },
            range_dps: has_range.then_some(self.range_dps),
            tightening: judged.then_some(Tightening {
                target_deg: tightening.target_deg,
                tolerance_deg: tightening.tolerance_deg,
                k_sigma: tightening.k_sigma,
                direction,
                scale_sigma: tightening.scale_sigma,
            }),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_goes_there_and_back() {
        let config = Config::default();
        assert_eq!(GyroConfig::from_core(&config).to_core(), Ok(config));
    }

    /// Every field set to a value of its own: a field copied to the wrong place, or not at
    /// all, comes back different.
    #[test]
    fn every_field_goes_there_and_back() {
        let config = Config {
            sample_rate_hz: 1.5,
            output_rate_hz: 2.5,
            max_abs_rate_dps: 3.5,
            filter: Butterworth {
                order: 4,
                cutoff_hz: 4.5,
            },
            motion: MotionConfig {
                enter_dps: 5.5,
                exit_dps: 6.5,
                min_motion_s: 7.5,
                min_rest_s: 8.5,
                initial_bias_dps: 9.5,
            },
            compensation: Compensation::Paper,
            paper: GaussMarkov {
                beta_per_s: 10.5,
                b0_dps: 11.5,
                o0_deg: 12.5,
            },
            kalman: KalmanConfig {
                beta_per_s: 13.5,
                bias_sigma_dps: 14.5,
                bias_mean_dps: 15.5,
                rate_noise_dps: 16.5,
                initial_bias_sigma_dps: 17.5,
            },
            correction: Correction {
                scale_k: 18.5,
                asymmetry_k: 19.5,
                bias_dps_per_c: 20.5,
                scale_per_c: 21.5,
                temperature_ref_c: Some(22.5),
            },
            range_dps: Some(23.5),
            tightening: Some(Tightening {
                target_deg: 24.5,
                tolerance_deg: 25.5,
                k_sigma: 26.5,
                direction: Direction::Negative,
                scale_sigma: 27.5,
            }),
        };
        let c = GyroConfig::from_core(&config);
        assert_eq!(c.compensation, GyroCompensation::Paper as u8);
        assert_eq!(c.tightening.direction, GyroDirection::Negative as u8);
        assert_eq!(c.to_core(), Ok(config));
        for compensation in [Compensation::None, Compensation::Kalman] {
            let config = Config {
                compensation,
                ..config
            };
            assert_eq!(GyroConfig::from_core(&config).to_core(), Ok(config));
        }
    }

    #[test]
    fn flags_and_codes_other_than_their_values_are_refused() {
        let valid = GyroConfig::from_core(&Config::default());
        let out_of_range = |field| Err((GyroStatus::ConfigOutOfRange, field));
        let mut c = valid;
        c.compensation = 3;
        assert_eq!(c.to_core(), out_of_range(GyroField::Compensation));
        let mut c = valid;
        c.has_range_dps = 2;
        assert_eq!(c.to_core(), out_of_range(GyroField::HasRangeDps));
        let mut c = valid;
        c.correction.has_temperature_ref_c = 0xff;
        assert_eq!(
            c.to_core(),
            out_of_range(GyroField::CorrectionHasTemperatureRefC)
        );
        let mut c = valid;
        c.tightening.enabled = 7;
        assert_eq!(c.to_core(), out_of_range(GyroField::TighteningEnabled));
        let mut c = valid;
        c.tightening.direction = 2;
        assert_eq!(c.to_core(), out_of_range(GyroField::TighteningDirection));
    }
}
