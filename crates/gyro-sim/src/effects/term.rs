//! The simulator terms of a set of effects: each table entry's `term` adds its
//! parameters here, and the sensor simulation reads the sum (identity when empty).

use super::Effect;

/// The simulator's effect terms, accumulated over a set of effects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SimTerms {
    /// Relative scale error.
    pub(crate) scale_k: f64,
    /// Scale asymmetry by the sign of the rate.
    pub(crate) asymmetry_k: f64,
    /// Cubic coefficient (1/(deg/s)²).
    pub(crate) k3_per_dps2: f64,
    /// Quadratic coefficient (1/(deg/s)).
    pub(crate) k2_per_dps: f64,
    /// Clip level (deg/s); infinite for none (the sensor's range still applies).
    pub(crate) limit_dps: f64,
    /// Extra output rounding (deg/s); 0 for none.
    pub(crate) extra_lsb_dps: f64,
    /// Delay of the gyro behind the motion (s).
    pub(crate) delay_s: f64,
    /// Sample-clock error, rows stamped by the logger's clock (ppm).
    pub(crate) clock_ppm: f64,
    /// Sample-clock error, rows stamped by the sensor's sample count (ppm).
    pub(crate) count_clock_ppm: f64,
    /// Dropout events per second and mean samples lost per event.
    pub(crate) dropouts: Option<(f64, f64)>,
    /// Bias per °C of temperature change (deg/s/°C).
    pub(crate) bias_dps_per_c: f64,
    /// Scale per °C of temperature change (1/°C).
    pub(crate) scale_per_c: f64,
    /// Standard deviation of the flicker-like wander (deg/s).
    pub(crate) flicker_sigma_dps: Option<f64>,
    /// Rate random walk (deg/s/√s).
    pub(crate) walk_dps_per_rt_s: f64,
    /// Turn-on bias spread across runs (deg/s).
    pub(crate) turn_on_sigma_dps: f64,
    /// The sensor's own low-pass (-3 dB, Hz).
    pub(crate) bandwidth_hz: Option<f64>,
    /// A vibration: peak amplitude (deg/s) and frequency (Hz).
    pub(crate) vibration: Option<(f64, f64)>,
}

impl Default for SimTerms {
    fn default() -> Self {
        Self {
            scale_k: 0.0,
            asymmetry_k: 0.0,
            k3_per_dps2: 0.0,
            k2_per_dps: 0.0,
            limit_dps: f64::INFINITY,
            extra_lsb_dps: 0.0,
            delay_s: 0.0,
            clock_ppm: 0.0,
            count_clock_ppm: 0.0,
            dropouts: None,
            bias_dps_per_c: 0.0,
            scale_per_c: 0.0,
            flicker_sigma_dps: None,
            walk_dps_per_rt_s: 0.0,
            turn_on_sigma_dps: 0.0,
            bandwidth_hz: None,
            vibration: None,
        }
    }
}

impl SimTerms {
    /// The terms of `effects`, each added by its table entry in order.
    pub(crate) fn of(effects: &[Effect]) -> Self {
        let mut terms = Self::default();
        for effect in effects {
            (effect.info().term)(&effect.params(), &mut terms);
        }
        terms
    }
}
