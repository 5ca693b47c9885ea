//! Kalman form of the error model: angle and Gauss-Markov bias, zero-rate updates at rest.
//!
//! State `x = [θ, b]`: angle (deg) and gyro bias (deg/s). The bias is a first-order
//! Gauss-Markov process around `bias_mean_dps` with correlation time `1/β` and stationary
//! standard deviation `bias_sigma_dps`. While moving, the angle integrates `rate − b̂`, so
//! its error grows with the bias error (the covariance couples them). At rest the measured
//! rate is an observation of the bias (the true rate is zero); the update corrects the
//! bias and, through the coupling, the angle accumulated during the last movement.

use crate::error::{check_range, Error};
use nalgebra::{Matrix2, RowVector2, Vector2};

/// Settings of the Kalman form.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct KalmanConfig {
    /// Inverse correlation time β of the bias (1/s), ≥ 0.
    pub beta_per_s: f32,
    /// Stationary standard deviation of the bias about its mean (deg/s).
    pub bias_sigma_dps: f32,
    /// Long-term mean of the bias (deg/s).
    pub bias_mean_dps: f32,
    /// White rate noise, standard deviation per output sample (deg/s).
    pub rate_noise_dps: f32,
    /// Standard deviation of the initial bias estimate (deg/s).
    pub initial_bias_sigma_dps: f32,
}

impl Default for KalmanConfig {
    fn default() -> Self {
        Self {
            beta_per_s: 1.0 / 300.0,
            bias_sigma_dps: 0.5,
            bias_mean_dps: 0.0,
            rate_noise_dps: 0.05,
            initial_bias_sigma_dps: 1.0,
        }
    }
}

impl KalmanConfig {
    /// Check the settings.
    pub fn validate(&self) -> Result<(), Error> {
        check_range("kalman.beta_per_s", self.beta_per_s.into(), 0.0, 1e6)?;
        check_range(
            "kalman.bias_sigma_dps",
            self.bias_sigma_dps.into(),
            0.0,
            1e4,
        )?;
        check_range("kalman.bias_mean_dps", self.bias_mean_dps.into(), -1e4, 1e4)?;
        check_range(
            "kalman.rate_noise_dps",
            self.rate_noise_dps.into(),
            1e-9,
            1e4,
        )?;
        check_range(
            "kalman.initial_bias_sigma_dps",
            self.initial_bias_sigma_dps.into(),
            0.0,
            1e4,
        )?;
        Ok(())
    }
}

/// The filter's state for a fixed step `dt_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanBias {
    dt_s: f32,
    phi: f32,
    bias_mean_dps: f32,
    q_bias: f32,
    q_angle: f32,
    r_rate: f32,
    bias_dps: f32,
    p: Matrix2<f32>,
}

impl KalmanBias {
    /// Filter for samples `dt_s` apart.
    pub fn try_new(config: &KalmanConfig, dt_s: f32) -> Result<Self, Error> {
        config.validate()?;
        let phi = libm::expf(-config.beta_per_s * dt_s);
        let sigma_b2 = config.bias_sigma_dps * config.bias_sigma_dps;
        // Discrete GM: var(b) stays sigma_b² when q = sigma_b² (1 − φ²). At β = 0 the bias
        // is a constant and only its initial uncertainty remains.
        let q_bias = sigma_b2 * (1.0 - phi * phi);
        let noise2 = config.rate_noise_dps * config.rate_noise_dps;
        let p0 = config.initial_bias_sigma_dps * config.initial_bias_sigma_dps;
        Ok(Self {
            dt_s,
            phi,
            bias_mean_dps: config.bias_mean_dps,
            q_bias,
            q_angle: noise2 * dt_s * dt_s,
            r_rate: noise2,
            bias_dps: config.bias_mean_dps,
            p: Matrix2::new(0.0, 0.0, 0.0, p0),
        })
    }

    /// Current bias estimate (deg/s).
    pub const fn bias_dps(&self) -> f32 {
        self.bias_dps
    }

    /// Standard deviation of the angle (deg).
    pub fn angle_std_deg(&self) -> f32 {
        libm::sqrtf(self.p[(0, 0)].max(0.0))
    }

    /// Standard deviation (deg) of the angle gained over a movement of `samples` steps that
    /// has just ended (before the rest after it updates the bias): the bias error times
    /// the duration, the white rate noise integrated over it, and the bias's own wander
    /// during it, `(n·dt)²·P_bb + n·q_θ + q_b·dt²·n³/3`. The bias variance is the one at
    /// the end, a little above the one at the start (conservative by the wander it grew).
    pub fn movement_std_deg(&self, samples: u32) -> f32 {
        let n = samples as f32;
        let duration_s = n * self.dt_s;
        let variance = duration_s * duration_s * self.p[(1, 1)].max(0.0)
            + n * self.q_angle
            + self.q_bias * self.dt_s * self.dt_s * n * n * n / 3.0;
        libm::sqrtf(variance)
    }

    /// Standard deviation of the bias estimate (deg/s).
    pub fn bias_std_dps(&self) -> f32 {
        libm::sqrtf(self.p[(1, 1)].max(0.0))
    }

    /// Propagate one step; `moving` if the angle integrates this step.
    pub fn predict(&mut self, moving: bool) {
        let coupling = if moving { -self.dt_s } else { 0.0 };
        let f = Matrix2::new(1.0, coupling, 0.0, self.phi);
        let q_angle = if moving { self.q_angle } else { 0.0 };
        self.p = f * self.p * f.transpose() + Matrix2::new(q_angle, 0.0, 0.0, self.q_bias);
        self.bias_dps = self.bias_mean_dps + self.phi * (self.bias_dps - self.bias_mean_dps);
    }

    /// Add the angle uncertainty of `samples` steps that were integrated while the motion
    /// was unconfirmed (propagated as static until then). Covariance only: the bias
    /// estimate already evolved the same way in both cases.
    pub fn add_motion(&mut self, samples: u32) {
        if samples == 0 {
            return;
        }
        let n = samples as f32;
        let g = Matrix2::new(1.0, -self.dt_s * n, 0.0, 1.0);
        self.p = g * self.p * g.transpose() + Matrix2::new(self.q_angle * n, 0.0, 0.0, 0.0);
    }

    /// Zero-rate update with the mean of `samples` rates measured at rest (its noise
    /// variance is R/samples). Returns the angle correction (deg).
    pub fn update_at_rest(&mut self, mean_rate_dps: f32, samples: u32) -> f32 {
        let rate_dps = mean_rate_dps;
        let r = self.r_rate / samples.max(1) as f32;
        let h = RowVector2::new(0.0, 1.0);
        let s = self.p[(1, 1)] + r;
        if s.is_nan() || s <= 0.0 {
            return 0.0;
        }
        let gain: Vector2<f32> = self.p * h.transpose() / s;
        let innovation = rate_dps - self.bias_dps;
        self.bias_dps += gain[1] * innovation;
        // Joseph form keeps P symmetric and positive in f32.
        let i_kh = Matrix2::identity() - gain * h;
        self.p = i_kh * self.p * i_kh.transpose() + gain * gain.transpose() * r;
        gain[0] * innovation
    }

    /// True if the state is finite.
    pub fn is_finite(&self) -> bool {
        self.bias_dps.is_finite() && self.p.iter().all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rest_updates_converge_to_the_bias() {
        let mut kf = KalmanBias::try_new(&KalmanConfig::default(), 0.02).unwrap();
        for _ in 0..500 {
            kf.predict(false);
            kf.update_at_rest(0.7, 1);
        }
        assert!((kf.bias_dps() - 0.7).abs() < 1e-3);
        // Steady state of a random walk observed directly: P ≈ √(q R), so the standard
        // deviation is (q R)^¼ = (0.25·(1 − φ²) · 0.05²)^¼ ≈ 0.017 deg/s.
        let phi = (-0.02_f32 / 300.0).exp();
        let expected = (0.25 * (1.0 - phi * phi) * 0.0025_f32).powf(0.25);
        assert!(
            (kf.bias_std_dps() - expected).abs() < 0.2 * expected,
            "{}",
            kf.bias_std_dps()
        );
    }

    #[test]
    fn angle_uncertainty_grows_while_moving_and_rest_corrects_it() {
        let mut kf = KalmanBias::try_new(&KalmanConfig::default(), 0.02).unwrap();
        for _ in 0..250 {
            kf.predict(true);
        }
        let std_after_motion = kf.angle_std_deg();
        assert!(std_after_motion > 1.0, "{std_after_motion}");
        // The true bias was 0.4 deg/s while the filter assumed 0, so the angle it integrated
        // over 5 s is 2 deg too high; the rest observations reveal it.
        let mut correction = 0.0;
        for _ in 0..200 {
            kf.predict(false);
            correction += kf.update_at_rest(0.4, 1);
        }
        assert!(kf.angle_std_deg() < std_after_motion);
        assert!(correction < -1.5 && correction > -2.5, "{correction}");
    }
}
